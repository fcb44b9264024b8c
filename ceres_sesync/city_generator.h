// A synthetic large-map pose-graph family: a Manhattan-style "city" walk, for
// measuring how solvers scale from 10^3 to 10^6 poses on maps that look like
// recorded urban trajectories (city10000, manhattan) rather than like the
// lattice sweep of the cube (cube_generator.h).
//
// The robot walks on the integer lattice {0..L-1}^2 (d = 2) or {0..L-1}^2 x
// {0..levels-1} (d = 3), one lattice unit per step, whose side grows with
// sqrt(n) so that the walk keeps coming back to places it has visited:
//
//   L = max(2, ceil(lattice_scale * sqrt(n / levels)))   (levels = 1 in 2D).
//
// It starts at the node (floor(L/2), floor(L/2), 0) heading +x. At each pose
// it chooses the direction of its next step from the lattice-axis directions
// perpendicular to its current heading that stay inside the lattice (the
// "turns": 2 in 2D, up to 4 in 3D, where up and down count as turns) and the
// heading itself ("straight"): one uniform draw u decides, it turns if
// u < turn_probability or straight ahead leaves the lattice, and a second
// draw picks the turn uniformly. It reverses only if neither is possible
// (never for L >= 2). Each pose faces the direction of its next step (the
// last pose keeps the heading of the one before it).
//
// Measurements, each oriented from the earlier to the later pose:
//  - odometry between every pair of consecutive poses (n - 1 edges);
//  - loop closures on revisits: when pose j arrives at a node that earlier
//    poses a_1 < ... < a_k have visited, those poses are considered newest
//    first, each gets a loop closure (a, j) independently with probability
//    loop_closure_probability, and the search stops once
//    max_loop_closures_per_visit closures have been drawn. (The skips
//    between accepted candidates are drawn as geometric variates, so a visit
//    costs O(max_loop_closures_per_visit) whatever k is.)
// Measurement values follow the generative model (10) of SE-Sync (Rosen et
// al., IJRR 2019), exactly as for the cube:
//   t~_ij = R_i^T (t_j - t_i) + N(0, tau^-1 I_d),
//   R~_ij = R_i^T R_j * Langevin(I_d, kappa)   (SampleIsotropicLangevin),
// so E[F(x_true)] = ExpectedGroundTruthObjective(d, m, kappa)
// (cube_generator.h). Edges are listed in order of the later pose j: the
// odometry edge (j - 1, j), then j's loop closures, newest earlier pose
// first.
//
// Time and memory are O(n + L^2 levels) = O(n) (the node tables hold
// lattice_scale^2 n + O(sqrt(n)) entries): 10^6 poses (1.6 M edges) take
// about 2 s.

#ifndef CERES_SESYNC_CITY_GENERATOR_H_
#define CERES_SESYNC_CITY_GENERATOR_H_

#include <cstdint>
#include <string>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct CityOptions {
  // Dimension d of the poses: 2 for a planar street grid, 3 for a walk
  // through a multi-level lattice (a city with bridges and tunnels, a
  // parking structure).
  int dimension = 2;
  // Number of poses n, in [2, 10^7].
  int num_poses = 10000;
  // Lattice side per sqrt(pose) (see L above), in (0, 2]. The walk spends on
  // average 1 / lattice_scale^2 poses per node once it has spread over the
  // lattice: 0.5 gives about 4 visits per node.
  double lattice_scale = 0.5;
  // d = 3 only: number of vertical levels of the lattice, in [1, 100]
  // (ignored for d = 2). 1 gives a planar walk with 3D poses.
  int levels = 4;
  // Probability of turning at a node where going straight is possible, in
  // [0, 1]. Straight runs last 1 / turn_probability steps on average.
  double turn_probability = 0.2;
  // Probability that each earlier pose at a revisited node gets a loop
  // closure to the arriving pose, in [0, 1].
  double loop_closure_probability = 0.3;
  // At most this many loop closures per arrival at a node (>= 0; 0 gives an
  // odometry chain).
  int max_loop_closures_per_visit = 2;
  // Rotational concentration kappa (> 0) of every measurement. The default
  // 100 is an RMS rotation error of 4.06 degrees per measurement (eq. 63).
  // At the cube's 16.67 (10 degrees) the relaxation is not exact on large
  // maps (10^5 poses, seed 0: relaxation not exact, rounding gap 3e-5).
  double kappa = 100;
  // Translational precision tau (> 0) of every measurement. The default 100
  // is an RMS translation error of sqrt(d / 100) (0.14 m in 2D) per
  // measurement, for steps of one spacing.
  double tau = 100;
  // Distance between neighbouring lattice points (> 0), in meters.
  double spacing = 1.0;
  // Seed of the std::mt19937_64 stream. The output is a deterministic
  // function of the options (identical on every platform).
  uint64_t seed = 0;
};

// Generates the city walk (see above). On success fills `graph` (dimension
// d, vertex ids 0..n-1 in walk order, kappa and tau on every edge, EMPTY
// initial_poses, fixed_pose = -1) and `ground_truth` (n poses at spacing
// times their lattice coordinates relative to the start node: pose 0 at the
// origin). Returns false with a message in `error` (if not null) for invalid
// options. Either output pointer may be null if not needed.
bool GenerateCity(const CityOptions& options, PoseGraph* graph,
                  Poses* ground_truth, std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CITY_GENERATOR_H_
