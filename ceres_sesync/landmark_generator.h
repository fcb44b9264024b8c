// A synthetic landmark-SLAM benchmark: a robot on a Manhattan-style walk
// (2D or 3D) observing random point landmarks within its sensor range, with
// optional GPS-like position priors and a prior on the start pose. The
// objective is that of pose_graph.h (edges, landmark measurements, priors).
//
// The walk: the robot starts at the origin facing +x (pose 0 = (I, 0)) and
// moves `step_length` per pose along a lattice axis. Intersections are the
// lattice points whose coordinates are all multiples of `block_length`
// steps; only there it may turn: with probability `turn_probability` to one
// of the perpendicular axis directions (2D: left or right; 3D: also up or
// down), chosen uniformly, else it goes straight. It never reverses and
// never leaves the box [-world_size / 2, world_size / 2]^d: directions whose
// next intersection lies outside are not taken (if straight is one of them,
// it turns). Each pose faces its direction of travel (the last pose keeps
// the heading of the one before it), as in cube_generator.h.
//
// Landmarks: `num_landmarks` points uniform in the box enlarged by the
// sensor range on every side. Pose i observes each landmark within distance
// `sensor_range` of t_i independently with probability
// `detection_probability`, keeping at most `max_observations_per_pose`
// (the nearest ones; 0: no limit). Landmarks that no pose observes are
// dropped; the others are numbered in order of first observation.
//
// Measurements (noise as in the generative model (10) of Rosen et al.; all
// of them exact with `noiseless`):
//  - odometry (i - 1, i): t~ = R_{i-1}^T (t_i - t_{i-1}) + N(0, I / tau),
//    R~ = R_{i-1}^T R_i Langevin(kappa);
//  - landmark l from pose i: z = R_i^T (p_l - t_i) + N(0, I / landmark_nu);
//  - GPS-like position priors on every `gps_interval`-th pose (0, k, 2k,
//    ...; 0: none): g = t_i + N(0, I / gps_tau);
//  - a start prior (if `start_prior`): a full pose prior on pose 0 with R~ =
//    R_0 Langevin(start_prior_kappa), g = t_0 + N(0, I / start_prior_tau).
// Ids: poses 0..n-1 in path order, landmarks n, n + 1, ... (dense order).
// The output is a deterministic function of the options (identical on every
// platform: the samplers of langevin.h).

#ifndef CERES_SESYNC_LANDMARK_GENERATOR_H_
#define CERES_SESYNC_LANDMARK_GENERATOR_H_

#include <cstdint>
#include <string>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct LandmarkGraphOptions {
  // Dimension d of the poses and landmarks: 2 or 3.
  int dimension = 2;
  // Number of poses n along the walk, in [2, 10^7].
  int num_poses = 1000;
  // Distance travelled between consecutive poses (> 0), in meters.
  double step_length = 1.0;
  // Steps between intersections (>= 1).
  int block_length = 5;
  // Probability of turning at an intersection, in [0, 1].
  double turn_probability = 0.5;
  // Side of the box the walk stays in (>= 2 block_length step_length).
  double world_size = 40;
  // Number of landmarks drawn (before dropping the unobserved ones), in
  // [1, 10^7].
  int num_landmarks = 300;
  // Sensor range (> 0), in meters.
  double sensor_range = 5;
  // Probability of observing a landmark in range, in (0, 1].
  double detection_probability = 1.0;
  // Largest number of landmarks observed per pose (the nearest); 0: all.
  int max_observations_per_pose = 0;
  // Odometry precisions (> 0). kappa = 100 is ~4 deg RMS (eq. 63), tau = 100
  // 0.1 m RMS per axis.
  double kappa = 100;
  double tau = 100;
  // Precision of the landmark measurements (> 0): 25 is 0.2 m RMS per axis.
  double landmark_nu = 25;
  // GPS-like position priors on every gps_interval-th pose (>= 0; 0: none),
  // with precision gps_tau (> 0; 1 is 1 m RMS per axis).
  int gps_interval = 0;
  double gps_tau = 1;
  // A full pose prior on pose 0 (precisions > 0).
  bool start_prior = false;
  double start_prior_kappa = 1e4;
  double start_prior_tau = 1e4;
  // Exact measurements (F = 0 at the ground truth), for tests.
  bool noiseless = false;
  // Seed of the random stream.
  uint64_t seed = 0;
};

// A dense-landmark preset after the character of the Victoria Park dataset
// (a vehicle whose laser range finder sees many tree trunks at once): 2D,
// 2000 poses of 0.5 m, 1500 landmarks in a 120 m park, a 12 m sensor range
// and 80% detection, i.e. ~30 landmarks per pose. Not a replica of the
// dataset's trajectory.
LandmarkGraphOptions VictoriaParkLikeOptions();

// Generates the graph (see above). On success fills `graph` (dimension d,
// n poses, landmarks, odometry edges, landmark measurements and priors,
// EMPTY initial poses and landmarks, fixed_pose = -1) and `ground_truth`
// (n poses, one position per landmark of `graph`). Returns false with a
// message in `error` (if not null) for invalid options. Either output
// pointer may be null.
bool GenerateLandmarkGraph(const LandmarkGraphOptions& options,
                           PoseGraph* graph, Solution* ground_truth,
                           std::string* error);

// Expected value of F at the ground truth over the noise of the model
// above, for any graph whose measurements follow it (edges and rotation
// priors with Langevin noise of their kappa, Gaussian translations with
// their tau / nu): each edge 4 kappa (1 - I1(2 kappa) / I0(2 kappa)) + d,
// each landmark measurement and position prior d, each rotation prior
// 4 kappa (1 - I1(2 kappa) / I0(2 kappa)) (see langevin.h).
double ExpectedGroundTruthObjective(const PoseGraph& graph);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_LANDMARK_GENERATOR_H_
