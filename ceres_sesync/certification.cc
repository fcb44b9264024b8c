#include "ceres_sesync/certification.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/objective_bound.h"
#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "glog/logging.h"

namespace ceres_sesync {

bool Certify(const PoseGraph& graph, const Poses& candidate,
             const CertifyOptions& options, Certificate* certificate,
             std::string* error) {
  if (graph.num_landmarks > 0) {
    if (error) {
      *error = "the graph has " + std::to_string(graph.num_landmarks) +
               " landmarks: certify a Solution with their positions";
    }
    return false;
  }
  return Certify(graph, Solution{candidate, {}}, options, certificate, error);
}

bool Certify(const PoseGraph& graph, const Solution& candidate_solution,
             const CertifyOptions& options, Certificate* certificate,
             std::string* error) {
  const auto start = std::chrono::steady_clock::now();
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!ValidatePoseGraph(graph, error)) return false;
  const Poses& candidate = candidate_solution.poses;
  const LandmarkPositions& landmarks = candidate_solution.landmarks;
  const int d = graph.dimension, n = graph.num_poses;
  if (static_cast<int>(candidate.size()) != n) {
    return fail("candidate has " + std::to_string(candidate.size()) +
                " poses, the graph has " + std::to_string(n));
  }
  if (static_cast<int>(landmarks.size()) != graph.num_landmarks) {
    return fail("candidate has " + std::to_string(landmarks.size()) +
                " landmark positions, the graph has " +
                std::to_string(graph.num_landmarks) + " landmarks");
  }
  for (int l = 0; l < graph.num_landmarks; ++l) {
    if (landmarks[l].size() != d || !landmarks[l].allFinite()) {
      return fail("candidate landmark " + std::to_string(l) + " (vertex " +
                  std::to_string(graph.landmark_ids[l]) +
                  ") is not a finite d-vector");
    }
  }
  // The problem's rotation blocks: the poses, then R_w = I with priors
  // (sesync_problem.h: the candidate in the world frame is the extended
  // problem's point with w = (I, 0)).
  const internal::ProblemLayout layout(graph);
  const int n_rot = layout.num_rotations();
  Certificate c;
  Poses projected = candidate;
  Eigen::MatrixXd R(d, d * n_rot);
  R.rightCols(d * (n_rot - n)).setIdentity();
  for (int i = 0; i < n; ++i) {
    const Pose& p = candidate[i];
    if (p.R.rows() != d || p.R.cols() != d || p.t.size() != d) {
      return fail("candidate pose " + std::to_string(i) + " (vertex " +
                  std::to_string(graph.vertex_ids[i]) +
                  ") has the wrong dimension");
    }
    if (!p.R.allFinite() || !p.t.allFinite()) {
      return fail("candidate pose " + std::to_string(i) + " (vertex " +
                  std::to_string(graph.vertex_ids[i]) + ") is not finite");
    }
    projected[i].R = internal::ProjectToRotation(p.R);
    c.max_rotation_error =
        std::max(c.max_rotation_error, (projected[i].R - p.R).norm());
    R.middleCols(d * i, d) = projected[i].R;
  }
  LOG_IF(WARNING, c.max_rotation_error > options.rotation_warning_tolerance)
      << "Certify: candidate rotations are up to " << c.max_rotation_error
      << " (Frobenius) away from SO(" << d << "); certifying their projection";
  c.objective = EvaluateObjective(graph, projected, landmarks);
  c.lambda_min = std::numeric_limits<double>::quiet_NaN();

  if (n_rot == 1 && layout.num_translations() == 1) {
    // A single pose, nothing else: trivially optimal.
    c.certified = true;
  } else {
    const internal::SESyncProblem problem(
        graph, internal::ResolveNumThreads(options.num_threads));
    if (!problem.ok()) return fail("the translational Laplacian is singular");
    Eigen::MatrixXd RQ;
    problem.MultiplyQ(R, &RQ);
    const Eigen::MatrixXd Lambda = SymBlockDiagProduct(RQ, R, d);
    const double trace = internal::BlockDiagonalTrace(Lambda, d);
    c.rotation_objective = trace;
    // Largest eta for which the bound can still meet a relative bound b:
    // objective - (trace - eta d n) <= b (trace - eta d n), with the
    // objective rounded up as in the reported bound below, and b lowered by
    // a relative 1e-6 for the proof's own slack (the proven shift is c plus
    // its backward error; the lower bound is rounded down): a proof at
    // eta_max then certifies instead of landing just above the tolerance.
    const double objective_up =
        internal::ObjectiveUpperBound(graph, projected, landmarks);
    auto eta_for = [&](double b) {
      b *= 1 - 1e-6;
      return (b * trace - (objective_up - trace)) / (d * n_rot * (1 + b));
    };
    internal::VerificationOptions verification;
    verification.eta_max =
        std::max(eta_for(options.max_relative_suboptimality), 0.0);
    // The goal: goal_relative_suboptimality, or when the candidate's own
    // excess over tr(Lambda) (its translations and landmarks not optimal
    // for its rotations, e.g. a local solver stopped early) already exceeds
    // it, four times that excess: a bound the proof can still reach.
    const double excess = (objective_up - trace) / std::abs(trace);
    verification.eta_goal = eta_for(
        std::min(std::max(options.goal_relative_suboptimality, 4 * excess),
                 options.max_relative_suboptimality));
    verification.eta_target =
        std::max(options.target_relative_bound * std::abs(trace) / (d * n_rot),
                 std::numeric_limits<double>::min());
    switch (options.proof_arithmetic) {
      case SolverOptions::ProofArithmetic::kAutomatic:
        verification.policy = internal::ProofPolicy::kAutomatic;
        break;
      case SolverOptions::ProofArithmetic::kDouble:
        verification.policy = internal::ProofPolicy::kDouble;
        break;
      case SolverOptions::ProofArithmetic::kDoubleDouble:
        verification.policy = internal::ProofPolicy::kDoubleDouble;
        break;
    }
    internal::CertificateMatrix matrix(problem);
    // The translations that are optimal for the rotations (those of Q, and
    // so of S's near-null global rotations), from the gauge's: what double
    // proofs' translation shifts cost (see VerificationOptions).
    verification.translation_offsets =
        matrix.TranslationOffsets(problem.RecoverTranslations(R));
    const internal::VerificationResult v =
        internal::VerifyCertificate(problem, Lambda, verification, &matrix);
    c.eta = v.eta;
    c.lambda_min = v.lambda_min_estimate;
    c.factorizations = v.factorizations;
    c.extended_factorizations = v.extended_factorizations;
    c.extended_proof_time_s = v.extended_time_s;
    if (std::isfinite(v.eta)) {
      c.proof_precision = internal::ProofPrecisionName(v.precision);
      c.lower_bound = internal::ProvenLowerBound(Lambda, d, v.eta);
    }
    if (!v.certified && v.direction.size() == d * n_rot &&
        v.direction_curvature < 0) {
      c.negative_curvature_direction = v.direction;
      c.negative_curvature = v.direction_curvature;
    }
  }
  // F is a sum of squares: 0 is always a lower bound, and a candidate at
  // F = 0 (up to round-off relative to the total weight) is optimal.
  if (!(c.lower_bound >= 0)) c.lower_bound = 0;
  c.lower_bound = std::min(c.lower_bound, c.objective);
  const bool zero_objective =
      c.objective <= 1e-12 * internal::TotalPrecision(graph);
  // F(candidate) rounded up: the bound must not rest on round-off in F.
  c.suboptimality_bound =
      internal::ObjectiveUpperBound(graph, projected, landmarks) -
      c.lower_bound;
  // A numerically zero F is optimal by F >= 0 (no ratio to a zero bound).
  c.relative_suboptimality_bound =
      zero_objective      ? 0
      : c.lower_bound > 0 ? c.suboptimality_bound / c.lower_bound
                          : std::numeric_limits<double>::infinity();
  // Certified iff the proven relative bound is within the tolerance.
  c.certified = zero_objective || c.relative_suboptimality_bound <=
                                      options.max_relative_suboptimality;
  c.time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  if (!c.certified && options.improve_if_not_certified) {
    Solution improved;
    Solve(graph, projected, options.solver_options, &improved,
          &c.improvement_summary);
    c.improved_poses = std::move(improved.poses);
    c.improved_landmarks = std::move(improved.landmarks);
    c.has_improved_poses = !c.improved_poses.empty();
  }
  *certificate = std::move(c);
  return true;
}

std::string Certificate::BriefReport() const {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "Certificate: %s, F = %.10g, lower bound %.10g, relative "
                "suboptimality <= %.3e, eta %.3e (proof in %s), %.3f s",
                certified ? "CERTIFIED" : "NOT CERTIFIED", objective,
                lower_bound, relative_suboptimality_bound, eta,
                proof_precision.c_str(), time_s);
  return buf;
}

std::string Certificate::FullReport() const {
  std::string out = "\nCertificate Report\n------------------\n";
  char buf[512];
  auto line = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof(buf), format, args...);
    out += buf;
  };
  line("%-36s %.12g\n", "Objective F(candidate)", objective);
  line("%-36s %.12g\n", "F with optimal translations", rotation_objective);
  if (std::isnan(lambda_min)) {
    line("%-36s %s\n", "lambda_min(S) estimate",
         "not computed (Cholesky test sufficed)");
  } else {
    line("%-36s %.3e\n", "lambda_min(S) estimate", lambda_min);
  }
  if (std::isfinite(eta)) {
    line("%-36s %.3e (proof in %s, all round-off included)\n",
         "eta (S + eta I proven PSD)", eta, proof_precision.c_str());
  } else {
    line("%-36s %s\n", "eta (S + eta I proven PSD)", "none proven");
  }
  line("%-36s %d double, %d double-double (%.4f s)\n",
       "Certificate factorizations", factorizations, extended_factorizations,
       extended_proof_time_s);
  line("%-36s %.12g\n", "Lower bound on the optimum", lower_bound);
  line("%-36s %.3e\n", "Suboptimality bound", suboptimality_bound);
  line("%-36s %.3e\n", "Relative suboptimality bound",
       relative_suboptimality_bound);
  line("%-36s %.3e\n", "Max rotation distance from SO(d)", max_rotation_error);
  if (negative_curvature_direction.size() > 0) {
    line("%-36s %.3e\n", "Negative curvature v^T S v", negative_curvature);
  }
  line("%-36s %.4f\n", "Time (s)", time_s);
  line("%-36s %s\n", "Result", certified ? "CERTIFIED" : "NOT CERTIFIED");
  if (has_improved_poses) {
    out += "\nImproved solution (SE-Sync from the candidate):\n  " +
           improvement_summary.BriefReport() + "\n";
  }
  return out;
}

}  // namespace ceres_sesync
