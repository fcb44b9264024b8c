// Solving a g2o pose-graph file with SE-Sync, in the fewest lines.
//
//   solve_g2o [FILE.g2o]
//
// Reads the file (2D EDGE_SE2 or 3D EDGE_SE3:QUAT; see g2o_io.h), solves it
// with SE-Sync, prints the solver's report, writes the optimized poses as g2o
// VERTEX lines and as a TUM trajectory, and exits with status 0 only if the
// solution is certified globally optimal. Without an argument it first
// generates a small synthetic cube (5 x 5 x 5 poses) into a temporary file,
// so the program runs out of the box (and as a test).

#include <unistd.h>  // getpid

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "ceres_sesync/ceres_sesync.h"

int main(int argc, char** argv) {
  std::string path;
  bool remove_input = false;
  if (argc > 1) {
    path = argv[1];
  } else {
    // No file given: make one. GenerateCube returns the graph (and the
    // ground truth, not needed here); WriteG2oFile writes it as EDGE lines.
    ceres_sesync::CubeOptions cube;
    cube.side = 5;
    ceres_sesync::PoseGraph cube_graph;
    std::string error;
    // (The process id keeps concurrent runs apart; the file is removed after
    // reading.)
    path = (std::filesystem::temp_directory_path() /
            ("solve_g2o_cube_" + std::to_string(getpid()) + ".g2o"))
               .string();
    remove_input = true;
    if (!ceres_sesync::GenerateCube(cube, &cube_graph, nullptr, &error) ||
        !ceres_sesync::WriteG2oFile(path, cube_graph, {}, &error)) {
      std::fprintf(stderr, "Cannot generate the example cube: %s\n",
                   error.c_str());
      return 1;
    }
    std::printf("No file given: generated a %dx%dx%d cube into %s\n", cube.side,
                cube.side, cube.side, path.c_str());
  }

  // 1. Read. Errors come back as "PATH:LINE: what is wrong".
  ceres_sesync::PoseGraph graph;
  std::string error;
  const bool read = ceres_sesync::ReadG2oFile(
      path, ceres_sesync::G2oReadOptions(), &graph, &error);
  std::error_code ignored;
  if (remove_input) std::filesystem::remove(path, ignored);
  if (!read) {
    std::fprintf(stderr, "Cannot read %s: %s\n", path.c_str(), error.c_str());
    return 1;
  }
  std::printf("Read %s: %dD, %d poses, %zu measurements\n", path.c_str(),
              graph.dimension, graph.num_poses, graph.measurements.size());

  // 2. Solve. The default options (chordal initialization, Riemannian
  // staircase from rank d + 2) are what the paper recommends.
  ceres_sesync::SolverOptions options;
  ceres_sesync::SolverSummary summary;
  const ceres_sesync::Poses poses =
      ceres_sesync::Solve(graph, options, &summary);
  std::printf("%s\n", summary.BriefReport().c_str());
  if (poses.empty()) {
    std::fprintf(stderr, "Solve failed: %s\n", summary.message.c_str());
    return 1;
  }

  // 3. Write the poses (into the working directory): g2o VERTEX lines with the
  // file's own vertex ids, and a TUM trajectory (timestamp = vertex id).
  const std::string g2o_out = "solve_g2o_result.g2o";
  const std::string tum_out = "solve_g2o_result.tum";
  if (!ceres_sesync::WriteG2oPoses(g2o_out, graph, poses, &error) ||
      !ceres_sesync::WriteTumFile(tum_out, graph, poses, &error)) {
    std::fprintf(stderr, "Cannot write the result: %s\n", error.c_str());
    return 1;
  }
  std::printf("Wrote %s and %s\n", g2o_out.c_str(), tum_out.c_str());

  // 4. The answer that matters: is this the global optimum?
  if (!summary.certified()) {
    std::printf("NOT certified (%s): the poses may be a local minimum.\n",
                summary.StatusString().c_str());
    return 1;
  }
  std::printf(
      "CERTIFIED: F = %.10g is globally optimal to within %.2e "
      "(relative).\n",
      summary.objective, summary.relative_suboptimality_bound);

  // (A self-check, for the example's own test: the objective reported by the
  // solver is eq. (12) evaluated at the returned poses.)
  const double f = ceres_sesync::EvaluateObjective(graph, poses);
  if (!(std::abs(f - summary.objective) <= 1e-9 * f)) {
    std::fprintf(stderr, "Objective mismatch: %.17g vs %.17g\n", f,
                 summary.objective);
    return 1;
  }
  return 0;
}
