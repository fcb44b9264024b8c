#include "ceres_sesync/internal/verification.h"

#include <chrono>
#include <cmath>
#include <limits>

#include "Eigen/Eigenvalues"
#include "Spectra/SymEigsSolver.h"
#include "ceres_sesync/internal/double_double.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

// The largest double floor, in goals, from which the shifts a first double
// proof's bounds set are expected to bring double within reach of the goal
// (they cost 3-13x less than the first shifts on the benchmark maps).
constexpr double kLearnedShiftReach = 2;

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
    return problem_->dimension() * problem_->num_rotations();
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

// FindNegativeCurvature's Lanczos: a basis of kLanczosBasis vectors and at
// most kLanczosRestarts restarts, so at most about kLanczosMaxProducts
// products with S.
constexpr int kLanczosBasis = 40, kLanczosRestarts = 3;
constexpr int kLanczosMaxProducts =
    kLanczosBasis + kLanczosRestarts * (kLanczosBasis - 1);

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
  Spectra::SymEigsSolver<CertificateOperator> eigs(
      op, 1, std::min(kLanczosBasis, dim));
  eigs.init();
  eigs.compute(Spectra::SortRule::SmallestAlge, kLanczosRestarts,
               /*tol=*/1e-3);
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

double ProvenLowerBound(const Eigen::MatrixXd& Lambda, int d, double eta) {
  // Sum in double-double: within gamma_k (double-double) of the exact sum,
  // k = dn terms; eta * dn exactly (TwoProduct); one more subtraction.
  DoubleDouble trace;
  double abs_trace = 0;
  const int dn = static_cast<int>(Lambda.cols());
  for (int i = 0; i < dn; ++i) {
    trace += DoubleDouble(Lambda(i % d, i));
    abs_trace += std::abs(Lambda(i % d, i));
  }
  const DoubleDouble shift = dd::TwoProduct(eta, static_cast<double>(dn));
  const DoubleDouble bound = trace - shift;
  const double error = DoubleDoubleGamma(dn + 2) *
                           (abs_trace + shift.AbsUpperBound()) * (1 + 1e-6) +
                       4 * kUnitRoundoffDouble * bound.AbsUpperBound();
  return bound.ToDouble() - error;
}

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
                                     const VerificationOptions& options,
                                     CertificateMatrix* matrix) {
  VerificationResult result;
  result.lambda_min_estimate = std::numeric_limits<double>::quiet_NaN();
  result.eta = std::numeric_limits<double>::infinity();
  const int d = problem.dimension();
  const int double_before = matrix->double_factorizations();
  const int extended_before = matrix->extended_factorizations();
  const double extended_time_before = matrix->extended_time_s();
  const double eta_target = options.eta_target, eta_max = options.eta_max;
  const double goal = options.eta_goal > 0 ? options.eta_goal : eta_max;
  const bool use_extended = options.policy != ProofPolicy::kDouble;
  const ProofPrecision first = options.policy == ProofPolicy::kDoubleDouble
                                   ? ProofPrecision::kDoubleDouble
                                   : ProofPrecision::kDouble;
  auto finish = [&]() {
    result.certified = result.eta <= eta_max;
    result.factorizations = matrix->double_factorizations() - double_before;
    result.extended_factorizations =
        matrix->extended_factorizations() - extended_before;
    result.extended_time_s = matrix->extended_time_s() - extended_time_before;
    if (!result.certified && (result.direction.size() != matrix->dimension() ||
                              !(result.direction_curvature < 0))) {
      result.eigensolver_failed = true;
    }
    return result;
  };
  matrix->set_deadline(options.deadline);
  const bool has_deadline =
      options.deadline != std::chrono::steady_clock::time_point::max();
  // Whether work predicted to take `seconds` fits before the deadline.
  auto fits = [&](double seconds) {
    if (!has_deadline) return true;
    const double left = std::chrono::duration<double>(
                            options.deadline - std::chrono::steady_clock::now())
                            .count();
    if (left > seconds && left > 0) return true;
    result.out_of_time = true;
    return false;
  };
  // Whether Lanczos on S (FindNegativeCurvature) is predicted to cost less
  // than two double factorizations, the witness's other route (a proof
  // above lambda_min, then shift-and-invert Lanczos on its factor). Its
  // products with Q cost O(m r) but solve with Lbar, whose factor fills on
  // 3D lattices: on a 97,336-pose cube ~160 products (a Lanczos run that did
  // not converge) cost 6.9 s against 0.9 s per factorization. Before a
  // factorization has completed (Certify() of a poor guess) Lanczos goes
  // first: it wins there (cubicle's file guess 0.45 -> 0.19 s, torus3D's
  // 0.24 -> 0.13 s). Predicted from the patterns, not timed, so that the
  // route, and with it the result, is the same on every run however loaded
  // the machine (a timed gate made an 8-pose graph's result differ between
  // two runs under ctest -j2). The unit: one multiply-add of a product
  // (2.6-4.9 ns measured, one thread, over the 12 datasets, cubes of 10^3 to
  // 46^3 poses and a 10^5-pose city). A factorization costs ~2.5 of them per
  // entry of L (11-22 ns measured: the simplicial work per entry) plus 1/64
  // per multiply-add of its own (supernodal dense kernels). On those graphs
  // the model's ratio of the two routes was 0.96-1.57x the timed one (timed
  // 3.1-36: Lanczos the dearer route on all of them once a factorization
  // had completed).
  auto lanczos_is_cheap = [&]() {
    if (!matrix->double_completed()) return true;
    const double factorization =
        2.5 * matrix->factor_nonzeros() + matrix->factorization_flops() / 64;
    return kLanczosMaxProducts * problem.MultiplyQCost() < 2 * factorization;
  };
  double failed_double = 0;  // The largest shift a double proof failed at.
  auto prove = [&](double c, ProofPrecision precision) {
    if (!fits(matrix->PredictedSeconds(precision))) return false;
    if (!matrix->Prove(Lambda, c, precision)) {
      if (matrix->timed_out()) result.out_of_time = true;
      if (precision == ProofPrecision::kDouble) {
        failed_double = std::max(failed_double, c);
      }
      return false;
    }
    if (matrix->proven_shift() < result.eta) {
      result.eta = matrix->proven_shift();
      result.precision = precision;
    }
    return true;
  };
  // lambda_min(S) estimated by shift-and-invert Lanczos on the current
  // double factor, which must be that of S + shift I (Factorize()); NaN if
  // Lanczos does not converge.
  auto estimate_lambda_min = [&](double shift) {
    ShiftInvertOperator op(matrix);
    const int dim = matrix->dimension();
    Spectra::SymEigsSolver<ShiftInvertOperator> eigs(op, 1, std::min(20, dim));
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestAlge, 1000, 1e-8);
    if (eigs.info() != Spectra::CompInfo::Successful) {
      return std::numeric_limits<double>::quiet_NaN();
    }
    return 1.0 / eigs.eigenvalues()(0) - shift;
  };
  // Double-double proofs from the goal up to the tolerance; the first
  // success ends them (each costs 1.8-4.6 double factorizations, measured).
  // When the goal fails (lambda_min(S) < -goal), the next shifts come from
  // an estimate of lambda_min(S) if the double factor at eta_max is at hand
  // (`factor_at_eta_max`), else by factors of 8, so that the proven bound
  // lands near what lambda_min(S) allows instead of at the tolerance itself
  // (where the rounded-up objective can put it just outside).
  // Double-double proofs are attempted at increasing shifts only.
  double tried = 0;
  // True when done: proven, or c cannot improve on what is proven.
  auto attempt = [&](double c) {
    c = std::max(c, eta_target);
    if (c >= result.eta) return true;
    if (c <= tried) return false;
    tried = c;
    return prove(c, ProofPrecision::kDoubleDouble);
  };
  auto prove_extended = [&](bool factor_at_eta_max) {
    if (attempt(goal / 16) || attempt(goal)) return;
    if (factor_at_eta_max) {
      const double lambda_min = estimate_lambda_min(eta_max);
      if (std::isfinite(lambda_min)) {
        result.lambda_min_estimate = lambda_min;
        if (-lambda_min < eta_max &&
            (attempt(-1.1 * lambda_min) || attempt(-2 * lambda_min))) {
          return;
        }
      }
    }
    for (double c = 8 * std::max(tried, goal); c < eta_max; c *= 8) {
      if (attempt(c)) return;
    }
    attempt(eta_max);
  };

  bool suspect_saddle = false;  // See the likely_optimal branch below.
  // 1. The fast path: a proof at the target shift, then in double one at a
  // quarter of the goal (where double suffices, e.g. compact 3D maps, that
  // is all it takes). Double proofs below the cost of their translation
  // shift (options.translation_offsets) would fail: start above it, and
  // skip double altogether when that cost is above the goal.
  const double double_floor =
      matrix->DoubleShiftCost(options.translation_offsets);
  VLOG(1) << "verification: double floor " << double_floor << " (target "
          << eta_target << ", goal " << goal << ", max " << eta_max
          << "), factorization " << matrix->factorization_flops()
          << " multiply-adds";
  // The first shift of a double ladder guided by an estimate of
  // lambda_min(S) (from a factor without translation shift): above it by
  // 10% of it, or by 1.5 double_floor where that is more. The floor is what
  // the proofs' translation shift mu costs (lambda_min(S_mu) is about
  // lambda_min(S) minus it), so 10% alone failed whenever |lambda_min(S)|
  // was within 10x of the floor (a 10^5-pose city's rank-5 certificate:
  // lambda_min -2.4e-5, floor 1.1e-5: 2.66e-5 failed, 2.1e-4 proven; now
  // 4.0e-5 at the first attempt).
  auto double_start = [&](double lambda_min) {
    return std::max(
        eta_target,
        -lambda_min + std::max(0.1 * std::abs(lambda_min), 1.5 * double_floor));
  };
  if (std::isfinite(options.known_shift)) {
    // Proven already (VerificationOptions::known_shift). Where double can
    // prove shifts at least 2x smaller, tighten as in step 3: a factor at
    // the known shift, the Lanczos estimate of lambda_min(S), double proofs
    // from just above it (plus what their translation shift costs) up by 8,
    // and, if they stop short of a 4x tighter shift that the estimate allows
    // (double's floor), one double-double proof there. (Closer to the floor
    // the factorization and Lanczos would cost about three factorizations
    // for less than a 2x tighter bound: a test proven at the floor itself,
    // PlanDescentTest in staircase.h, is not repeated.)
    result.eta = options.known_shift;
    result.precision = options.known_precision;
    if (!options.tighten_known_shift) return finish();
    const double start = std::max(
        {eta_target, 1.5 * double_floor, std::numeric_limits<double>::min()});
    const bool held = options.known_shift_factor > 0;
    auto factor_at_known_shift = [&] {
      return fits(matrix->PredictedSeconds(ProofPrecision::kDouble)) &&
             matrix->Factorize(Lambda, result.eta);
    };
    if (first == ProofPrecision::kDouble && start < 0.5 * result.eta &&
        (held || factor_at_known_shift())) {
      double lambda_min =
          estimate_lambda_min(held ? options.known_shift_factor : result.eta);
      // The held factor's estimate is of S_M, below lambda_min(S) by up to
      // what its translation shifts M cost. Where that is over 5% of the
      // estimate (a lambda_min within a few floors of zero), the proofs
      // below would start that much too high: a factor at the known shift,
      // without M, estimates S's own.
      if (held && std::isfinite(lambda_min) &&
          matrix->FactorShiftCost(options.translation_offsets) >
              0.05 * std::abs(lambda_min) &&
          factor_at_known_shift()) {
        lambda_min = estimate_lambda_min(result.eta);
      }
      result.lambda_min_estimate = lambda_min;
      // Without an estimate (Lanczos did not converge) there is nothing to
      // tighten towards: no proof is tried.
      const bool estimated = std::isfinite(lambda_min);
      const double inf = std::numeric_limits<double>::infinity();
      const double tight =
          estimated ? std::max(eta_target, -1.1 * lambda_min) : inf;
      const double first_shift = estimated ? double_start(lambda_min) : inf;
      for (double c = std::max(start, std::min(first_shift, result.eta));
           c < result.eta && !result.out_of_time; c *= 8) {
        if (prove(c, ProofPrecision::kDouble)) break;
      }
      if (use_extended && tight < result.eta / 4 && !result.out_of_time) {
        prove(tight, ProofPrecision::kDoubleDouble);
      }
    }
    return finish();
  }
  if (first == ProofPrecision::kDoubleDouble) {
    if (prove(eta_target, first) && result.eta <= goal) return finish();
  } else if (double_floor <= goal / 4 || !use_extended) {
    const double c1 = std::max(eta_target, 1.5 * double_floor);
    if (prove(c1, first) && result.eta <= goal) return finish();
    if (goal / 4 > c1 && prove(goal / 4, ProofPrecision::kDouble) &&
        result.eta <= goal) {
      return finish();
    }
  } else {
    // Double cannot reach the goal with the shifts its next proof starts
    // with. A fresh matrix's come from Lbar's round-off (3-13x above the
    // bounds K's own factorization then has, weighted by what they cost);
    // a completed proof sets the next ones from its bounds. Where that is
    // expected to bring double within reach (a floor within
    // kLearnedShiftReach goals) and a double-double factorization costs
    // well over two double ones (learned_shift_min_multiply_adds), a double
    // proof at what the first shifts cost, then one at what its bounds cost
    // (if that and the first's rotation rows' bound are within half the
    // goal), come before double-double. Either ends the verification
    // within half the goal; above it double-double tightens as before.
    if (double_floor <= kLearnedShiftReach * goal &&
        matrix->factorization_flops() >=
            options.learned_shift_min_multiply_adds &&
        !options.test_in_double_first) {
      const double c1 = std::max(eta_target, 1.5 * double_floor);
      if (prove(c1, ProofPrecision::kDouble)) {
        if (result.eta <= goal / 2) return finish();
        const double c2 = std::max(
            eta_target,
            1.5 * matrix->DoubleShiftCost(options.translation_offsets));
        if (c2 + matrix->backward_error() <= goal / 2 &&
            prove(c2, ProofPrecision::kDouble) && result.eta <= goal / 2) {
          return finish();
        }
      }
    }
    if (options.likely_optimal && !options.test_in_double_first) {
      // A probably optimal candidate goes to double-double directly (see
      // VerificationOptions::likely_optimal).
      if (attempt(goal / 16) && result.eta <= goal) return finish();
      // Failed: lambda_min(S) < -goal / 16. Usually a lifted saddle of rank
      // d (rounding loses nothing there either), whose witness step 4
      // finds: the near-optimality test of step 2 is skipped. A
      // near-optimal candidate is recognized after step 4 instead, by the
      // witness's curvature, and its double-double proofs then step up by 8
      // from the goal (without step 2's Lanczos estimate).
      suspect_saddle = !(result.eta <= eta_max);
    }
  }

  // 2. Near-optimal (lambda_min(S) > -eta_max up to round-off) or not?
  bool near_optimal = result.eta <= eta_max;
  if (result.out_of_time) return finish();
  // The double factor is that of S + eta_max I (no proof since).
  bool factor_at_eta_max = false;
  if (!near_optimal && !suspect_saddle && eta_max > eta_target &&
      fits(matrix->PredictedSeconds(ProofPrecision::kDouble))) {
    near_optimal = factor_at_eta_max = matrix->Factorize(Lambda, eta_max);
    // Tested in double first (test_in_double_first): a likely optimal
    // candidate that is not near-optimal is a lifted saddle, as after a
    // failed double-double proof above.
    suspect_saddle =
        !near_optimal && options.likely_optimal && options.test_in_double_first;
  }
  if (result.out_of_time) return finish();
  // 3. Near-optimal: tighten the proof.
  if (near_optimal) {
    if (use_extended) {
      prove_extended(factor_at_eta_max);
    } else {
      // Double only: the strict proofs need shifts above what the
      // translation shift mu costs and above those that failed already;
      // start just above the estimate of lambda_min(S) from the factor at
      // eta_max and step up by 8.
      double start =
          std::max({eta_target, 1.5 * double_floor, 2 * failed_double,
                    std::numeric_limits<double>::min()});
      if (factor_at_eta_max) {
        result.lambda_min_estimate = estimate_lambda_min(eta_max);
        if (std::isfinite(result.lambda_min_estimate)) {
          start = std::max(start, double_start(result.lambda_min_estimate));
        }
      }
      for (double c = start; c < result.eta; c = std::min(8 * c, eta_max)) {
        if (prove(c, ProofPrecision::kDouble) || c >= eta_max) break;
      }
    }
    if (result.eta <= eta_max || result.out_of_time) return finish();
  }

  // 4. A witness of negative curvature. Bracket lambda_min(S) from below:
  // S + cI is PD for c > lambda_max(Lambda).
  double c_upper = 1.01 * MaxBlockEigenvalue(Lambda, d) + eta_target;
  double c = std::max(eta_target, eta_max);
  // Poor candidate? With c_vacuous = tr(Lambda) / dn every proven shift
  // c >= c_vacuous gives the bound tr(Lambda) - c d n <= 0. One factorization
  // at c_vacuous tells: if it fails, so would every smaller shift, so no
  // bound worth proving exists: the witness comes from Lanczos on S if that
  // converges (cubicle's file guess 0.45 -> 0.19 s, torus3D 0.24 -> 0.13 s),
  // else the ladder starts at c_vacuous (skipping up to ten factorizations
  // that fail late). If it succeeds, the ladder stops there at the latest.
  const double c_vacuous = BlockDiagonalTrace(Lambda, d) / Lambda.cols();
  double factor_shift = 0;  // The smallest shift proven here.
  bool proven = false;
  bool factor_is_current = false;  // The double factor is that at factor_shift.
  // The ladder's first two shifts before the poor-candidate test, 64 and
  // 256 eta_max: a saddle's negative curvature is usually mild (2D cities,
  // kappa 100 at 10^5 poses: lambda_min(S) = -3 eta_max; kappa 30 at 10^5:
  // -16 to -19 eta_max; kappa 100 at 10^6: -26 eta_max), so one of these
  // proofs is the one the ladder ends at, and the test's factorization is
  // saved; a poor candidate pays up to two failed factorizations more. The
  // first at 64 rather than 16 eta_max: the measured saddles below -16
  // eta_max then take one proof instead of a failed one and one at 256
  // (10^6: ~40 s each); those above take one either way. (16 eta_max
  // when 64 eta_max is at or above the vacuous shift.)
  const double c0 = c, limit = std::min(c_vacuous, c_upper);
  for (const double m : {64 * c0 < limit ? 64.0 : 16.0, 256.0}) {
    if (!suspect_saddle || proven || !(m * c0 < limit)) break;
    c = m * c0;  // If it fails, the ladder goes on above it.
    if (prove(c, ProofPrecision::kDouble)) {
      proven = factor_is_current = true;
      factor_shift = c;
    }
    if (result.out_of_time) return finish();
  }
  if (!proven && c_vacuous > c && c_vacuous < c_upper) {
    if (prove(c_vacuous, ProofPrecision::kDouble)) {
      c_upper = c_vacuous;
      proven = factor_is_current = true;
      factor_shift = c_vacuous;
    } else {
      result.vacuous_bound = true;
      if (result.out_of_time) return finish();
      if (fits(0) && lanczos_is_cheap() &&
          FindNegativeCurvature(problem, Lambda, &result)) {
        return finish();
      }
      c = c_vacuous;
    }
  }
  for (int step = 0; c < c_upper && !result.out_of_time; ++step) {
    if (step == 2 && matrix->supernodal() && !result.vacuous_bound && fits(0) &&
        lanczos_is_cheap()) {
      // lambda_min(S) < -256 max(eta_target, eta_max): usually clear
      // negative curvature (a saddle or a poor candidate), which Lanczos on
      // S finds in a few dozen products with Q; jump the shift just past
      // it. Only worth it when factorizations are expensive (supernodal:
      // heavy fill, e.g. torus3D); sparser factorizations are cheaper than
      // the Lanczos run. (Not again after the poor-candidate test: it
      // already ran, and failed.)
      if (FindNegativeCurvature(problem, Lambda, &result)) {
        c = std::max(c,
                     std::min(-1.1 * result.direction_curvature, c_upper) / 16);
      }
    }
    c = std::min(16 * std::max(c, std::numeric_limits<double>::min()), c_upper);
    // c_vacuous (or the saddle's first shift) is proven already.
    if (proven && c >= factor_shift) break;
    factor_is_current = prove(c, ProofPrecision::kDouble);
    if (factor_is_current) {
      proven = true;
      factor_shift = c;
      break;
    }
  }
  if (!proven) return finish();  // Only round-off can make this fail.
  if (result.eta <= eta_max || result.out_of_time) return finish();
  if (result.direction.size() == 0 && fits(0)) {
    // lambda_min(S_mu) > -c: the largest eigenvalue of (S_mu + cI)^{-1} is
    // 1 / (lambda_min + c). (Refactorize if the ladder failed after the
    // poor-candidate test proved c_vacuous.)
    if (!factor_is_current &&
        !matrix->Prove(Lambda, factor_shift, ProofPrecision::kDouble)) {
      return finish();
    }
    // Accuracy: the tightening below sets its shift 5% above the estimate,
    // whose error is about the tolerance times factor_shift (up to 16
    // |lambda_min|), so it needs a tight tolerance. The witness alone (the
    // staircase's escape) needs only a direction of clearly negative
    // curvature, which its Rayleigh quotient, computed afresh below,
    // measures; 1e-2 converges in the first Lanczos basis where 1e-8 took
    // two restarts (a 10^5-pose city's saddle: 51 -> 21 solves, 4.5 -> 1.3
    // s; the curvature -0.0153361 against -0.0153380).
    const double tolerance = options.tighten_uncertified ? 1e-8 : 1e-2;
    ShiftInvertOperator op(matrix);
    const int dim = matrix->dimension();
    Spectra::SymEigsSolver<ShiftInvertOperator> eigs(op, 1, std::min(20, dim));
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestAlge, 1000, tolerance);
    if (eigs.info() == Spectra::CompInfo::Successful) {
      result.lambda_min_estimate = 1.0 / eigs.eigenvalues()(0) - factor_shift;
      result.direction = eigs.eigenvectors().col(0).normalized();
      result.direction_curvature = result.direction.dot(
          MultiplyCertificate(problem, Lambda, result.direction));
    } else {
      LOG(WARNING) << "shift-and-invert Lanczos did not converge";
    }
    // Tighten the shift to just above the estimate, unless the bound stays
    // vacuous there too (a shift >= c_vacuous bounds F by at most 0).
    if (options.tighten_uncertified &&
        std::isfinite(result.lambda_min_estimate)) {
      const double tight =
          std::max(eta_target, -1.05 * result.lambda_min_estimate);
      if (tight < factor_shift && tight < c_vacuous) {
        prove(tight, ProofPrecision::kDouble);
      }
    }
  }
  // No clear negative curvature of S itself (the direction's Rayleigh
  // quotient, from products with Q, is above -eta_max): the failures were
  // round-off (large maps: mu's cost); prove it in double-double.
  if (use_extended && result.eta > eta_max &&
      !(result.direction_curvature < -eta_max)) {
    prove_extended(false);
  }
  return finish();
}

}  // namespace ceres_sesync::internal
