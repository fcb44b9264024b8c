// The synthetic "cube" pose-graph benchmark of SE-Sync (Rosen et al., IJRR
// 2019, Section 6.1 and Figure 2; after Carlone et al., 2015).
//
// A robot travels a rectilinear (boustrophedon) path through a regular
// lattice of side s with spacing `spacing`: an s x s x s cube (d = 3, n = s^3
// poses) or an s x s square (d = 2, n = s^2). Within a horizontal layer it
// sweeps the rows back and forth; between layers it steps up once and sweeps
// the layer in the reverse order, so every step moves one lattice unit along
// one axis. Each pose faces its direction of travel (the last pose keeps the
// heading of the one before it).
//
// Measurements, each oriented from the earlier to the later pose:
//  - odometry between every pair of consecutive poses (n - 1 edges);
//  - a loop closure between every pair of "nearby non-sequential" poses,
//    independently with probability loop_closure_probability. "Nearby"
//    means lattice points at most loop_closure_radius lattice units apart:
//    by default (radius 1) the lattice neighbours, i.e. the pairs one unit
//    apart that are not consecutive along the path. The paper does not say
//    what "nearby" is, and the choice matters: see loop_closure_radius.
// Measurement values follow the generative model (10):
//   t~_ij = R_i^T (t_j - t_i) + N(0, tau^-1 I_d),
//   R~_ij = R_i^T R_j * Langevin(I_d, kappa)   (SampleIsotropicLangevin).
// Edges are listed in order of the later pose j: first the odometry edge
// (j - 1, j), then the loop closures (i, j), i < j - 1: the unit offsets in
// lattice-axis order (-x, +x, -y, +y, -z, +z), then any longer offsets
// within the radius in lexicographic order. The random stream for radius 1
// does not depend on the radius option (same graphs as before it existed).
//
// The expected objective at the ground truth has the closed form
//   E[F(x_true)] = m (4 kappa (1 - VonMisesMeanCosine(2 kappa)) + d),
// m = number of edges (see langevin.h).

#ifndef CERES_SESYNC_CUBE_GENERATOR_H_
#define CERES_SESYNC_CUBE_GENERATOR_H_

#include <cstdint>
#include <string>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct CubeOptions {
  // Dimension d of the poses: 3 for the paper's cube, 2 for the square-grid
  // variant.
  int dimension = 3;
  // Side length s of the lattice, in poses (>= 2, and n = s^d <= 10^7). The
  // paper's default s = 10 gives n = 1000 poses in 3D.
  int side = 10;
  // Probability pLC that each nearby non-sequential pair of poses gets a loop
  // closure, in [0, 1]. Paper default 0.1.
  double loop_closure_probability = 0.1;
  // Loop-closure candidates: non-consecutive pose pairs whose lattice
  // points are at most this many lattice units apart, in [1, 4]. 1 (the
  // default) gives the lattice neighbours (2d offsets); sqrt(2) adds the
  // face diagonals, sqrt(3) (3D) the whole 3 x 3 x 3 block (26 offsets).
  // Offsets o count when |o|^2 <= radius^2 + 1e-3 (|o|^2 is an integer, so
  // 1.732 selects the same offsets as sqrt(3)).
  // Exactness of the relaxation depends strongly on this density. At the
  // paper's defaults (pLC 0.1, tau 75, s 10; 20 seeds per setting) radius 1
  // is exact in 13/20 cubes at 10 deg RMS rotation noise, 1/20 at 12.5 deg,
  // 0/20 from 15 deg on; radius sqrt(3) in 20/20 up to 12.5 deg and 11/20 at
  // 20 deg, the paper's reported limit (bench/results/cube_exactness.md).
  double loop_closure_radius = 1.0;
  // Rotational concentration kappa (> 0) of every measurement. The paper's
  // default 16.67 corresponds to an RMS rotation error of ~10 degrees
  // (eq. 63).
  double kappa = 16.67;
  // Translational precision tau (> 0) of every measurement. The paper's
  // default 75 corresponds to an RMS translation error of sqrt(3/75) = 0.2 m
  // in 3D.
  double tau = 75;
  // Distance between neighbouring lattice points (> 0), in meters.
  double spacing = 1.0;
  // Seed of the std::mt19937_64 stream. The output is a deterministic
  // function of the options (identical on every platform).
  uint64_t seed = 0;
};

// Generates the cube (see above). On success fills `graph` (dimension d,
// vertex ids 0..n-1 in path order, kappa and tau on every edge, EMPTY
// initial_poses, fixed_pose = -1) and `ground_truth` (n poses; pose 0 at the
// origin facing +x). Returns false with a message in `error` (if not null)
// for invalid options. Either output pointer may be null if not needed.
bool GenerateCube(const CubeOptions& options, PoseGraph* graph,
                  Poses* ground_truth, std::string* error);

// Expected value of the objective (12) at the ground truth over the noise of
// the model (10), for a graph with `num_measurements` edges of rotational
// concentration kappa in dimension d (any tau: tau E||N(0, tau^-1 I)||^2 =
// d): m (4 kappa (1 - I1(2 kappa) / I0(2 kappa)) + d).
double ExpectedGroundTruthObjective(int dimension, int num_measurements,
                                    double kappa);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CUBE_GENERATOR_H_
