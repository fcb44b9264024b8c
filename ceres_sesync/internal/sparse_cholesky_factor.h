// A sparse Cholesky factor P A P^T = L L^T, copied once from CHOLMOD's or
// from supernodes (extended_cholesky.h's double factor), with
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
//
// Parallel solves. The r rows are independent solves, but splitting them over
// threads makes every thread stream the whole factor (and gather from its
// own W at random rows): with r = 3 on two threads each still pays almost a
// whole one-thread solve. Instead the elimination tree of the supernodes is
// cut once, at construction, into kTreeSplitBins = 2 "bins" of disjoint
// subtrees of about equal weight and the "top" (their common ancestors, with
// nested dissection the top separators). Forward, the bins are solved
// concurrently, each adding its updates of top rows into an accumulator of its
// own (extra columns of W, to which the bins' row indices of top rows point),
// the accumulators are added to the top in bin order, and the top is solved
// with its rows split over threads; backward in reverse, the top's solution
// copied into the accumulators for the bins to read. The schedule depends only
// on the factor, never on the thread count, so results are bitwise the same for
// every thread count (they differ from an unsplit solve in round-off only:
// the order in which updates of top rows are summed).

#ifndef CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
#define CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_

#include <cstdint>
#include <functional>
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
  // Copies a supernodal LL^T factor of P A P^T (permutation[k] = P's k-th
  // pivot, CHOLMOD's Perm) given as fundamental supernodes:
  // for_each_supernode(f) calls f(first, ncols, rows, nrows, values) for the
  // supernodes in column order, where columns first .. first + ncols - 1
  // have the rows rows[0 .. nrows) (the columns themselves, then the rows
  // below them, ascending, the same for every column) and values is the
  // nrows x ncols block, column-major (leading dimension nrows; its entries
  // above the diagonal are not read). Kept as given: no zeros are dropped.
  using SupernodeVisitor = std::function<void(
      int first, int ncols, const int* rows, int nrows, const double* values)>;
  SparseCholeskyFactor(
      std::vector<int> permutation,
      const std::function<void(const SupernodeVisitor&)>& for_each_supernode);

  // Replaces the values with those of a factor of the same supernodes
  // (a numeric refactorization with the same analysis), given as for the
  // constructor above, and keeps the rest: the solve schedule is not
  // rebuilt. Not for a factor in single precision.
  void RefreshValues(
      const std::function<void(const SupernodeVisitor&)>& for_each_supernode);

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
  // Bins of the parallel solve schedule (0: unsplit) and the stored entries
  // of its top (all of them when unsplit).
  int num_bins() const { return static_cast<int>(bin_end_.size()); }
  int64_t top_entries() const;
  int64_t memory_bytes() const;

 private:
  // The CHOLMOD constructor's copy, column by column.
  using ColumnVisitor =
      std::function<void(int, double, std::vector<int>*, std::vector<double>*)>;
  void Build(std::vector<int> permutation,
             const std::function<void(const ColumnVisitor&)>& for_each_column);
  // The solve schedule (see the top of this file), built by the constructor.
  void BuildSchedule();
  // W = W L^{-1} (forward) or W = W L^{-T} (backward) restricted to the
  // supernodes order_[begin .. end - 1], for the r rows of W starting at `w`
  // (column j at w + j * ld).
  template <typename Scalar, int R>
  void Forward(const Scalar* values, int begin, int end, int r, int ld,
               double* w) const;
  template <typename Scalar, int R>
  void Backward(const Scalar* values, int begin, int end, int r, int ld,
                double* w) const;
  template <typename Scalar>
  void SolvePhase(bool forward, const Scalar* values, int begin, int end, int r,
                  int ld, double* w) const;
  void SolvePhase(bool forward, int begin, int end, int r, int ld,
                  double* w) const;

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
  // Where supernode s's values and row indices start.
  std::vector<int64_t> value_begin_, row_begin_;
  // The schedule: every supernode once, bin 0's in ascending order, then bin
  // 1's, ..., then the top's; bin b is order_[bin_end_[b - 1] ..
  // bin_end_[b] - 1] (bin_end_[-1] = 0), the top the rest. Without a split,
  // bin_end_ is empty and everything is top. In the bins' row indices, top
  // row top_columns_[t] reads n_ + b * top_columns_.size() + t instead.
  std::vector<int> order_, bin_end_, top_columns_;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
