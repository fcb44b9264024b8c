// `ceres_sesync generate landmarks ...`: writes a synthetic landmark-SLAM
// graph (a Manhattan-style walk observing random landmarks, optional GPS-like
// and start priors; see ceres_sesync/landmark_generator.h).

#include <cstdio>
#include <string>

#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "gflags/gflags.h"
#include "tools/commands.h"

// Shared with `generate cube` (generate_command.cc); their defaults there are
// the cube's, so for landmarks a flag left at its default means the
// LandmarkGraphOptions default.
DECLARE_int32(dimension);
DECLARE_double(kappa);
DECLARE_double(tau);
DECLARE_uint64(seed);
DECLARE_string(ground_truth);
DECLARE_string(vertices);

DEFINE_string(preset, "manhattan",
              "generate landmarks: 'manhattan' (the LandmarkGraphOptions "
              "defaults) or 'victoria' (dense landmarks, ~30 per pose); the "
              "other flags override the preset.");
DEFINE_int32(num_poses, 1000, "generate landmarks: poses along the walk.");
DEFINE_int32(num_landmarks, 300,
             "generate landmarks: landmarks drawn (unobserved ones dropped).");
DEFINE_double(sensor_range, 5, "generate landmarks: sensor range (m).");
DEFINE_double(world_size, 40,
              "generate landmarks: side of the box the walk stays in (m).");
DEFINE_int32(block_length, 5,
             "generate landmarks: steps between intersections.");
DEFINE_double(step_length, 1, "generate landmarks: step length (m).");
DEFINE_double(turn_probability, 0.5,
              "generate landmarks: probability of a turn at an intersection.");
DEFINE_double(detection_probability, 1,
              "generate landmarks: probability of seeing a landmark in range.");
DEFINE_int32(max_observations, 0,
             "generate landmarks: at most this many (nearest) landmarks per "
             "pose (0: all in range).");
DEFINE_double(landmark_nu, 25,
              "generate landmarks: precision of the landmark measurements.");
DEFINE_int32(gps_interval, 0,
             "generate landmarks: a GPS-like position prior on every k-th "
             "pose (0: none).");
DEFINE_double(gps_tau, 1, "generate landmarks: precision of the GPS priors.");
DEFINE_bool(start_prior, false,
            "generate landmarks: a full pose prior on pose 0.");
DEFINE_double(start_prior_kappa, 1e4,
              "generate landmarks: rotational precision of the start prior.");
DEFINE_double(start_prior_tau, 1e4,
              "generate landmarks: translational precision of the start "
              "prior.");
DEFINE_bool(noiseless, false,
            "generate landmarks: exact measurements (F = 0 at the ground "
            "truth).");

namespace ceres_sesync::tools {
namespace {

constexpr char kUsage[] =
    "usage: ceres_sesync generate landmarks [--preset manhattan|victoria] "
    "[--dimension 2|3] [--num_poses N] [--num_landmarks L] "
    "[--sensor_range R] [--world_size W] [--block_length B] "
    "[--step_length S] [--turn_probability P] [--detection_probability P] "
    "[--max_observations K] [--kappa K] [--tau T] [--landmark_nu NU] "
    "[--gps_interval K] [--gps_tau T] [--start_prior] "
    "[--start_prior_kappa K] [--start_prior_tau T] [--noiseless] [--seed N] "
    "--output FILE.g2o [--ground_truth FILE.g2o] "
    "[--vertices odometry|ground_truth|none]\n";

int UsageError(const std::string& message) {
  std::fprintf(stderr, "ceres_sesync generate: %s\n%s", message.c_str(),
               kUsage);
  return kUsageOrInputError;
}

bool IsDefault(const char* flag) {
  return gflags::GetCommandLineFlagInfoOrDie(flag).is_default;
}

}  // namespace

int RunGenerateLandmarks(const Args& args) {
  if (args.size() > 1) {
    return UsageError("unexpected argument '" + args[1] + "'");
  }
  for (const char* flag :
       {"side", "poses", "loop_closure_probability", "loop_closure_radius",
        "fraction", "mode", "cluster_size", "outlier_indices",
        "landmark_fraction", "prior_fraction"}) {
    if (!IsDefault(flag)) {
      return UsageError(std::string("--") + flag +
                        " is not an option of 'generate landmarks'");
    }
  }
  if (FLAGS_output.empty()) return UsageError("--output FILE.g2o is required");
  if (FLAGS_vertices != "odometry" && FLAGS_vertices != "ground_truth" &&
      FLAGS_vertices != "none") {
    return UsageError("--vertices must be odometry, ground_truth or none");
  }
  LandmarkGraphOptions o;
  if (FLAGS_preset == "victoria") {
    o = VictoriaParkLikeOptions();
  } else if (FLAGS_preset != "manhattan") {
    return UsageError("--preset must be manhattan or victoria");
  }
  // Flags given on the command line override the preset.
  if (!IsDefault("dimension")) o.dimension = FLAGS_dimension;
  if (!IsDefault("kappa")) o.kappa = FLAGS_kappa;
  if (!IsDefault("tau")) o.tau = FLAGS_tau;
  if (!IsDefault("num_poses")) o.num_poses = FLAGS_num_poses;
  if (!IsDefault("num_landmarks")) o.num_landmarks = FLAGS_num_landmarks;
  if (!IsDefault("sensor_range")) o.sensor_range = FLAGS_sensor_range;
  if (!IsDefault("world_size")) o.world_size = FLAGS_world_size;
  if (!IsDefault("block_length")) o.block_length = FLAGS_block_length;
  if (!IsDefault("step_length")) o.step_length = FLAGS_step_length;
  if (!IsDefault("turn_probability")) {
    o.turn_probability = FLAGS_turn_probability;
  }
  if (!IsDefault("detection_probability")) {
    o.detection_probability = FLAGS_detection_probability;
  }
  if (!IsDefault("max_observations")) {
    o.max_observations_per_pose = FLAGS_max_observations;
  }
  if (!IsDefault("landmark_nu")) o.landmark_nu = FLAGS_landmark_nu;
  if (!IsDefault("gps_interval")) o.gps_interval = FLAGS_gps_interval;
  if (!IsDefault("gps_tau")) o.gps_tau = FLAGS_gps_tau;
  if (!IsDefault("start_prior")) o.start_prior = FLAGS_start_prior;
  if (!IsDefault("start_prior_kappa")) {
    o.start_prior_kappa = FLAGS_start_prior_kappa;
  }
  if (!IsDefault("start_prior_tau")) o.start_prior_tau = FLAGS_start_prior_tau;
  if (!IsDefault("noiseless")) o.noiseless = FLAGS_noiseless;
  o.seed = FLAGS_seed;

  PoseGraph graph;
  Solution truth;
  std::string error;
  if (!GenerateLandmarkGraph(o, &graph, &truth, &error)) {
    return UsageError(error);
  }
  Solution vertices;
  if (FLAGS_vertices == "odometry") {
    vertices.poses = OdometryInitialization(graph);
    vertices.landmarks = InitialLandmarkPositions(graph, vertices.poses);
  } else if (FLAGS_vertices == "ground_truth") {
    vertices = truth;
  }
  if (!WriteG2oFile(FLAGS_output, graph, vertices.poses, vertices.landmarks,
                    &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  if (!FLAGS_ground_truth.empty() &&
      !WriteG2oSolution(FLAGS_ground_truth, graph, truth, &error)) {
    std::fprintf(stderr, "ceres_sesync generate: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  const int m = static_cast<int>(graph.landmark_measurements.size());
  std::printf(
      "landmarks: d=%d poses=%d odometry=%d landmarks=%d (of %d drawn) "
      "landmark measurements=%d (%.2f per pose) priors=%d\n"
      "objective at ground truth %.6e (expected %.6e over the noise)\n"
      "wrote %s%s%s\n",
      graph.dimension, graph.num_poses,
      static_cast<int>(graph.measurements.size()), graph.num_landmarks,
      o.num_landmarks, m, static_cast<double>(m) / graph.num_poses,
      static_cast<int>(graph.priors.size()), EvaluateObjective(graph, truth),
      o.noiseless ? 0.0 : ExpectedGroundTruthObjective(graph),
      FLAGS_output.c_str(), FLAGS_ground_truth.empty() ? "" : " and ",
      FLAGS_ground_truth.c_str());
  return kSuccess;
}

}  // namespace ceres_sesync::tools
