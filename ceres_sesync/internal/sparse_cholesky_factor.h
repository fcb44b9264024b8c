// A sparse Cholesky factor P A P^T = L L^T, extracted once from CHOLMOD, with
// triangular solves specialized for the SE-Sync data layout: the right-hand
// side is an r x N matrix whose N columns are the (vector-valued) unknowns, so
// X = B A^{-1} is solved in one pass over L with contiguous r-vector updates.
// For the small r of the Riemannian staircase this is several times faster
// than CHOLMOD's solve on B^T (no transposes, no per-supernode BLAS calls).

#ifndef CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
#define CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_

#include <vector>

#include "Eigen/Core"
#include "cholmod.h"

namespace ceres_sesync::internal {

class SparseCholeskyFactor {
 public:
  SparseCholeskyFactor() = default;
  // Copies the numeric factor (simplicial or supernodal, LL^T or LDL^T) as a
  // simplicial LL^T factor in compressed columns; `factor` is unchanged.
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

 private:
  // W = W L^{-T} L^{-1} for W (r x size(), column-major), in place.
  template <int R>
  void SolveInPlace(int r, double* w) const;
  void SolvePermuted(int r, double* w) const;

  int n_ = 0;
  std::vector<int> column_start_, row_index_, permutation_;
  std::vector<double> values_;            // Off-diagonal entries of L.
  std::vector<double> inverse_diagonal_;  // 1 / L(j, j).
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SPARSE_CHOLESKY_FACTOR_H_
