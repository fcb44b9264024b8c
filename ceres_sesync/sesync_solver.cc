#include "ceres_sesync/sesync_solver.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>

#include "ceres_sesync/internal/ceres_local_solver.h"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "glog/logging.h"

namespace ceres_sesync {
namespace {

using Clock = std::chrono::steady_clock;
double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

internal::PreconditionerType ToInternal(SolverOptions::Preconditioner p) {
  switch (p) {
    case SolverOptions::Preconditioner::kNone:
      return internal::PreconditionerType::kNone;
    case SolverOptions::Preconditioner::kBlockJacobi:
      return internal::PreconditionerType::kBlockJacobi;
    case SolverOptions::Preconditioner::kSparseCholesky:
      return internal::PreconditionerType::kSparseCholesky;
    case SolverOptions::Preconditioner::kRegularizedQ:
      return internal::PreconditionerType::kRegularizedQ;
  }
  return internal::PreconditionerType::kNone;
}

double MaxDiagonal(const internal::SparseMatrix& A) {
  double m = 0;
  for (int k = 0; k < A.rows(); ++k) m = std::max(m, A.coeff(k, k));
  return m;
}

// Poses from rotations R (d x dn) and translations T (d x n), expressed in the
// documented gauge: the FIX pose (else pose 0) sits at its initial value (else
// at the identity).
Poses ToPosesInGauge(const PoseGraph& graph, const Eigen::MatrixXd& R,
                     const Eigen::MatrixXd& T) {
  const int d = graph.dimension, n = graph.num_poses;
  const int g = graph.fixed_pose >= 0 ? graph.fixed_pose : 0;
  Eigen::MatrixXd RG = Eigen::MatrixXd::Identity(d, d);
  Eigen::VectorXd tG = Eigen::VectorXd::Zero(d);
  if (!graph.initial_poses.empty()) {
    RG = graph.initial_poses[g].R;
    tG = graph.initial_poses[g].t;
  }
  const Eigen::MatrixXd A = RG * R.middleCols(d * g, d).transpose();
  const Eigen::VectorXd tg = T.col(g);
  Poses poses(n);
  for (int i = 0; i < n; ++i) {
    poses[i].R = internal::ProjectToRotation(A * R.middleCols(d * i, d));
    poses[i].t = A * (T.col(i) - tg) + tG;
  }
  return poses;
}

Poses SolveImpl(const PoseGraph& graph, const Poses* initial,
                const SolverOptions& options, SolverSummary* summary) {
  const auto start = Clock::now();
  *summary = SolverSummary();
  summary->lambda_min_estimate = std::numeric_limits<double>::quiet_NaN();
  SolverSummary& s = *summary;
  s.dimension = graph.dimension;
  s.num_poses = graph.num_poses;
  s.num_measurements = static_cast<int>(graph.measurements.size());
  s.strict_round_off = options.strict_round_off;
  if (!ValidatePoseGraph(graph, &s.message)) {
    s.status = SolverSummary::Status::kInvalidInput;
    return {};
  }
  const int d = graph.dimension, n = graph.num_poses;
  const int r0 = options.initial_rank > 0 ? options.initial_rank : d + 2;
  if (r0 < d + 1 || options.max_rank < r0) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = "initial_rank must be >= d + 1 and <= max_rank";
    return {};
  }
  if (initial && static_cast<int>(initial->size()) != n) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = "initial poses: wrong number of poses";
    return {};
  }
  if (n == 1) {  // Nothing to estimate: the pose is the gauge.
    s.status = SolverSummary::Status::kCertifiedOptimum;
    s.final_rank = d;
    s.total_time_s = Seconds(start);
    return ToPosesInGauge(graph, Eigen::MatrixXd::Identity(d, d),
                          Eigen::MatrixXd::Zero(d, 1));
  }

  // Data matrices.
  auto t = Clock::now();
  internal::SESyncProblem problem(
      graph, internal::ResolveNumThreads(options.num_threads));
  if (!problem.ok()) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = "the translational Laplacian is not positive definite";
    return {};
  }
  internal::CertificateMatrix certificate(problem, options.strict_round_off);
  internal::SESyncPreconditioner preconditioner(
      problem, ToInternal(options.preconditioner),
      options.regularized_cholesky_max_condition, &certificate);
  const double scale = MaxDiagonal(problem.D());
  // Objective values below this are zero up to round-off (F is a sum of
  // squares weighted by kappa and tau).
  double total_weight = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    total_weight += e.kappa + e.tau;
  }
  const double zero_objective = 1e-12 * total_weight;
  s.data_time_s = Seconds(t);

  // Initialization.
  t = Clock::now();
  Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(r0, d * n);
  if (initial) {
    for (int i = 0; i < n; ++i) {
      Y.block(0, d * i, d, d) = internal::ProjectToRotation((*initial)[i].R);
    }
  } else if (options.initialization ==
             SolverOptions::Initialization::kVertices) {
    if (graph.initial_poses.empty()) {
      s.status = SolverSummary::Status::kInvalidInput;
      s.message =
          "initialization from vertices requested, but the graph has "
          "no initial poses";
      return {};
    }
    for (int i = 0; i < n; ++i) {
      Y.block(0, d * i, d, d) = graph.initial_poses[i].R;
    }
  } else if (options.initialization == SolverOptions::Initialization::kRandom) {
    std::mt19937_64 rng(options.seed);
    Y = RandomStiefelProductPoint(d, r0, n, &rng);
  } else {
    Eigen::MatrixXd R;
    if (!internal::ChordalRotationsFromLaplacian(problem.RotationLaplacian(), d,
                                                 &R)) {
      s.status = SolverSummary::Status::kInvalidInput;
      s.message = "chordal initialization failed";
      return {};
    }
    Y.topRows(d) = R;
  }
  s.initialization_time_s = Seconds(t);

  internal::SESyncCost cost(&problem, &preconditioner);
  RiemannianTrustRegionOptions rtr;
  rtr.max_iterations = options.max_iterations;
  rtr.max_inner_iterations = options.max_inner_iterations;
  rtr.gradient_tolerance = 0;
  rtr.relative_decrease_tolerance = options.relative_decrease_tolerance;
  internal::VerificationResult verification;
  double sdp_value = 0;
  for (int r = r0;; ++r) {
    SolverSummary::Level level;
    level.rank = r;
    rtr.callback = [&](int it, double f, double g, double radius, int inner) {
      if (options.verbose) {
        LOG(INFO) << "rank " << r << " iter " << it << " F " << f << " |grad| "
                  << g << " radius " << radius << " tCG " << inner;
      }
      return !options.callback || options.callback(r, it, f, g, radius);
    };
    // Optimize; the gradient tolerance is relative to the final F, so repeat
    // (cheaply, from the current point) if F dropped below the guess.
    t = Clock::now();
    double f = cost.Evaluate(Y);
    const bool use_ceres =
        options.local_solver == SolverOptions::LocalSolver::kCeresLbfgs;
    if (use_ceres) {
      internal::CeresLocalSolverSummary ceres_summary;
      internal::MinimizeWithCeresLbfgs(
          problem, options.ceres_lbfgs_max_iterations,
          options.ceres_lbfgs_gradient_tolerance,
          options.relative_decrease_tolerance,
          options.max_time_s > 0
              ? std::max(1e-3, options.max_time_s - Seconds(start))
              : 0,
          &Y, &ceres_summary);
      level.iterations += ceres_summary.iterations;
      level.termination = ceres_summary.termination;
    }
    for (int pass = 0; pass < 3 && !use_ceres; ++pass) {
      const double floor = 1e-14 * scale;
      rtr.preconditioned_gradient_tolerance =
          options.relative_preconditioned_gradient_tolerance *
          std::sqrt(std::max(f, floor));
      if (options.max_time_s > 0) {
        rtr.max_time_s = std::max(1e-3, options.max_time_s - Seconds(start));
      }
      RiemannianTrustRegionSummary rtr_summary;
      MinimizeRiemannianTrustRegion(rtr, &cost, &Y, &rtr_summary);
      level.iterations += rtr_summary.iterations;
      level.hessian_vector_products += rtr_summary.hessian_vector_products;
      level.gradient_norm = rtr_summary.final_gradient_norm;
      level.termination = rtr_summary.TerminationString();
      const double previous = f;
      f = rtr_summary.final_cost;
      if (rtr_summary.termination != RiemannianTrustRegionSummary::Termination::
                                         kPreconditionedGradientTolerance ||
          f >= 0.5 * previous) {
        break;
      }
    }
    cost.Evaluate(Y);  // Make Y current (Lambda at Y).
    if (use_ceres) {
      Eigen::MatrixXd gradient;
      cost.Gradient(&gradient);
      level.gradient_norm = gradient.norm();
    }
    level.optimize_time_s = Seconds(t);
    // F(Y) = tr(Q Y^T Y) = tr(Lambda): the dual objective of these multipliers.
    sdp_value = internal::BlockDiagonalTrace(cost.Lambda(), d);
    level.sdp_value = sdp_value;

    // Verify.
    t = Clock::now();
    const double eta_floor = options.min_relative_eta * scale;
    const double eta_target =
        std::max(eta_floor, options.certification_target_relative_bound *
                                sdp_value / (d * n));
    const double eta_max =
        std::max(eta_floor, options.certification_max_relative_bound *
                                sdp_value / (d * n));
    verification = internal::VerifyCertificate(
        problem, cost.Lambda(), eta_target, eta_max, &certificate);
    if (!verification.certified && sdp_value <= zero_objective) {
      // F >= 0 always: a (numerically) zero value is optimal as it stands.
      verification.certified = true;
      verification.eta = 0;
    }
    level.verify_time_s = Seconds(t);
    level.certified = verification.certified;
    level.eta = verification.eta;
    level.lambda_min_estimate = verification.lambda_min_estimate;
    s.factorizations += verification.factorizations;
    s.iterations += level.iterations;
    s.hessian_vector_products += level.hessian_vector_products;
    s.optimization_time_s += level.optimize_time_s;
    s.verification_time_s += level.verify_time_s;
    s.levels.push_back(level);
    s.final_rank = r;
    if (options.verbose) {
      LOG(INFO) << "rank " << r << ": F(Y) " << sdp_value << ", eta "
                << verification.eta << ", lambda_min estimate "
                << verification.lambda_min_estimate
                << (verification.certified ? " (certified)" : "");
    }
    if (verification.certified) {
      s.status = SolverSummary::Status::kCertifiedOptimum;
      break;
    }
    if (verification.eigensolver_failed) {
      s.status = SolverSummary::Status::kEigenImprecision;
      break;
    }
    if (options.max_time_s > 0 && Seconds(start) >= options.max_time_s) {
      s.status = SolverSummary::Status::kTimeLimit;
      break;
    }
    if (r >= options.max_rank) {
      s.status = SolverSummary::Status::kMaxRankReached;
      break;
    }
    // Escape the saddle along [0; v^T] at rank r + 1, backtracking.
    Eigen::MatrixXd Y_plus = Eigen::MatrixXd::Zero(r + 1, d * n);
    Y_plus.topRows(r) = Y;
    Eigen::MatrixXd V = Eigen::MatrixXd::Zero(r + 1, d * n);
    V.row(r) = verification.direction.transpose();
    double max_block_norm = 0;
    for (int i = 0; i < n; ++i) {
      max_block_norm = std::max(
          max_block_norm, verification.direction.segment(d * i, d).norm());
    }
    double alpha = 1.0 / max_block_norm;
    bool escaped = false;
    Eigen::MatrixXd Y_trial;
    for (int k = 0; k < 60 && !escaped; ++k, alpha *= 0.5) {
      RetractStiefelProduct(Y_plus, alpha * V, d, &Y_trial);
      escaped = cost.Evaluate(Y_trial) < sdp_value;
    }
    if (!escaped) {
      s.status = SolverSummary::Status::kSaddleNotEscaped;
      cost.Evaluate(Y);
      break;
    }
    Y = Y_trial;
  }

  // Round and recover translations.
  t = Clock::now();
  Eigen::MatrixXd R = internal::RoundSolution(Y, d);
  if (options.refine_rounded_solution) {
    // Local search on O(d)^n = St(d, d)^n from the rounded rotations (blocks
    // stay in SO(d) by continuity). A no-op when the relaxation is exact.
    const double rounded = cost.Evaluate(R);
    if (rounded > sdp_value * (1 + 1e-12)) {
      RiemannianTrustRegionSummary refine_summary;
      rtr.callback = nullptr;
      if (options.max_time_s > 0) {
        rtr.max_time_s = std::max(1e-3, options.max_time_s - Seconds(start));
      }
      rtr.preconditioned_gradient_tolerance =
          options.relative_preconditioned_gradient_tolerance *
          std::sqrt(rounded);
      MinimizeRiemannianTrustRegion(rtr, &cost, &R, &refine_summary);
      s.iterations += refine_summary.iterations;
      s.hessian_vector_products += refine_summary.hessian_vector_products;
      R = internal::ProjectBlocksToRotations(R, d);
    }
  }
  const Eigen::MatrixXd T = problem.RecoverTranslations(R);
  Poses poses = ToPosesInGauge(graph, R, T);
  s.rounding_time_s = Seconds(t);

  s.sdp_value = sdp_value;
  s.objective = EvaluateObjective(graph, poses);
  s.eta = verification.eta;
  s.lambda_min_estimate = verification.lambda_min_estimate;
  s.rounding_gap = (s.objective - sdp_value) / std::max(sdp_value, 1e-300);
  // tr(Lambda) - eta d n bounds the optimum whenever S + eta I was proven
  // PSD, certified or not.
  s.lower_bound = std::isfinite(s.eta)
                      ? std::max(0.0, sdp_value - s.eta * d * n)
                      : 0.0;  // F >= 0 always.
  // The attained objective bounds the optimum too (guards F(Y) round-off).
  s.lower_bound = std::min(s.lower_bound, s.objective);
  s.suboptimality_bound = std::max(0.0, s.objective - s.lower_bound);
  s.relative_suboptimality_bound =
      s.lower_bound > 0               ? s.suboptimality_bound / s.lower_bound
      : s.objective <= zero_objective ? 0
                                      : std::numeric_limits<double>::infinity();
  if (s.status == SolverSummary::Status::kCertifiedOptimum &&
      !(s.relative_suboptimality_bound <=
            options.certification_max_relative_bound &&
        (s.rounding_gap <= options.certification_max_rounding_gap ||
         s.objective <= zero_objective))) {
    // Y is optimal for the SDP, but the rounded poses are not provably
    // optimal: the relaxation is not exact on this problem.
    s.status = SolverSummary::Status::kRelaxationNotExact;
  }
  s.total_time_s = Seconds(start);
  return poses;
}

}  // namespace

Poses Solve(const PoseGraph& graph, const SolverOptions& options,
            SolverSummary* summary) {
  return SolveImpl(graph, nullptr, options, summary);
}

Poses Solve(const PoseGraph& graph, const Poses& initial,
            const SolverOptions& options, SolverSummary* summary) {
  return SolveImpl(graph, &initial, options, summary);
}

std::string SolverSummary::StatusString() const {
  switch (status) {
    case Status::kCertifiedOptimum:
      return "CERTIFIED_OPTIMUM";
    case Status::kRelaxationNotExact:
      return "RELAXATION_NOT_EXACT";
    case Status::kSaddleNotEscaped:
      return "SADDLE_NOT_ESCAPED";
    case Status::kEigenImprecision:
      return "EIGEN_IMPRECISION";
    case Status::kMaxRankReached:
      return "MAX_RANK_REACHED";
    case Status::kTimeLimit:
      return "TIME_LIMIT";
    case Status::kInvalidInput:
      return "INVALID_INPUT";
  }
  return "UNKNOWN";
}

std::string SolverSummary::BriefReport() const {
  char buf[512];
  if (status == Status::kInvalidInput) {
    std::snprintf(buf, sizeof(buf), "SE-Sync: INVALID_INPUT: %s",
                  message.c_str());
    return buf;
  }
  std::snprintf(buf, sizeof(buf),
                "SE-Sync: %s, F(x) = %.10g, lower bound %.10g, relative "
                "suboptimality <= %.2e, rank %d, %d iterations, %.3f s",
                StatusString().c_str(), objective, lower_bound,
                relative_suboptimality_bound, final_rank, iterations,
                total_time_s);
  return buf;
}

std::string SolverSummary::FullReport() const {
  std::string out;
  char buf[512];
  auto line = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof(buf), format, args...);
    out += buf;
  };
  out += "\nSE-Sync Solver Report\n---------------------\n";
  line("%-34s %d\n", "Dimension", dimension);
  line("%-34s %d\n", "Poses", num_poses);
  line("%-34s %d\n", "Measurements", num_measurements);
  if (status == Status::kInvalidInput) {
    line("%-34s %s\n", "Error", message.c_str());
    return out;
  }
  out += "\nRiemannian staircase\n";
  line("  %4s %6s %8s %18s %11s %11s %11s %s\n", "rank", "iters", "Hv", "F(Y)",
       "|grad F|", "eta", "lambda_min", "termination");
  for (const Level& l : levels) {
    line("  %4d %6d %8d %18.12g %11.3e %11.3e %11.3e %s%s\n", l.rank,
         l.iterations, l.hessian_vector_products, l.sdp_value, l.gradient_norm,
         l.eta, l.lambda_min_estimate, l.termination.c_str(),
         l.certified ? ", certified" : "");
  }
  out += "\nSolution\n";
  line("%-34s %.12g\n", "Objective F(x)", objective);
  line("%-34s %.12g\n", "SDP value F(Y)", sdp_value);
  line("%-34s %.3e\n", "Rounding gap (F(x)-F(Y))/F(Y)", rounding_gap);
  line("%-34s %.12g\n", "Lower bound F(Y) - eta d n", lower_bound);
  line("%-34s %.3e\n", "Suboptimality bound", suboptimality_bound);
  line("%-34s %.3e\n", "Relative suboptimality bound",
       relative_suboptimality_bound);
  line("%-34s %.3e (%s)\n", "eta (S + eta I proven PD)", eta,
       strict_round_off ? "all round-off rigorous"
                        : "translation-block round-off to first order");
  if (std::isnan(lambda_min_estimate)) {
    line("%-34s %s\n", "lambda_min(S) estimate",
         "not computed (Cholesky test sufficed)");
  } else {
    line("%-34s %.3e\n", "lambda_min(S) estimate", lambda_min_estimate);
  }
  line("%-34s %d\n", "Final rank", final_rank);
  line("%-34s %d\n", "Trust-region iterations", iterations);
  line("%-34s %d\n", "Hessian-vector products", hessian_vector_products);
  line("%-34s %d\n", "Certificate factorizations", factorizations);
  out += "\nTime (seconds)\n";
  line("%-34s %.4f\n", "  Data matrices", data_time_s);
  line("%-34s %.4f\n", "  Initialization", initialization_time_s);
  line("%-34s %.4f\n", "  Optimization", optimization_time_s);
  line("%-34s %.4f\n", "  Verification", verification_time_s);
  line("%-34s %.4f\n", "  Rounding", rounding_time_s);
  line("%-34s %.4f\n", "Total", total_time_s);
  line("\n%-34s %s\n", "Status", StatusString().c_str());
  return out;
}

}  // namespace ceres_sesync
