#include "ceres_sesync/sesync_solver.h"

#include <cmath>
#include <cstdio>

#include "ceres_sesync/internal/staircase.h"

namespace ceres_sesync {
namespace {

// problem -> initialize -> staircase -> round -> continue -> report
// (internal/staircase.h).
Solution SolveImpl(const PoseGraph& graph, const Poses* initial,
                   const SolverOptions& options, SolverSummary* summary) {
  internal::Staircase staircase(graph, options, summary);
  if (!staircase.ok()) return {};
  if (initial && static_cast<int>(initial->size()) != graph.num_poses) {
    summary->status = SolverSummary::Status::kInvalidInput;
    summary->message = "initial poses: wrong number of poses";
    return {};
  }
  if (staircase.trivial()) return staircase.Trivial();
  Eigen::MatrixXd Y;
  if (!staircase.Initialize(initial, &Y)) return {};
  staircase.Run(&Y);
  Solution solution = staircase.Round(Y);
  staircase.Continue(&Y, &solution);
  staircase.Report(Y, solution);
  return solution;
}

}  // namespace

Poses Solve(const PoseGraph& graph, const SolverOptions& options,
            SolverSummary* summary) {
  return SolveImpl(graph, nullptr, options, summary).poses;
}

Poses Solve(const PoseGraph& graph, const Poses& initial,
            const SolverOptions& options, SolverSummary* summary) {
  return SolveImpl(graph, &initial, options, summary).poses;
}

void Solve(const PoseGraph& graph, const SolverOptions& options,
           Solution* solution, SolverSummary* summary) {
  *solution = SolveImpl(graph, nullptr, options, summary);
}

void Solve(const PoseGraph& graph, const Poses& initial,
           const SolverOptions& options, Solution* solution,
           SolverSummary* summary) {
  *solution = SolveImpl(graph, &initial, options, summary);
}

std::string SolverSummary::StatusString() const {
  switch (status) {
    case Status::kCertifiedOptimum:
      return "CERTIFIED_OPTIMUM";
    case Status::kBoundAboveTolerance:
      return "BOUND_ABOVE_TOLERANCE";
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
                "suboptimality <= %.2e (proof in %s), rank %d%s, %d "
                "iterations, %.3f s",
                StatusString().c_str(), objective, lower_bound,
                relative_suboptimality_bound, proof_precision.c_str(),
                final_rank, relaxation_exact ? "" : ", relaxation not exact",
                iterations, total_time_s);
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
  if (num_landmarks > 0 || num_priors > 0) {
    line("%-34s %d\n", "Landmarks", num_landmarks);
    line("%-34s %d\n", "Landmark measurements", num_landmark_measurements);
    line("%-34s %d\n", "Priors", num_priors);
  }
  if (status == Status::kInvalidInput) {
    line("%-34s %s\n", "Error", message.c_str());
    return out;
  }
  out += "\nRiemannian staircase\n";
  line("  %4s %6s %8s %18s %11s %11s %11s %7s %s\n", "rank", "iters", "Hv",
       "F(Y)", "|grad F|", "eta", "lambda_min", "fact.", "termination");
  for (const Level& l : levels) {
    char factorizations[32];
    std::snprintf(factorizations, sizeof(factorizations), "%d+%d",
                  l.factorizations, l.extended_factorizations);
    line("  %4d %6d %8d %18.12g %11.3e %11.3e %11.3e %7s %s%s\n", l.rank,
         l.iterations, l.hessian_vector_products, l.sdp_value, l.gradient_norm,
         l.eta, l.lambda_min_estimate, factorizations, l.termination.c_str(),
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
  if (std::isfinite(eta)) {
    line("%-34s %.3e (proof in %s, all round-off included)\n",
         "eta (S + eta I proven PSD)", eta, proof_precision.c_str());
  } else {
    line("%-34s %s\n", "eta (S + eta I proven PSD)", "none proven");
  }
  line("%-34s %s\n", "Relaxation exact",
       relaxation_exact ? "yes" : "no (rounding gap or rank)");
  if (std::isnan(lambda_min_estimate)) {
    line("%-34s %s\n", "lambda_min(S) estimate",
         "not computed (Cholesky test sufficed)");
  } else {
    line("%-34s %.3e\n", "lambda_min(S) estimate", lambda_min_estimate);
  }
  line("%-34s %d\n", "Final rank", final_rank);
  line("%-34s %d\n", "Trust-region iterations", iterations);
  line("%-34s %d\n", "Hessian-vector products", hessian_vector_products);
  line("%-34s %s\n", "Preconditioner", preconditioner.c_str());
  line("%-34s %d double, %d double-double (%.4f s)\n",
       "Certificate factorizations", factorizations, extended_factorizations,
       extended_proof_time_s);
  if (certificate_tests > 0) {
    line("%-34s %d (%s)\n", "Certificate tests after escapes",
         certificate_tests,
         !levels.empty() && levels.back().certificate_test_passed
             ? "the last passed: its descent stopped there"
             : "none passed");
  }
  out += "\nTime (seconds)\n";
  line("%-34s %.4f\n", "  Data matrices", data_time_s);
  line("%-34s %.4f\n", "  Initialization", initialization_time_s);
  line("%-34s %.4f\n", "  Optimization", optimization_time_s);
  line("%-34s %.4f\n", "  Verification", verification_time_s);
  line("%-34s %.4f\n", "  Rounding", rounding_time_s);
  line("%-34s %.4f\n", "Total", total_time_s);
  line("\n%-34s %s\n", "Status", StatusString().c_str());
  if (!message.empty()) line("%-34s %s\n", "", message.c_str());
  return out;
}

}  // namespace ceres_sesync
