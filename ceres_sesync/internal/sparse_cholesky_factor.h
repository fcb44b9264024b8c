// A sparse Cholesky factor P A P^T = L L^T, extracted once from CHOLMOD, with
// triangular solves specialized for the SE-Sync data layout: the right-hand
// side is an r x N matrix whose N columns are the (vector-valued) unknowns, so
// X = B A^{-1} is solved in one pass over L with contiguous r-vector updates.
// For the small r of the Riemannian staircase this is several times faster
// than CHOLMOD's solve on B^T (no transposes, no per-supernode BLAS calls).
//
// Storage. The solves stream the whole factor from memory twice (forward and
// backward) and do about one multiply-add per entry and right-hand-side row,
// so their cost is the factor's size in bytes. L is stored in fundamental
// supernodes: maximal runs of consecutive columns j0..j0+c-1 whose patterns
// below the run coincide, which the (d+1)-blocks of the certificate matrix
// produce everywhere (each pose's translation and rotation unknowns are
// eliminated together). A supernode stores its c x c lower triangle and its
// nb x c rectangle below as dense values and ONE row index per row of the
// rectangle (CHOLMOD's simplicial layout needs one per entry). Entries that
// are exactly zero (the padding of CHOLMOD's relaxed supernodes) are dropped
// before the supernodes are formed, so nothing is stored that the solves do
// not need: per entry 8 bytes plus 4/c bytes of index (12 before), or 4 plus
// 4/c in single precision (ConvertToSinglePrecision()).

#ifndef CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
#define CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_

#include <cstdint>
#include <vector>

#include "Eigen/Core"
#include "cholmod.h"

namespace ceres_sesync::internal {

class SparseCholeskyFactor {
 public:
  SparseCholeskyFactor() = default;
  // Copies the numeric factor (simplicial or supernodal, LL^T or LDL^T) of
  // P A P^T; `factor` is unchanged. Reads a supernodal or simplicial LL^T
  // factor in place (no intermediate copy of it).
  SparseCholeskyFactor(const cholmod_factor* factor, cholmod_common* common);

  int size() const { return n_; }
  // X = B A^{-1} for B of size r x size(); X may not alias B. The r rows are
  // independent solves, split over up to `num_threads` threads.
  void SolveRows(const Eigen::MatrixXd& B, Eigen::MatrixXd* X,
                 int num_threads = 1) const;
  // The same for an A of size offset + B.cols() and a right-hand side that is
  // zero in its first `offset` columns; returns only the last B.cols()
  // columns of the solution (the rotation block of an augmented system).
  void SolveRowsTail(const Eigen::MatrixXd& B, int offset, Eigen::MatrixXd* X,
                     int num_threads = 1) const;

  // Rounds the stored factor to single precision (the solves still compute
  // in double). The operator applied is then exactly (L~ L~^T)^{-1} for the
  // rounded L~ (|L~ - L| <= 2^-24 |L| entrywise, diagonal included): symmetric
  // positive definite like the original, within a relative perturbation of
  // the order of 2^-24 times the condition of L of it. For preconditioners
  // only: products with it are not accurate solves.
  void ConvertToSinglePrecision();
  bool single_precision() const { return !values_float_.empty(); }

  // Statistics of the storage: entries of L stored (diagonal included),
  // supernodes, and bytes of the arrays the solves read.
  int64_t stored_entries() const { return stored_entries_; }
  int num_supernodes() const { return static_cast<int>(rows_.size()); }
  int64_t memory_bytes() const;

 private:
  // W = W L^{-T} L^{-1} for W (r x size(), column-major), in place.
  template <typename Scalar, int R>
  void SolveInPlace(const Scalar* values, int r, double* w) const;
  template <typename Scalar>
  void SolvePermuted(const Scalar* values, int r, double* w) const;

  int n_ = 0;
  int64_t stored_entries_ = 0;
  std::vector<int> permutation_;
  // Supernode s covers columns first_[s] .. first_[s + 1] - 1 (width c) and
  // has rows_[s] rows below them, whose indices are the next rows_[s] entries
  // of row_index_ (ascending, all >= first_[s + 1]). Its values, in
  // order: the c x c lower triangle row by row (row k: L(k, 0..k-1), then
  // 1 / L(k, k)), then the rectangle row by row (c values per row). Offsets
  // are accumulated during the (sequential) solves.
  std::vector<int> first_, rows_, row_index_;
  std::vector<double> values_;       // Double precision (the default) ...
  std::vector<float> values_float_;  // ... or single (then values_ is empty).
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
