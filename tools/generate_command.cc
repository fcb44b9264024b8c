// `ceres_sesync generate cube ...`: writes a synthetic cube (or 2D grid)
// pose graph of SE-Sync's Section 6.1 (see ceres_sesync/cube_generator.h).

#include <cstdio>
#include <string>

#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "gflags/gflags.h"
#include "tools/commands.h"

DEFINE_int32(side, 10, "Side length s of the lattice, in poses.");
DEFINE_int32(dimension, 3, "3 for the s x s x s cube, 2 for the s x s grid.");
DEFINE_double(loop_closure_probability, 0.1,
              "Probability pLC of a loop closure between each pair "
              "of nearby non-sequential poses.");
DEFINE_double(loop_closure_radius, 1.0,
              "Loop-closure candidates are non-consecutive poses "
              "at most this many lattice units apart, in [1, 4] (1: lattice "
              "neighbours; sqrt(3): the 3 x 3 x 3 block).");
DEFINE_double(kappa, 16.67,
              "Rotational concentration of every measurement "
              "(16.67 ~ 10 deg RMS).");
DEFINE_double(tau, 75,
              "Translational precision of every measurement (75 ~ "
              "0.2 m RMS in 3D).");
DEFINE_uint64(seed, 0, "Random seed (deterministic output).");
DEFINE_string(ground_truth, "",
              "Also write the ground-truth poses (VERTEX lines) to "
              "this g2o file.");
DEFINE_string(vertices, "odometry",
              "VERTEX lines of --output: 'odometry' (dead reckoning "
              "along the path, like recorded datasets), 'ground_truth', or "
              "'none'.");

namespace ceres_sesync::tools {

namespace {

constexpr char kUsage[] =
    "usage: ceres_sesync generate cube --side S [--dimension 2|3] "
    "[--loop_closure_probability P] [--loop_closure_radius R] [--kappa K] "
    "[--tau T] [--seed N] --output FILE.g2o [--ground_truth FILE.g2o] "
    "[--vertices odometry|ground_truth|none]\n";

int UsageError(const std::string& message) {
  std::fprintf(stderr, "ceres_sesync generate: %s\n%s", message.c_str(),
               kUsage);
  return kUsageOrInputError;
}

// Dead reckoning: composes the odometry edges (j - 1, j) from x_0 = identity.
Poses DeadReckoning(const PoseGraph& graph) {
  Poses poses = IdentityPoses(graph.dimension, graph.num_poses);
  for (const RelativePoseMeasurement& m : graph.measurements) {
    if (m.j != m.i + 1) continue;
    poses[m.j].R = poses[m.i].R * m.R;
    poses[m.j].t = poses[m.i].t + poses[m.i].R * m.t;
  }
  return poses;
}

}  // namespace

int RunGenerate(const Args& args) {
  if (args.empty()) return UsageError("missing the model name (cube)");
  if (args[0] != "cube") {
    return UsageError("unknown model '" + args[0] + "' (only 'cube')");
  }
  if (args.size() > 1) {
    return UsageError("unexpected argument '" + args[1] + "'");
  }
  if (FLAGS_output.empty()) return UsageError("--output FILE.g2o is required");
  if (FLAGS_vertices != "odometry" && FLAGS_vertices != "ground_truth" &&
      FLAGS_vertices != "none") {
    return UsageError("--vertices must be odometry, ground_truth or none");
  }

  CubeOptions options;
  options.dimension = FLAGS_dimension;
  options.side = FLAGS_side;
  options.loop_closure_probability = FLAGS_loop_closure_probability;
  options.loop_closure_radius = FLAGS_loop_closure_radius;
  options.kappa = FLAGS_kappa;
  options.tau = FLAGS_tau;
  options.seed = FLAGS_seed;
  PoseGraph graph;
  Poses truth;
  std::string error;
  if (!GenerateCube(options, &graph, &truth, &error)) return UsageError(error);

  Poses vertices;
  if (FLAGS_vertices == "odometry") {
    vertices = DeadReckoning(graph);
  } else if (FLAGS_vertices == "ground_truth") {
    vertices = truth;
  }
  if (!WriteG2oFile(FLAGS_output, graph, vertices, &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  if (!FLAGS_ground_truth.empty() &&
      !WriteG2oPoses(FLAGS_ground_truth, graph, truth, &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }

  const int m = static_cast<int>(graph.measurements.size());
  const int loop_closures = m - (graph.num_poses - 1);
  std::printf(
      "cube: d=%d side=%d poses=%d measurements=%d (odometry %d, loop "
      "closures %d)\n"
      "objective at ground truth %.6e (expected %.6e over the noise)\n"
      "wrote %s%s%s\n",
      graph.dimension, options.side, graph.num_poses, m, graph.num_poses - 1,
      loop_closures, EvaluateObjective(graph, truth),
      ExpectedGroundTruthObjective(graph.dimension, m, options.kappa),
      FLAGS_output.c_str(), FLAGS_ground_truth.empty() ? "" : " and ",
      FLAGS_ground_truth.c_str());
  return kSuccess;
}

}  // namespace ceres_sesync::tools
