// Verification of the SE-Sync optimality certificate S = Q - Lambda
// (Rosen et al. 2019, Section 5.3, Algorithm 3) with sparse Cholesky tests of
// S + cI and a shift-and-invert Lanczos eigensolver for negative curvature.

#ifndef CERES_SESYNC_INTERNAL_VERIFICATION_H_
#define CERES_SESYNC_INTERNAL_VERIFICATION_H_

#include <chrono>
#include <limits>

#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

// Which arithmetic proves the certificate.
enum class ProofPolicy {
  kAutomatic,     // Double; double-double when double cannot reach the goal.
  kDouble,        // Double only.
  kDoubleDouble,  // Double-double only (double still finds saddle escapes).
};

struct VerificationOptions {
  // First shift tried (the tightest proof worth attempting).
  double eta_target = 0;
  // Certified iff a shift <= eta_max is proven (the tolerance).
  double eta_max = 0;
  // A proof above this shift is tightened in double-double (kAutomatic);
  // <= 0: the goal is out of reach, use eta_max.
  double eta_goal = 0;
  ProofPolicy policy = ProofPolicy::kAutomatic;
  // kAutomatic where double cannot reach the goal with the shifts its next
  // proof starts with, but within kLearnedShiftReach goals: two double
  // proofs (the second with the first's bounds as shifts) are tried before
  // double-double on factorizations of at least this many multiply-adds
  // (below it a double-double factorization costs about two double ones).
  double learned_shift_min_multiply_adds = 1e7;
  // The candidate's translations from the gauge's, by K's translation row
  // (CertificateMatrix::TranslationOffsets; empty: unknown). A double proof
  // lowers the translation block by diag(mu_j), which costs about
  // CertificateMatrix::DoubleShiftCost(translation_offsets) in
  // lambda_min(S) (the global-rotation directions, where S is near
  // singular): shifts below that are not tried in double.
  Eigen::MatrixXd translation_offsets;
  // The candidate is probably optimal (the caller's evidence: the staircase
  // sets it when rounding Y loses at most the goal; a lifted saddle of rank
  // d passes that test too). Where double cannot reach the goal (its floor,
  // see translation_offsets, is above it) and kAutomatic escalates to
  // double-double, the double-double proof at goal / 16 is then tried first,
  // before the near-optimality test in double (one double factorization at
  // eta_max), which is needed only if that proof fails: a certified map
  // takes one double-double factorization instead of it plus a double one,
  // a lifted saddle one failed double-double factorization more (~4.6
  // double ones on large maps). When that proof fails, the candidate is
  // taken for a lifted saddle: the near-optimality test is skipped, and the
  // witness's ladder proves its first shift (64 eta_max) before the
  // poor-candidate test (two factorizations fewer for a saddle; one more for
  // a poor candidate).
  bool likely_optimal = false;
  // With likely_optimal: the near-optimality test in double comes first all
  // the same, and when it fails the candidate is taken for a lifted saddle
  // (as after a failed double-double proof). That costs a certified
  // candidate one double factorization and saves a saddle ~3.6 (a failed
  // double-double one minus the test): it pays where more than ~1 in 5
  // candidates are saddles, which the staircase expects of large maps.
  bool test_in_double_first = false;
  // When not certified: prove a last shift just above the Lanczos estimate
  // of lambda_min(S) (one more factorization), so that eta and its lower
  // bound are near what lambda_min allows instead of at the witness's
  // shift. A caller that only needs the witness (the staircase escaping to
  // the next rank, whose own verification replaces this bound) sets false.
  bool tighten_uncertified = true;
  // S + known_shift I was proven already for this Lambda, in
  // known_precision (a certificate test during the optimization: see
  // SolverOptions::test_certificate_after_escape). The result starts from
  // it, and only VerifyCertificate's known-shift tightening tries to improve
  // on it, where double reaches at least 2x below it (no double-double proof
  // repeats the test's cost unless double stops 4x short of the Lanczos
  // estimate).
  double known_shift = std::numeric_limits<double>::infinity();
  ProofPrecision known_precision = ProofPrecision::kDouble;
  // False: the known shift is the result as it stands (a test near
  // convergence, SolverOptions::test_certificate_near_convergence, ran step
  // 1's proof already; step 1 would stop there too).
  bool tighten_known_shift = true;
  // > 0: the matrix still holds the double factor of the test that proved
  // known_shift, of K_c at this c (with that proof's translation shifts M).
  // The known-shift tightening then estimates lambda_min by Lanczos on it
  // instead of factorizing again at known_shift: an estimate of
  // lambda_min(S_M), below lambda_min(S) by at most what M costs
  // (CertificateMatrix::FactorShiftCost, about double's floor). Where that
  // is over 5% of the estimate, the factor at known_shift is made after
  // all. Estimates only: the proofs are new factorizations either way.
  double known_shift_factor = 0;
  // No factorization is started that is predicted to end after this
  // (CertificateMatrix::PredictedSeconds), double-double ones stop at it,
  // and nothing starts once it has passed; the result then has out_of_time
  // and the best shift proven before.
  std::chrono::steady_clock::time_point deadline =
      std::chrono::steady_clock::time_point::max();
};

struct VerificationResult {
  // S + eta I was proven positive semidefinite with eta <= eta_max.
  bool certified = false;
  // Smallest shift c for which S + cI was proven positive semidefinite (the
  // certificate's slack), all round-off included; +infinity if none was.
  double eta = 0;
  // The arithmetic of the factorization that proved eta (when finite).
  ProofPrecision precision = ProofPrecision::kDouble;
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
  // Factorizations in double and in double-double, and the seconds spent in
  // the latter.
  int factorizations = 0;
  int extended_factorizations = 0;
  double extended_time_s = 0;
  // The deadline stopped the verification early.
  bool out_of_time = false;
};

// A lower bound, rounded down, on tr(Lambda) - eta d n (the dual objective
// of the multipliers Lambda - eta I, which is a lower bound on the optimum
// once S + eta I >= 0 is proven): the trace is summed in double-double.
double ProvenLowerBound(const Eigen::MatrixXd& Lambda, int d, double eta);

// S v for the d x dn multipliers Lambda.
Eigen::VectorXd MultiplyCertificate(const SESyncProblem& problem,
                                    const Eigen::MatrixXd& Lambda,
                                    const Eigen::VectorXd& v);

// Proves the smallest shift it can (a complete proof, CertificateMatrix::
// Prove). With a known shift (VerificationOptions::known_shift) only a
// tightening as in step 3 runs, where double can reach below it (at most one
// double-double proof, at the Lanczos estimate, when that is 4x tighter).
// Otherwise:
//  1. a proof at eta_target, then in double at eta_goal / 4; done if one
//     proves a shift <= the goal;
//  2. one factorization (no proof) at eta_max tells a near-optimal Lambda
//     (it succeeds: lambda_min(S) > -eta_max up to double round-off) from a
//     saddle or poor candidate (skipped after a failed likely_optimal
//     proof, where step 4 starts with its ladder's first shift);
//  3. near-optimal: proofs at eta_goal / 16 and eta_goal, then (when they
//     fail) at shifts guided by a shift-and-invert Lanczos estimate of
//     lambda_min(S) from the factor at eta_max, then by factors of 8 up to
//     eta_max, in double-double unless the policy is kDouble (then double);
//  4. otherwise: a witness of negative curvature (for the staircase's escape
//     and Certify's report) from Lanczos on S or, where that does not
//     converge, shift-and-invert Lanczos on the first proven shift of a
//     ladder (factors of 16 up to lambda_max(Lambda), where S + cI is
//     positive definite since Q is PSD). Poor candidates: one factorization
//     at c = tr(Lambda) / dn (above which every bound is vacuous) caps the
//     ladder there when it succeeds; when it fails (vacuous_bound) the
//     ladder starts there.
VerificationResult VerifyCertificate(const SESyncProblem& problem,
                                     const Eigen::MatrixXd& Lambda,
                                     const VerificationOptions& options,
                                     CertificateMatrix* matrix);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_VERIFICATION_H_
