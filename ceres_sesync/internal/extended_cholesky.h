// Sparse Cholesky factorization A = L L^T in double-double arithmetic
// (double_double.h), with a rigorous bound on its backward error: the proof
// engine for certificates that double precision cannot resolve.
//
// The factorization is the up-looking (row by row) scheme: row k of L solves
// L(0:k-1, 0:k-1) l_k = A(0:k-1, k) over the elimination-tree reach of
// A(:, k), then l_kk = sqrt(a_kk - l_k^T l_k) (Davis, "Direct Methods for
// Sparse Linear Systems", SIAM 2006, Sec. 4.2). Every computed entry obeys
// the componentwise backward-error bound of Higham ("Accuracy and
// Stability of Numerical Algorithms", 2nd ed., Thm. 10.3 with Lemma 8.4: any
// summation order) in any arithmetic satisfying the standard model:
//
//   L L^T = A + E,   |E| <= gamma_{k+1} |L| |L^T|,
//
// with k the number of stored entries of the row and gamma the double-double
// gamma (kDoubleDoubleUnitRoundoff ~ 3.9e-31). A factorization that completes
// therefore proves A + E positive semidefinite, i.e. A + diag(rho) >= 0 for
// the Gershgorin row sums rho_i >= sum_j |E_ij| returned by
// RowBackwardErrorBounds().
//
// The matrix is given already permuted (the caller chooses the fill-reducing
// ordering), as the upper triangle in compressed columns.

#ifndef CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_
#define CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_

#include <vector>

#include "ceres_sesync/internal/double_double.h"

namespace ceres_sesync::internal {

class DoubleDoubleCholesky {
 public:
  // Symbolic analysis of the n x n pattern: column k of the upper triangle
  // holds the rows row_index[column_start[k] .. column_start[k+1]) (each
  // <= k; the diagonal must be present). O(nnz(L)).
  void Analyze(int n, std::vector<int> column_start,
               std::vector<int> row_index);

  // Numerical factorization with values[p] the entry row_index[p] of the
  // pattern. Returns false if a pivot is not positive (A is not positive
  // definite, up to the backward error) or if a value is so small that the
  // arithmetic could underflow (then nothing is proven).
  bool Factorize(const std::vector<DoubleDouble>& values);

  // After a successful Factorize(): rho_i >= sum_j |E_ij| for every row i
  // (permuted order), with the rounding of this computation itself covered.
  void RowBackwardErrorBounds(std::vector<double>* rho) const;

  int size() const { return n_; }
  // Entries of L (after Analyze()).
  long long factor_nonzeros() const {
    return factor_start_.empty() ? 0 : factor_start_.back();
  }
  // After a successful Factorize(): L in compressed columns (each column's
  // diagonal first, then its rows in increasing order).
  const std::vector<int>& factor_start() const { return factor_start_; }
  const std::vector<int>& factor_row() const { return factor_row_; }
  const std::vector<DoubleDouble>& factor_value() const {
    return factor_value_;
  }
  // Multiply-adds of one factorization: sum over columns of count^2 / 2.
  double flops() const { return flops_; }

 private:
  int n_ = 0;
  std::vector<int> column_start_, row_index_;  // The upper triangle of A.
  std::vector<int> parent_;                    // Elimination tree.
  std::vector<int> factor_start_;              // Column pointers of L.
  std::vector<int> factor_row_;                // Row indices of L.
  std::vector<DoubleDouble> factor_value_;     // Values of L.
  std::vector<int> row_count_;                 // Entries per row of L.
  double flops_ = 0;
  bool factorized_ = false;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_
