// Sparse test of the SE-Sync optimality certificate.
//
// For multipliers Lambda (block diagonal, n symmetric d x d blocks) the
// certificate matrix is S = Q - Lambda (Rosen et al. 2019, Section 5.3). Q is
// dense, but S + cI is the Schur complement of the positive definite block
// Lbar in the sparse matrix
//
//   K_c = [ Lbar     -Vbar            ]     ((n-1) + dn square),
//         [ -Vbar^T   D - Lambda + cI ]
//
// so S + cI is positive definite if and only if K_c is, and a sparse Cholesky
// factorization of K_c that succeeds proves lambda_min(S) > -c (up to the
// floating-point backward error of the factorization, which Factorize()
// accounts for: see proven_shift()). The same factorization applies
// (S + cI)^{-1}, which the shift-and-invert eigensolver uses.

#ifndef CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_
#define CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_

#include <vector>

#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

class CertificateMatrix {
 public:
  explicit CertificateMatrix(const SESyncProblem& problem);

  // Assembles and factorizes K_c for the d x dn multipliers Lambda. Returns
  // true iff the Cholesky factorization ran to completion. Without
  // `bound_backward_error` (for preconditioning, not proofs) proven_shift()
  // is not computed.
  bool Factorize(const Eigen::MatrixXd& Lambda, double c,
                 bool bound_backward_error = true);

  // After a successful Factorize(): x = (S + cI)^{-1} y, y and x in R^{dn}.
  void SolveShifted(const Eigen::VectorXd& y, Eigen::VectorXd* x) const;
  // The same for the columns of Y (dn x k).
  void SolveShifted(const Eigen::MatrixXd& Y, Eigen::MatrixXd* X) const;
  // After a successful Factorize(): a copy of the factor for fast repeated
  // solves X = V (S + cI)^{-1} with V of size r x dn (SolveRowsTail with
  // offset translation_size()).
  SparseCholeskyFactor ExtractFactor() { return factor_.ExtractFactor(); }
  int translation_size() const { return translation_size_; }

  // After a successful Factorize(Lambda, c): c + delta, where delta bounds
  // the factorization's backward error ||L L^T - P K_c P^T||_2 (see
  // CholmodFactor::BackwardErrorBound), so K_c + delta I is proven positive
  // semidefinite. Round-off in the translation block (rows of Lbar) reaches S
  // amplified by ||Lbar^{-1} Vbar||^2; that worst case is not added (see
  // certification.h, "Floating point").
  double proven_shift() const { return proven_shift_; }
  double backward_error() const { return backward_error_; }

  // Dimension dn of S.
  int dimension() const { return rotation_size_; }
  // CHOLMOD chose a supernodal factor: factorizations cost much more than
  // products with Q (3D graphs).
  bool supernodal() const { return factor_.IsSupernodal(); }

 private:
  int d_ = 0, n_ = 0, translation_size_ = 0, rotation_size_ = 0;
  SparseMatrix K_;                   // Lower triangle, pattern fixed.
  std::vector<double> base_values_;  // K_0 without Lambda.
  std::vector<int> block_entry_;     // Value index of each (i, a >= b).
  CholmodFactor factor_;
  double proven_shift_ = 0;
  double backward_error_ = 0;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_
