// SE-Sync versus Ceres on the paper's synthetic cube.
//
//   generate_and_benchmark [SIDE [SEED]]
//
// Generates a SIDE x SIDE x SIDE cube (default 10, i.e. 1000 poses, as in the
// paper) with the paper's default noise (Rosen et al., IJRR 2019, Section
// 6.1), then minimizes the same objective (eq. 12) with
//   - SE-Sync (Solve), which also certifies its answer, and
//   - Ceres with Powell's dogleg and the Gauss-Newton model (SolveWithCeres;
//     the paper's PDL-GN baseline), once from the chordal initialization and
//     once from odometry (composing the measurements along a spanning tree),
// certifies each Ceres result after the fact (Certify), and prints objective
// values, times and certificates side by side. It exits with status 1 unless
// SE-Sync is certified and no Ceres run found a lower objective (to a relative
// 1e-9).

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "ceres_sesync/ceres_sesync.h"

namespace {

struct Row {
  std::string method;
  double objective = 0;
  double time_s = 0;
  std::string certificate;
};

// Certifies `poses` and describes the outcome in a few words.
std::string CertificateText(const ceres_sesync::PoseGraph& graph,
                            const ceres_sesync::Poses& poses) {
  ceres_sesync::Certificate certificate;
  std::string error;
  if (!ceres_sesync::Certify(graph, poses, ceres_sesync::CertifyOptions(),
                             &certificate, &error)) {
    return "error: " + error;
  }
  char text[128];
  if (certificate.certified) {
    std::snprintf(text, sizeof(text), "certified (rel. gap <= %.1e)",
                  certificate.relative_suboptimality_bound);
  } else {
    std::snprintf(text, sizeof(text), "NOT certified (lambda_min(S) %.2g)",
                  certificate.lambda_min);
  }
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  // ---- 1. The data. ----
  // The paper's defaults: kappa 16.67 (~10 degrees RMS rotation noise),
  // tau 75 (~0.2 m RMS), loop-closure probability 0.1.
  ceres_sesync::CubeOptions cube;
  cube.side = argc > 1 ? std::atoi(argv[1]) : 10;
  cube.seed = argc > 2 ? std::strtoull(argv[2], nullptr, 10) : 0;
  ceres_sesync::PoseGraph graph;
  ceres_sesync::Poses ground_truth;
  std::string error;
  if (!ceres_sesync::GenerateCube(cube, &graph, &ground_truth, &error)) {
    std::fprintf(stderr, "GenerateCube: %s\n", error.c_str());
    return 1;
  }
  std::printf("Cube: side %d, %d poses, %zu measurements, seed %llu\n",
              cube.side, graph.num_poses, graph.measurements.size(),
              static_cast<unsigned long long>(cube.seed));
  std::printf("F(ground truth) = %.6f (expected over the noise: %.1f)\n\n",
              ceres_sesync::EvaluateObjective(graph, ground_truth),
              ceres_sesync::ExpectedGroundTruthObjective(
                  graph.dimension, graph.measurements.size(), cube.kappa));

  std::vector<Row> rows;

  // ---- 2. SE-Sync. ----
  ceres_sesync::SolverSummary sesync;
  const ceres_sesync::Poses sesync_poses =
      ceres_sesync::Solve(graph, ceres_sesync::SolverOptions(), &sesync);
  std::printf("%s\n", sesync.BriefReport().c_str());
  char text[128];
  std::snprintf(text, sizeof(text), "%s (rel. gap <= %.1e)",
                sesync.certified() ? "certified" : "NOT certified",
                sesync.relative_suboptimality_bound);
  rows.push_back(
      {"SE-Sync (chordal init)", sesync.objective, sesync.total_time_s, text});

  // ---- 3. Ceres, Powell's dogleg (PDL-GN), from two initializations. ----
  ceres_sesync::Poses chordal;
  if (!ceres_sesync::ChordalInitialization(graph, &chordal, &error)) {
    std::fprintf(stderr, "ChordalInitialization: %s\n", error.c_str());
    return 1;
  }
  const ceres_sesync::Poses odometry =
      ceres_sesync::OdometryInitialization(graph);
  struct Start {
    const char* name;
    const ceres_sesync::Poses* poses;
  };
  const Start starts[] = {{"Ceres PDL-GN (chordal init)", &chordal},
                          {"Ceres PDL-GN (odometry init)", &odometry}};
  ceres_sesync::CeresBaselineOptions ceres_options;  // Dogleg by default.
  std::vector<double> ceres_objectives;
  for (const Start& start : starts) {
    ceres_sesync::Poses result;
    ceres_sesync::CeresBaselineSummary summary;
    if (!ceres_sesync::SolveWithCeres(graph, *start.poses, ceres_options,
                                      &result, &summary, &error)) {
      std::fprintf(stderr, "SolveWithCeres: %s\n", error.c_str());
      return 1;
    }
    std::printf("%s: %s\n", start.name, summary.BriefReport().c_str());
    ceres_objectives.push_back(summary.final_objective);
    rows.push_back({start.name, summary.final_objective, summary.time_s,
                    CertificateText(graph, result)});
  }

  // ---- 4. Side by side. ----
  std::printf("\n%-30s %14s %9s  %s\n", "method", "F (eq. 12)", "time [s]",
              "certificate (Certify, default tolerance)");
  for (const Row& row : rows) {
    std::printf("%-30s %14.6f %9.3f  %s\n", row.method.c_str(), row.objective,
                row.time_s, row.certificate.c_str());
  }

  // ---- 5. Checks. ----
  bool ok = sesync.certified();
  if (!ok) std::printf("\nFAILED: SE-Sync did not certify its solution.\n");
  for (size_t k = 0; k < ceres_objectives.size(); ++k) {
    if (!(sesync.objective <= ceres_objectives[k] * (1 + 1e-9))) {
      std::printf("\nFAILED: %s found a lower objective than SE-Sync.\n",
                  starts[k].name);
      ok = false;
    }
  }
  std::printf("\n%s\n",
              ok ? "SE-Sync certified, and no Ceres run beat it." : "FAILED.");
  return ok ? 0 : 1;
}
