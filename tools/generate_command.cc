// `ceres_sesync generate cube|city ...`: writes a synthetic pose graph: the
// cube (or 2D grid) of SE-Sync's Section 6.1 (ceres_sesync/cube_generator.h)
// or a large Manhattan-style city walk (ceres_sesync/city_generator.h).
// `generate landmarks ...` is in generate_landmarks_command.cc.
// `ceres_sesync generate outliers GRAPH.g2o ...`: a copy of a graph with wrong
// loop closures appended (ceres_sesync/outlier_generator.h).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/file_util.h"
#include "ceres_sesync/outlier_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "gflags/gflags.h"
#include "tools/commands.h"

DEFINE_int32(side, 10, "Cube: side length s of the lattice, in poses.");
DEFINE_int32(poses, 0, "City: number of poses n (required).");
DEFINE_int32(dimension, 3,
             "Cube: 3 for the s x s x s cube, 2 for the s x s "
             "grid; city: 2 (default) or 3.");
DEFINE_double(loop_closure_probability, 0.1,
              "Cube: probability pLC of a loop closure between "
              "each pair of nearby non-sequential poses; city (default 0.3): "
              "probability of a closure to each earlier pose at a revisited "
              "lattice node (at most 2 per visit).");
DEFINE_double(loop_closure_radius, 1.0,
              "Cube: loop-closure candidates are non-consecutive "
              "poses at most this many lattice units apart, in [1, 4] (1: "
              "lattice neighbours; sqrt(3): the 3 x 3 x 3 block).");
DEFINE_double(kappa, 16.67,
              "Rotational concentration of every measurement "
              "(cube default 16.67 ~ 10 deg RMS; city default 100 ~ 4 deg).");
DEFINE_double(tau, 75,
              "Translational precision of every measurement (cube "
              "default 75 ~ 0.2 m RMS in 3D; city default 100).");
DEFINE_uint64(seed, 0, "Random seed (deterministic output).");
DEFINE_string(ground_truth, "",
              "Also write the ground-truth poses (VERTEX lines) to "
              "this g2o file.");
DEFINE_string(vertices, "odometry",
              "VERTEX lines of --output: 'odometry' (dead reckoning "
              "along the path, like recorded datasets), 'ground_truth', or "
              "'none'.");

DEFINE_double(fraction, -1,
              "generate outliers: fraction of the output's loop closures that "
              "are wrong, in [0, 1) (this, --landmark_fraction or "
              "--prior_fraction is required).");
DEFINE_string(mode, "random",
              "generate outliers: random (random pose pairs and relative "
              "poses) | clustered (groups of mutually consistent wrong "
              "closures: perceptual aliasing).");
DEFINE_int32(cluster_size, 10,
             "generate outliers --mode clustered: wrong closures per group.");
DEFINE_double(landmark_fraction, 0,
              "generate outliers: fraction of the output's landmark "
              "measurements that are wrong data associations (a true "
              "observation attributed to another landmark), in [0, 1).");
DEFINE_double(prior_fraction, 0,
              "generate outliers: fraction of the output's position priors "
              "that are false fixes (10-40 sigma jumps), in [0, 1).");
DEFINE_string(outlier_indices, "",
              "generate outliers: where to write the 0-based indices of the "
              "added measurements, one per line, in the order of the "
              "output's EDGE lines; added landmark measurements as "
              "'landmark K', priors as 'prior K' (K in the order of their "
              "own lines). Default: OUTPUT.outliers.txt.");

namespace ceres_sesync::tools {

namespace {

constexpr char kUsage[] =
    "usage: ceres_sesync generate cube --side S [--dimension 2|3] "
    "[--loop_closure_probability P] [--loop_closure_radius R] [--kappa K] "
    "[--tau T] [--seed N] --output FILE.g2o [--ground_truth FILE.g2o] "
    "[--vertices odometry|ground_truth|none]\n"
    "       ceres_sesync generate city --poses N [--dimension 2|3] "
    "[--loop_closure_probability P] [--kappa K] [--tau T] [--seed N] "
    "--output FILE.g2o [--ground_truth FILE.g2o] "
    "[--vertices odometry|ground_truth|none]\n"
    "       ceres_sesync generate outliers GRAPH.g2o [--fraction F] "
    "[--mode random|clustered] [--cluster_size K] [--landmark_fraction F] "
    "[--prior_fraction F] [--seed N] --output FILE.g2o "
    "[--outlier_indices FILE.txt]\n";

// Whether `flag` was given on the command line.
bool IsSet(const char* flag) {
  return !gflags::GetCommandLineFlagInfoOrDie(flag).is_default;
}

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

// `generate outliers GRAPH.g2o`: the graph plus wrong loop closures.
int RunGenerateOutliers(const Args& args) {
  if (args.size() != 2) {
    return UsageError(args.size() < 2
                          ? "missing the input GRAPH.g2o"
                          : "unexpected argument '" + args[2] + "'");
  }
  for (const char* flag :
       {"side", "poses", "dimension", "loop_closure_probability",
        "loop_closure_radius", "kappa", "tau", "ground_truth", "vertices"}) {
    if (IsSet(flag)) {
      return UsageError(std::string("--") + flag +
                        " is not an option of 'generate outliers'");
    }
  }
  const bool closures = IsSet("fraction");
  const bool landmark_terms =
      IsSet("landmark_fraction") || IsSet("prior_fraction");
  if (!closures && !landmark_terms) {
    return UsageError(
        "--fraction F (wrong loop closures), --landmark_fraction F or "
        "--prior_fraction F is required");
  }
  if (closures && !(FLAGS_fraction >= 0 && FLAGS_fraction < 1)) {
    return UsageError("--fraction must be in [0, 1)");
  }
  for (double f : {FLAGS_landmark_fraction, FLAGS_prior_fraction}) {
    if (!(f >= 0 && f < 1)) {
      return UsageError(
          "--landmark_fraction and --prior_fraction must be in "
          "[0, 1)");
    }
  }
  if (FLAGS_output.empty()) return UsageError("--output FILE.g2o is required");
  OutlierOptions options;
  options.fraction = FLAGS_fraction;
  options.cluster_size = FLAGS_cluster_size;
  options.seed = FLAGS_seed;
  if (FLAGS_mode == "random") {
    options.mode = OutlierOptions::Mode::kRandom;
  } else if (FLAGS_mode == "clustered") {
    options.mode = OutlierOptions::Mode::kClustered;
  } else {
    return UsageError("--mode must be random or clustered");
  }
  if (IsSet("cluster_size") &&
      options.mode != OutlierOptions::Mode::kClustered) {
    return UsageError("--cluster_size is for --mode clustered");
  }
  PoseGraph graph, corrupted;
  std::string error;
  if (!ReadG2oFile(args[1], {}, &graph, &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  std::vector<int> added, added_l, added_p;
  if (closures) {
    if (!AddOutliers(graph, options, &corrupted, &added, &error)) {
      std::fprintf(stderr, "ceres_sesync generate: %s: %s\n", args[1].c_str(),
                   error.c_str());
      return kUsageOrInputError;
    }
  } else {
    corrupted = graph;
  }
  if (landmark_terms) {
    LandmarkOutlierOptions landmark_options;
    landmark_options.landmark_fraction = FLAGS_landmark_fraction;
    landmark_options.prior_fraction = FLAGS_prior_fraction;
    landmark_options.seed = FLAGS_seed;
    const PoseGraph with_closures = corrupted;
    if (!AddLandmarkOutliers(with_closures, landmark_options, &corrupted,
                             &added_l, &added_p, &error)) {
      std::fprintf(stderr, "ceres_sesync generate: %s: %s\n", args[1].c_str(),
                   error.c_str());
      return kUsageOrInputError;
    }
  }
  const std::string indices_path = FLAGS_outlier_indices.empty()
                                       ? FLAGS_output + ".outliers.txt"
                                       : FLAGS_outlier_indices;
  std::string indices;
  for (int k : added) indices += std::to_string(k) + "\n";
  for (int k : added_l) indices += "landmark " + std::to_string(k) + "\n";
  for (int k : added_p) indices += "prior " + std::to_string(k) + "\n";
  if (!internal::WriteFileAtomically(indices_path, indices, &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  if (!WriteG2oFile(FLAGS_output, corrupted, corrupted.initial_poses, &error)) {
    std::remove(indices_path.c_str());  // No partial output.
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  const int m = static_cast<int>(graph.measurements.size());
  if (closures) {
    std::printf(
        "outliers (%s): %d wrong loop closures appended to the %d "
        "measurements of %s (fraction %.3g of the loop closures), seed "
        "%llu\n",
        FLAGS_mode.c_str(), static_cast<int>(added.size()), m, args[1].c_str(),
        options.fraction, static_cast<unsigned long long>(options.seed));
  }
  if (landmark_terms) {
    std::printf(
        "outliers: %d wrong landmark associations and %d false position "
        "fixes appended to the %zu landmark measurements and %zu priors of "
        "%s, seed %llu\n",
        static_cast<int>(added_l.size()), static_cast<int>(added_p.size()),
        graph.landmark_measurements.size(), graph.priors.size(),
        args[1].c_str(), static_cast<unsigned long long>(FLAGS_seed));
  }
  std::printf("wrote %s and %s\n", FLAGS_output.c_str(), indices_path.c_str());
  return kSuccess;
}

}  // namespace

int RunGenerate(const Args& args) {
  if (args.empty()) {
    return UsageError(
        "missing the model name (cube, city, landmarks or outliers)");
  }
  if (args[0] == "landmarks") return RunGenerateLandmarks(args);
  const std::string& model = args[0];
  if (model == "outliers") return RunGenerateOutliers(args);
  if (model != "cube" && model != "city") {
    return UsageError("unknown model '" + model +
                      "' (cube, city, landmarks or outliers)");
  }
  for (const char* flag :
       {"fraction", "mode", "cluster_size", "outlier_indices",
        "landmark_fraction", "prior_fraction"}) {
    if (IsSet(flag)) {
      return UsageError(std::string("--") + flag +
                        " is for 'generate outliers'");
    }
  }
  if (args.size() > 1) {
    return UsageError("unexpected argument '" + args[1] + "'");
  }
  if (FLAGS_output.empty()) return UsageError("--output FILE.g2o is required");
  if (FLAGS_vertices != "odometry" && FLAGS_vertices != "ground_truth" &&
      FLAGS_vertices != "none") {
    return UsageError("--vertices must be odometry, ground_truth or none");
  }

  PoseGraph graph;
  Poses truth;
  std::string error;
  std::string size;  // "side=S" or "lattice=AxB[xC]", for the report.
  double kappa = 0;
  if (model == "cube") {
    if (IsSet("poses")) {
      return UsageError("--poses is for 'generate city' (the cube has --side)");
    }
    CubeOptions options;
    options.dimension = FLAGS_dimension;
    options.side = FLAGS_side;
    options.loop_closure_probability = FLAGS_loop_closure_probability;
    options.loop_closure_radius = FLAGS_loop_closure_radius;
    options.kappa = FLAGS_kappa;
    options.tau = FLAGS_tau;
    options.seed = FLAGS_seed;
    if (!GenerateCube(options, &graph, &truth, &error)) {
      return UsageError(error);
    }
    size = "side=" + std::to_string(options.side);
    kappa = options.kappa;
  } else {
    if (IsSet("side")) {
      return UsageError("--side is for 'generate cube' (the city has --poses)");
    }
    if (IsSet("loop_closure_radius")) {
      return UsageError("--loop_closure_radius is for 'generate cube'");
    }
    if (!IsSet("poses")) return UsageError("--poses N is required");
    // Flags not given keep CityOptions' defaults (which differ from the
    // cube's flag defaults).
    CityOptions options;
    options.num_poses = FLAGS_poses;
    if (IsSet("dimension")) options.dimension = FLAGS_dimension;
    if (IsSet("loop_closure_probability")) {
      options.loop_closure_probability = FLAGS_loop_closure_probability;
    }
    if (IsSet("kappa")) options.kappa = FLAGS_kappa;
    if (IsSet("tau")) options.tau = FLAGS_tau;
    options.seed = FLAGS_seed;
    if (!GenerateCity(options, &graph, &truth, &error)) {
      return UsageError(error);
    }
    // The lattice extent actually covered by the walk, in nodes per axis.
    for (int k = 0; k < graph.dimension; ++k) {
      double lo = 0, hi = 0;
      for (const Pose& pose : truth) {
        lo = std::min(lo, pose.t[k]);
        hi = std::max(hi, pose.t[k]);
      }
      size += (k == 0 ? "lattice=" : "x") +
              std::to_string(std::lround((hi - lo) / options.spacing) + 1);
    }
    kappa = options.kappa;
  }

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
      "%s: d=%d %s poses=%d measurements=%d (odometry %d, loop closures %d)\n"
      "objective at ground truth %.6e (expected %.6e over the noise)\n"
      "wrote %s%s%s\n",
      model.c_str(), graph.dimension, size.c_str(), graph.num_poses, m,
      graph.num_poses - 1, loop_closures, EvaluateObjective(graph, truth),
      ExpectedGroundTruthObjective(graph.dimension, m, kappa),
      FLAGS_output.c_str(), FLAGS_ground_truth.empty() ? "" : " and ",
      FLAGS_ground_truth.c_str());
  return kSuccess;
}

}  // namespace ceres_sesync::tools
