// `ceres_sesync solve GRAPH.g2o`: SE-Sync with certification.

#include <cmath>
#include <cstdio>
#include <iostream>

#include "ceres_sesync/component_solver.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/json_writer.h"
#include "ceres_sesync/robust_solver.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "tools/commands.h"
#include "tools/progress.h"
#include "tools/robust_output.h"

DEFINE_string(tum, "", "Also write the poses as a TUM trajectory.");
DEFINE_string(init, "chordal",
              "Initialization, one of chordal|random|vertices.");
DECLARE_uint64(seed);  // Defined in generate_command.cc.
DEFINE_int32(initial_rank, 0, "Initial staircase rank (0: d + 2).");
DEFINE_int32(max_rank, 10, "Maximum staircase rank.");
DEFINE_string(preconditioner, "auto",
              "Truncated-CG preconditioner: auto (block-Jacobi where the "
              "exact one's factor is costly, else q)|q (regularized Q, exact "
              "Schur complement)|cholesky (of Q's sparse part)|jacobi|none.");
DEFINE_string(local_solver, "rtr",
              "Staircase local solver: rtr (built-in trust region) | "
              "ceres (ceres::GradientProblemSolver LBFGS).");
DEFINE_double(max_time, 0, "Wall-clock limit in seconds (0: none).");
DEFINE_double(
    gradient_tolerance,
    ceres_sesync::SolverOptions().relative_preconditioned_gradient_tolerance,
    "Relative preconditioned gradient tolerance of the "
    "local solver.");
DEFINE_bool(test_certificate_after_escape,
            ceres_sesync::SolverOptions().test_certificate_after_escape,
            "After a saddle escape, test the certificate during the new "
            "rank's optimization and stop it once the bound is provably "
            "within the tolerance (the poses are the same; the bound can be "
            "looser than after a converged descent).");
DEFINE_bool(test_certificate_near_convergence,
            ceres_sesync::SolverOptions().test_certificate_near_convergence,
            "Test the certificate of a level started at rank d (the chordal "
            "start) before its descent converges, once the gradient is "
            "small, and stop it if the verification's first proof holds "
            "(SolverOptions::test_certificate_near_convergence).");
DEFINE_bool(newton_at_rank_d, ceres_sesync::SolverOptions().newton_at_rank_d,
            "Precondition the first level's truncated CG with the "
            "Riemannian Hessian's inverse: in 2D from the start where it is "
            "cheap, else once its first solves are long "
            "(SolverOptions::newton_at_rank_d).");
DEFINE_bool(components, false,
            "Solve a disconnected graph per connected component (poses and "
            "landmarks linked by measurements), each in its own gauge (its "
            "first pose, or its FIX pose, fixed; the one with the priors in "
            "the world frame); the report and --json list the components. "
            "Without it a disconnected graph is an input error.");

DEFINE_bool(robust, false,
            "solve: outlier-robust solve (GNC with truncated least squares "
            "around SE-Sync); certified and the exit code then refer to the "
            "problem restricted to the accepted edges.");
DEFINE_double(inlier_threshold, 0,
              "solve --robust: TLS threshold c^2 on each measurement's term "
              "of the objective (0: the --inlier_probability quantile of "
              "chi^2 with d(d+1)/2 degrees of freedom; landmark measurements "
              "and priors: of their own degrees of freedom; > 0: every "
              "term's).");
DEFINE_double(inlier_probability,
              ceres_sesync::RobustSolverOptions().inlier_probability,
              "solve --robust: chi-square probability of the default "
              "threshold.");
DEFINE_string(known_inliers, "odometry",
              "solve --robust: measurements kept at weight 1: odometry "
              "(between consecutive poses) | none.");
DEFINE_string(edge_report, "",
              "solve --robust: write the per-edge verdicts (weight, inlier, "
              "residuals) to this CSV file.");

namespace ceres_sesync::tools {
namespace {

// The fields of a SolverSummary in the --json file (the whole solve, or one
// component of --components). `status` (if not empty) replaces the
// summary's status.
void AddSummary(const SolverSummary& summary, internal::JsonWriter* json,
                const std::string& status = "") {
  json->Int("num_poses", summary.num_poses);
  json->Int("num_measurements", summary.num_measurements);
  json->Int("num_landmarks", summary.num_landmarks);
  json->Int("num_landmark_measurements", summary.num_landmark_measurements);
  json->Int("num_priors", summary.num_priors);
  json->Int("dimension", summary.dimension);
  json->Number("objective", summary.objective);
  json->Number("sdp_value", summary.sdp_value);
  json->Number("lower_bound", summary.lower_bound);
  json->Number("suboptimality_bound", summary.suboptimality_bound);
  json->Number("relative_suboptimality_bound",
               summary.relative_suboptimality_bound);
  json->Number("rounding_gap", summary.rounding_gap);
  json->Number("lambda_min", summary.lambda_min_estimate);
  json->Number("eta", summary.eta);
  // Every proof accounts for all round-off (the key is kept for scripts).
  json->Bool("strict_round_off", true);
  json->Bool("certified", summary.certified());
  json->Bool("relaxation_exact", summary.relaxation_exact);
  json->Int("rank", summary.final_rank);
  json->String("status", status.empty() ? summary.StatusString() : status);
  json->Int("iterations", summary.iterations);
  json->Int("hessian_vector_products", summary.hessian_vector_products);
  json->String("preconditioner", summary.preconditioner);
  json->BeginObject("proof");
  json->String("precision", summary.proof_precision);
  json->Int("factorizations", summary.factorizations);
  json->Int("extended_factorizations", summary.extended_factorizations);
  json->Number("extended_time_s", summary.extended_proof_time_s);
  json->Int("certificate_tests", summary.certificate_tests);
  json->Number("verification_time_s", summary.verification_time_s);
  json->EndObject();
  json->BeginObject("time_s");
  json->Number("data", summary.data_time_s);
  json->Number("initialization", summary.initialization_time_s);
  json->Number("optimization", summary.optimization_time_s);
  json->Number("verification", summary.verification_time_s);
  json->Number("rounding", summary.rounding_time_s);
  json->EndObject();
  json->Number("total_time_s", summary.total_time_s);
}

void AddComponents(const PoseGraph& graph, const ComponentsSummary& summary,
                   internal::JsonWriter* json) {
  json->Int("num_poses", summary.num_poses);
  json->Int("num_measurements", summary.num_measurements);
  json->Int("num_landmarks", summary.num_landmarks);
  json->Int("num_landmark_measurements", summary.num_landmark_measurements);
  json->Int("num_priors", summary.num_priors);
  json->Int("dimension", summary.dimension);
  json->Number("objective", summary.objective);
  json->Number("lower_bound", summary.lower_bound);
  json->Number("suboptimality_bound", summary.suboptimality_bound);
  json->Number("relative_suboptimality_bound",
               summary.relative_suboptimality_bound);
  json->Bool("certified", summary.certified());
  json->String("status", summary.StatusString());
  json->Number("total_time_s", summary.total_time_s);
  json->Int("num_components", static_cast<int>(summary.components.size()));
  json->BeginArray("components");
  for (const ComponentsSummary::Component& c : summary.components) {
    json->BeginObject();
    json->Int("gauge_vertex_id", c.gauge_vertex_id);
    json->BeginArray("vertex_ids");
    for (int v : c.poses) json->Int(graph.vertex_ids[v]);
    json->EndArray();
    json->BeginArray("landmark_ids");
    for (int l : c.landmarks) json->Int(graph.landmark_ids[l]);
    json->EndArray();
    AddSummary(c.summary, json);
    json->EndObject();
  }
  json->EndArray();
}

int InputError(const std::string& message) {
  std::fprintf(stderr, "ceres_sesync solve: %s\n", message.c_str());
  return kUsageOrInputError;
}

}  // namespace

int RunSolve(const Args& args) {
  if (args.size() != 1) {
    std::fputs(
        "usage: ceres_sesync solve GRAPH.g2o [flags] (see 'ceres_sesync help "
        "solve')\n",
        stderr);
    return kUsageOrInputError;
  }
  SolverOptions options;
  if (FLAGS_init == "chordal") {
    options.initialization = SolverOptions::Initialization::kChordal;
  } else if (FLAGS_init == "random") {
    options.initialization = SolverOptions::Initialization::kRandom;
  } else if (FLAGS_init == "vertices") {
    options.initialization = SolverOptions::Initialization::kVertices;
  } else {
    return InputError("unknown --init '" + FLAGS_init + "'");
  }
  if (FLAGS_preconditioner == "auto") {
    options.preconditioner = SolverOptions::Preconditioner::kAutomatic;
  } else if (FLAGS_preconditioner == "q") {
    options.preconditioner = SolverOptions::Preconditioner::kRegularizedQ;
  } else if (FLAGS_preconditioner == "cholesky") {
    options.preconditioner = SolverOptions::Preconditioner::kSparseCholesky;
  } else if (FLAGS_preconditioner == "jacobi") {
    options.preconditioner = SolverOptions::Preconditioner::kBlockJacobi;
  } else if (FLAGS_preconditioner == "none") {
    options.preconditioner = SolverOptions::Preconditioner::kNone;
  } else {
    return InputError("unknown --preconditioner '" + FLAGS_preconditioner +
                      "'");
  }
  if (FLAGS_local_solver == "ceres") {
    options.local_solver = SolverOptions::LocalSolver::kCeresLbfgs;
  } else if (FLAGS_local_solver != "rtr") {
    return InputError("unknown --local_solver '" + FLAGS_local_solver + "'");
  }
  options.seed = FLAGS_seed;
  options.initial_rank = FLAGS_initial_rank;
  options.max_rank = FLAGS_max_rank;
  options.test_certificate_after_escape = FLAGS_test_certificate_after_escape;
  options.test_certificate_near_convergence =
      FLAGS_test_certificate_near_convergence;
  options.newton_at_rank_d = FLAGS_newton_at_rank_d;
  options.max_time_s = FLAGS_max_time;
  options.verbose = FLAGS_verbose;
  options.num_threads = FLAGS_num_threads;
  if (!ParseProofArithmetic(FLAGS_proof_arithmetic,
                            &options.proof_arithmetic)) {
    return InputError("unknown --proof_arithmetic '" + FLAGS_proof_arithmetic +
                      "'");
  }
  options.relative_preconditioned_gradient_tolerance = FLAGS_gradient_tolerance;
  RobustSolverOptions robust_options;
  robust_options.inlier_threshold = FLAGS_inlier_threshold;
  robust_options.inlier_probability = FLAGS_inlier_probability;
  if (!ParseKnownInliers(FLAGS_known_inliers, &robust_options.known_inliers)) {
    std::fprintf(stderr, "ceres_sesync solve: unknown --known_inliers '%s'\n",
                 FLAGS_known_inliers.c_str());
    return kUsageOrInputError;
  }
  for (const char* flag : {"inlier_threshold", "inlier_probability",
                           "known_inliers", "edge_report"}) {
    if (!FLAGS_robust &&
        !gflags::GetCommandLineFlagInfoOrDie(flag).is_default) {
      std::fprintf(stderr, "ceres_sesync solve: --%s needs --robust\n", flag);
      return kUsageOrInputError;
    }
  }
  if (FLAGS_robust && !std::isfinite(InlierThreshold(robust_options, 2))) {
    std::fprintf(stderr,
                 "ceres_sesync solve: --inlier_threshold must be finite and "
                 "--inlier_probability in (0, 1)\n");
    return kUsageOrInputError;
  }

  const std::string& path = args[0];
  PoseGraph graph;
  std::string error;
  G2oReadOptions read_options;
  read_options.allow_disconnected = FLAGS_components;
  if (!ReadG2oFile(path, read_options, &graph, &error)) {
    if (error.find("measurement graph is disconnected") != std::string::npos) {
      error += " (--components solves each component on its own)";
    }
    return InputError(error);
  }
  if (options.initialization == SolverOptions::Initialization::kVertices &&
      graph.initial_poses.empty()) {
    return InputError(path +
                      ": --init vertices, but the file has no VERTEX lines");
  }
  if (FLAGS_robust && FLAGS_components) {
    return InputError("--robust and --components cannot be combined");
  }
  std::unique_ptr<ProgressPrinter> progress = ProgressPrinterFromFlags();
  if (progress) options.progress = progress->Callback();

  Solution solution;
  bool certified = false;
  internal::JsonWriter json;
  json.String("graph", path);
  RobustSolverSummary robust;
  if (FLAGS_components) {
    ComponentsSummary summary;
    SolveByComponent(graph, options, &solution, &summary);
    if (progress) progress->Finish();
    std::cout << summary.FullReport() << std::flush;
    if (summary.status == SolverSummary::Status::kInvalidInput) {
      return InputError(path + ": " + summary.message);
    }
    certified = summary.certified();
    AddComponents(graph, summary, &json);
  } else if (FLAGS_robust) {
    robust_options.solver_options = options;
    // --max_time limits the whole command, not each of its solves.
    robust_options.max_time_s = options.max_time_s;
    SolveRobust(graph, robust_options, &solution, &robust);
    if (progress) progress->Finish();
    std::cout << robust.FullReport() << std::flush;
    if (robust.status == RobustSolverSummary::Status::kInvalidInput) {
      return InputError(path + ": " + robust.message);
    }
    // Disconnected accepted edges: ran, not certified (exit 1), no inlier
    // problem was solved.
    const bool disconnected =
        robust.status == RobustSolverSummary::Status::kInlierGraphDisconnected;
    if (disconnected) {
      std::fprintf(stderr, "ceres_sesync solve: %s: %s\n", path.c_str(),
                   robust.message.c_str());
    }
    // Out of time during GNC: no inlier problem was solved (exit 1).
    const bool timed_out =
        robust.status == RobustSolverSummary::Status::kTimeLimit;
    // The problem of the accepted edges.
    const SolverSummary& summary = robust.inlier_summary;
    certified = robust.certified();
    AddSummary(
        summary, &json,
        disconnected || timed_out ? robust.StatusString() : std::string());
    AddRobustJson(robust, &json);
  } else {
    SolverSummary summary;
    Solve(graph, options, &solution, &summary);
    if (progress) progress->Finish();
    std::cout << summary.FullReport() << std::flush;
    if (summary.status == SolverSummary::Status::kInvalidInput) {
      return InputError(path + ": " + summary.message);
    }
    certified = summary.certified();
    AddSummary(summary, &json);
  }
  // The poses, then the landmark positions (original ids).
  if (!FLAGS_output.empty() &&
      !WriteG2oSolution(FLAGS_output, graph, solution, &error)) {
    return InputError(error);
  }
  if (!FLAGS_tum.empty() &&
      !WriteTumFile(FLAGS_tum, graph, solution.poses, &error)) {
    return InputError(error);
  }
  if (!FLAGS_edge_report.empty() &&
      !WriteEdgeReport(FLAGS_edge_report, robust, &error)) {
    return InputError(error);
  }
  if (!FLAGS_json.empty() && !json.WriteToFile(FLAGS_json, &error)) {
    return InputError(error);
  }
  return certified ? kSuccess : kNotCertified;
}

bool ParseProofArithmetic(const std::string& name,
                          SolverOptions::ProofArithmetic* arithmetic) {
  if (name == "automatic") {
    *arithmetic = SolverOptions::ProofArithmetic::kAutomatic;
  } else if (name == "double") {
    *arithmetic = SolverOptions::ProofArithmetic::kDouble;
  } else if (name == "double-double") {
    *arithmetic = SolverOptions::ProofArithmetic::kDoubleDouble;
  } else {
    return false;
  }
  return true;
}

}  // namespace ceres_sesync::tools
