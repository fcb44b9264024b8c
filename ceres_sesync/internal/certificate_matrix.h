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
  // `strict_round_off`: see proven_shift().
  explicit CertificateMatrix(const SESyncProblem& problem,
                             bool strict_round_off = false);

  // Assembles and factorizes K_c for the d x dn multipliers Lambda. Returns
  // true iff the Cholesky factorization ran to completion. Without
  // `bound_backward_error` (for preconditioning, not proofs) proven_shift()
  // is not computed.
  bool Factorize(const Eigen::MatrixXd& Lambda, double c,
                 bool bound_backward_error = true);

  // After a successful Factorize(): x = (S_mu + cI)^{-1} y, y and x in R^{dn},
  // where S_mu = D - Lambda - Vbar^T (Lbar - mu I)^{-1} Vbar, mu =
  // translation_shift() (0 after Factorize without bound_backward_error):
  // S_mu <= S, within mu ||Lbar^{-1} Vbar||^2 of it (for eigenvalue
  // estimates, not proofs).
  void SolveShifted(const Eigen::VectorXd& y, Eigen::VectorXd* x) const;
  // The same for the columns of Y (dn x k).
  void SolveShifted(const Eigen::MatrixXd& Y, Eigen::MatrixXd* X) const;
  // After a successful Factorize(): a copy of the factor for fast repeated
  // solves X = V (S + cI)^{-1} with V of size r x dn (SolveRowsTail with
  // offset translation_size()).
  SparseCholeskyFactor ExtractFactor() { return factor_.ExtractFactor(); }
  int translation_size() const { return translation_size_; }

  // After a successful Factorize(Lambda, c): c + delta, with delta a bound
  // on the factorization's floating-point backward error, computed row by
  // row (CholmodFactor::BackwardErrorBound, plus the rounding of the
  // assembly) and split into the translation rows (h) and the rotation rows.
  //  - Default: delta = max over all rows. K_c + delta I is then proven
  //    positive semidefinite; S + delta I follows to first order only:
  //    round-off h in the translation block reaches S amplified by up to
  //    ||Lbar^{-1} Vbar||^2, and that amplification is not added.
  //  - strict_round_off: the factorized matrix is K_c with its translation
  //    block shifted down to Lbar - mu I, mu >= h (adapted until it is), and
  //    delta covers the rotation rows only. Then K_c + diag(0, delta I) is
  //    proven positive semidefinite, hence its Schur complement
  //    S + (c + delta) I, rigorously. The price: S_mu = S - (about)
  //    mu Vbar^T Lbar^{-2} Vbar is what must be positive semidefinite, which
  //    costs roughly mu * (mean squared distance of the poses from pose 0)
  //    in lambda_min: large maps need much larger shifts.
  double proven_shift() const { return proven_shift_; }
  double backward_error() const { return backward_error_; }
  // mu of the last factorization with bound_backward_error (see
  // proven_shift()), else 0.
  double translation_shift() const { return factorized_shift_; }

  // Dimension dn of S.
  int dimension() const { return rotation_size_; }
  // CHOLMOD chose a supernodal factor: factorizations cost much more than
  // products with Q (3D graphs).
  bool supernodal() const { return factor_.IsSupernodal(); }

 private:
  // K_ = K_c with Lambda, c and the translation block Lbar - mu I; sets
  // *rotation_rounding to a bound on the rounding of the rotation rows.
  void Assemble(const Eigen::MatrixXd& Lambda, double c, double mu,
                double* rotation_rounding);

  bool strict_round_off_ = false;
  int d_ = 0, n_ = 0, translation_size_ = 0, rotation_size_ = 0;
  SparseMatrix K_;                   // Lower triangle, pattern fixed.
  std::vector<double> base_values_;  // K_0 without Lambda.
  std::vector<int> block_entry_;     // Value index of each (i, a >= b).
  CholmodFactor factor_;
  std::vector<int> translation_diagonal_;  // Value index of each Lbar_jj.
  double max_translation_diagonal_ = 0;
  // mu: the translation block of the factorized matrix is Lbar - mu I.
  double translation_shift_ = 0;
  double factorized_shift_ = 0;  // The mu of the current factor.
  double proven_shift_ = 0;
  double backward_error_ = 0;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_
