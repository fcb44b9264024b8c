#include "ceres_sesync/internal/verification.h"

#include <cmath>
#include <limits>

#include "Eigen/Eigenvalues"
#include "Spectra/SymEigsSolver.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

// y = (S + cI)^{-1} x through the factorized K_c, for Spectra.
class ShiftInvertOperator {
 public:
  using Scalar = double;
  explicit ShiftInvertOperator(const CertificateMatrix* matrix)
      : matrix_(matrix) {}
  Eigen::Index rows() const { return matrix_->dimension(); }
  Eigen::Index cols() const { return matrix_->dimension(); }
  void perform_op(const double* x_in, double* y_out) const {
    Eigen::VectorXd y;
    matrix_->SolveShifted(
        Eigen::Map<const Eigen::VectorXd>(x_in, matrix_->dimension()), &y);
    Eigen::Map<Eigen::VectorXd>(y_out, y.size()) = y;
  }

 private:
  const CertificateMatrix* matrix_;
};

// y = S x with S = Q - Lambda applied through products with Q (no
// factorization), for Spectra.
class CertificateOperator {
 public:
  using Scalar = double;
  CertificateOperator(const SESyncProblem* problem,
                      const Eigen::MatrixXd* Lambda)
      : problem_(problem), lambda_(Lambda) {}
  Eigen::Index rows() const {
    return problem_->dimension() * problem_->num_poses();
  }
  Eigen::Index cols() const { return rows(); }
  void perform_op(const double* x_in, double* y_out) const {
    const Eigen::Map<const Eigen::VectorXd> x(x_in, rows());
    Eigen::Map<Eigen::VectorXd>(y_out, rows()) =
        MultiplyCertificate(*problem_, *lambda_, x);
  }

 private:
  const SESyncProblem* problem_;
  const Eigen::MatrixXd* lambda_;
};

// Fast detection of clearly negative curvature: a short Lanczos run for the
// smallest eigenvalue of S itself. Returns true, with result->direction a
// unit vector v, result->direction_curvature = v^T S v < 0 and
// result->lambda_min_estimate the same Rayleigh quotient (>= lambda_min(S)),
// when it converged to a negative eigenvalue; else leaves *result alone.
bool FindNegativeCurvature(const SESyncProblem& problem,
                           const Eigen::MatrixXd& Lambda,
                           VerificationResult* result) {
  CertificateOperator op(&problem, &Lambda);
  const int dim = static_cast<int>(op.rows());
  if (dim < 3) return false;
  Spectra::SymEigsSolver<CertificateOperator> eigs(op, 1, std::min(40, dim));
  eigs.init();
  eigs.compute(Spectra::SortRule::SmallestAlge, /*maxit=*/3, /*tol=*/1e-3);
  if (eigs.info() != Spectra::CompInfo::Successful) return false;
  const Eigen::VectorXd v = eigs.eigenvectors().col(0).normalized();
  const double curvature = v.dot(MultiplyCertificate(problem, Lambda, v));
  if (!(curvature < 0)) return false;
  result->direction = v;
  result->direction_curvature = curvature;
  result->lambda_min_estimate = curvature;
  return true;
}

double MaxBlockEigenvalue(const Eigen::MatrixXd& Lambda, int d) {
  double lambda_max = 0;
  for (int i = 0; i < Lambda.cols() / d; ++i) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(
        Lambda.middleCols(d * i, d), Eigen::EigenvaluesOnly);
    lambda_max = std::max(lambda_max, eig.eigenvalues().maxCoeff());
  }
  return lambda_max;
}

}  // namespace

Eigen::VectorXd MultiplyCertificate(const SESyncProblem& problem,
                                    const Eigen::MatrixXd& Lambda,
                                    const Eigen::VectorXd& v) {
  const int d = problem.dimension();
  Eigen::MatrixXd vq;
  problem.MultiplyQ(v.transpose(), &vq);
  Eigen::MatrixXd v_lambda;
  BlockDiagonalMultiply(v.transpose(), Lambda, d, &v_lambda);
  return (vq - v_lambda).transpose();
}

VerificationResult VerifyCertificate(const SESyncProblem& problem,
                                     const Eigen::MatrixXd& Lambda,
                                     double eta_target, double eta_max,
                                     CertificateMatrix* matrix) {
  VerificationResult result;
  result.lambda_min_estimate = std::numeric_limits<double>::quiet_NaN();
  const int d = problem.dimension();
  ++result.factorizations;
  if (matrix->Factorize(Lambda, eta_target) &&
      matrix->proven_shift() <= eta_max) {
    result.certified = true;
    result.eta = matrix->proven_shift();
    return result;
  }
  // Bracket lambda_min(S) from below: S + cI is PD for c > lambda_max(Lambda).
  double c_upper = 1.01 * MaxBlockEigenvalue(Lambda, d) + eta_target;
  double c = eta_target;
  bool proven = false;
  // Poor candidate? With c_vacuous = tr(Lambda) / dn every proven shift
  // c >= c_vacuous gives the bound tr(Lambda) - c d n <= 0. One factorization
  // at c_vacuous tells: if it fails, so would every smaller shift, so no
  // bound worth proving exists: the witness comes from Lanczos on S if that
  // converges (cubicle's file guess 0.45 -> 0.19 s, torus3D 0.24 -> 0.13 s),
  // else the bracketing starts at c_vacuous instead of eta_target (skipping
  // up to ten factorizations that fail late). If it succeeds, the
  // bracketing stops there at the latest.
  const double c_vacuous = BlockDiagonalTrace(Lambda, d) / Lambda.cols();
  if (c_vacuous > std::max(eta_target, eta_max) && c_vacuous < c_upper) {
    ++result.factorizations;
    if (matrix->Factorize(Lambda, c_vacuous)) {
      c_upper = c_vacuous;
    } else {
      result.vacuous_bound = true;
      if (FindNegativeCurvature(problem, Lambda, &result)) {
        result.eta = std::numeric_limits<double>::infinity();
        return result;
      }
      c = c_vacuous;
    }
  }
  for (int step = 0; c < c_upper; ++step) {
    if (step == 2 && matrix->supernodal() && !result.vacuous_bound) {
      // lambda_min(S) < -256 eta_target: usually clear negative curvature
      // (a saddle or a poor candidate), which Lanczos on S finds in a few
      // dozen products with Q; jump the shift just past it. Only worth it
      // when factorizations are expensive (supernodal: heavy fill, e.g.
      // torus3D); sparser factorizations are cheaper than the Lanczos run.
      // (Not again after the poor-candidate test: it already ran, and failed.)
      if (FindNegativeCurvature(problem, Lambda, &result)) {
        c = std::max(c,
                     std::min(-1.1 * result.direction_curvature, c_upper) / 16);
      }
    }
    c = std::min(16 * c, c_upper);
    ++result.factorizations;
    if (matrix->Factorize(Lambda, c)) {
      proven = true;
      break;
    }
  }
  if (!proven) {
    // Only round-off can make this fail; report it as an eigen failure.
    result.eta = std::numeric_limits<double>::infinity();
    result.eigensolver_failed = true;
    return result;
  }
  result.eta = matrix->proven_shift();
  if (result.eta <= eta_max) {  // Certified with a larger shift.
    result.certified = true;
    return result;
  }
  if (result.direction.size() > 0) {
    // Negative curvature already found (FindNegativeCurvature) and the bound
    // proven: nothing to tighten that could certify.
    return result;
  }
  // lambda_min(S) > -c: the largest eigenvalue of (S + cI)^{-1} is
  // 1 / (lambda_min + c).
  ShiftInvertOperator op(matrix);
  const int dim = matrix->dimension();
  Spectra::SymEigsSolver<ShiftInvertOperator> eigs(op, 1, std::min(20, dim));
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-8);
  if (eigs.info() == Spectra::CompInfo::Successful) {
    const double mu = eigs.eigenvalues()(0);
    result.lambda_min_estimate = 1.0 / mu - c;
    result.direction = eigs.eigenvectors().col(0).normalized();
  } else {
    LOG(WARNING) << "shift-and-invert Lanczos did not converge";
  }
  if (result.direction.size() == dim) {
    result.direction_curvature = result.direction.dot(
        MultiplyCertificate(problem, Lambda, result.direction));
  }
  // Tighten the shift to just above the estimate when that can certify.
  if (std::isfinite(result.lambda_min_estimate) && result.eta > eta_max) {
    const double tight =
        std::max(eta_target, -1.05 * result.lambda_min_estimate);
    if (tight < c) {
      ++result.factorizations;
      if (matrix->Factorize(Lambda, tight)) {
        result.eta = std::min(result.eta, matrix->proven_shift());
      }
    }
  }
  if (result.eta <= eta_max) {
    result.certified = true;
    return result;
  }
  if (result.direction.size() != dim || !(result.direction_curvature < 0)) {
    result.eigensolver_failed = true;
  }
  return result;
}

}  // namespace ceres_sesync::internal
