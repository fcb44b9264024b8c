// `ceres_sesync solve GRAPH.g2o`: SE-Sync with certification.

#include <cstdio>
#include <iostream>

#include "ceres_sesync/component_solver.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/json_writer.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "tools/commands.h"
#include "tools/progress.h"

DEFINE_string(tum, "", "Also write the poses as a TUM trajectory.");
DEFINE_string(init, "chordal",
              "Initialization, one of chordal|random|vertices.");
DECLARE_uint64(seed);  // Defined in generate_command.cc.
DEFINE_int32(initial_rank, 0, "Initial staircase rank (0: d + 2).");
DEFINE_int32(max_rank, 10, "Maximum staircase rank.");
DEFINE_string(preconditioner, "q",
              "Truncated-CG preconditioner: q (regularized Q, exact "
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
DEFINE_bool(components, false,
            "Solve a disconnected graph per connected component, each in its "
            "own gauge (its first pose, or its FIX pose, fixed); the report "
            "and --json list the components. Without it a disconnected graph "
            "is an input error.");

namespace ceres_sesync::tools {
namespace {

// The fields of a SolverSummary in the --json file (the whole solve, or one
// component of --components).
void AddSummary(const SolverSummary& summary, internal::JsonWriter* json) {
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
  json->String("status", summary.StatusString());
  json->Int("iterations", summary.iterations);
  json->Int("hessian_vector_products", summary.hessian_vector_products);
  json->BeginObject("proof");
  json->String("precision", summary.proof_precision);
  json->Int("factorizations", summary.factorizations);
  json->Int("extended_factorizations", summary.extended_factorizations);
  json->Number("extended_time_s", summary.extended_proof_time_s);
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
  if (FLAGS_preconditioner == "q") {
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
  options.max_time_s = FLAGS_max_time;
  options.verbose = FLAGS_verbose;
  options.num_threads = FLAGS_num_threads;
  if (!ParseProofArithmetic(FLAGS_proof_arithmetic,
                            &options.proof_arithmetic)) {
    return InputError("unknown --proof_arithmetic '" + FLAGS_proof_arithmetic +
                      "'");
  }
  options.relative_preconditioned_gradient_tolerance = FLAGS_gradient_tolerance;

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
  std::unique_ptr<ProgressPrinter> progress = ProgressPrinterFromFlags();
  if (progress) options.progress = progress->Callback();

  Solution solution;
  bool certified = false;
  internal::JsonWriter json;
  json.String("graph", path);
  if (FLAGS_components) {
    ComponentsSummary summary;
    solution.poses = SolveByComponent(graph, options, &summary);
    if (progress) progress->Finish();
    std::cout << summary.FullReport() << std::flush;
    if (summary.status == SolverSummary::Status::kInvalidInput) {
      return InputError(path + ": " + summary.message);
    }
    certified = summary.certified();
    AddComponents(graph, summary, &json);
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
