// Verification of the SE-Sync optimality certificate S = Q - Lambda
// (Rosen et al. 2019, Section 5.3, Algorithm 3) with sparse Cholesky tests of
// S + cI and a shift-and-invert Lanczos eigensolver for negative curvature.

#ifndef CERES_SESYNC_INTERNAL_VERIFICATION_H_
#define CERES_SESYNC_INTERNAL_VERIFICATION_H_

#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

struct VerificationResult {
  // S + eta I was proven positive definite with eta <= eta_max.
  bool certified = false;
  // Smallest shift c for which S + cI was proven positive definite (the
  // certificate's slack); +infinity if none was.
  double eta = 0;
  // Estimate of lambda_min(S) (an upper bound when it is from a Ritz value);
  // NaN if no eigensolve was needed.
  double lambda_min_estimate = 0;
  // When not certified: a unit vector v in R^{dn} with v^T S v < 0.
  Eigen::VectorXd direction;
  // v^T S v for `direction`.
  double direction_curvature = 0;
  // The eigensolver did not produce a direction of negative curvature.
  bool eigensolver_failed = false;
  // S + (tr(Lambda) / dn) I is not positive definite: every provable shift
  // gives the vacuous bound tr(Lambda) - eta d n < 0 (eta > tr(Lambda) / dn).
  bool vacuous_bound = false;
  int factorizations = 0;
};

// S v for the d x dn multipliers Lambda.
Eigen::VectorXd MultiplyCertificate(const SESyncProblem& problem,
                                    const Eigen::MatrixXd& Lambda,
                                    const Eigen::VectorXd& v);

// Tests S + eta_target I, then larger shifts by factors of 16 up to
// lambda_max(Lambda) (where S + cI is positive definite since Q is PSD).
// Certified iff the smallest proven shift is <= eta_max; otherwise a
// negative-curvature direction is computed by shift-and-invert Lanczos.
// Poor candidates: one factorization at c = tr(Lambda) / dn (above which
// every bound is vacuous) caps the bracketing there when it succeeds; when it
// fails (vacuous_bound), the witness comes from Lanczos on S (eta = +inf) or,
// if that does not converge, the bracketing starts there.
VerificationResult VerifyCertificate(const SESyncProblem& problem,
                                     const Eigen::MatrixXd& Lambda,
                                     double eta_target, double eta_max,
                                     CertificateMatrix* matrix);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_VERIFICATION_H_
