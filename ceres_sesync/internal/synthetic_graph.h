// Pieces shared by the synthetic pose-graph generators (cube_generator.h,
// city_generator.h): the heading rotation of a pose travelling along a
// lattice axis, the validation of the noise options, and one measurement of
// SE-Sync's generative model (Rosen et al., IJRR 2019, eq. 10).

#ifndef CERES_SESYNC_INTERNAL_SYNTHETIC_GRAPH_H_
#define CERES_SESYNC_INTERNAL_SYNTHETIC_GRAPH_H_

#include <cstdint>
#include <random>
#include <string>

#include "Eigen/Core"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::internal {

// Largest number of poses a generator produces.
constexpr int64_t kMaxSyntheticPoses = 10000000;

// A rotation in SO(d) whose first column (the body's forward axis) is
// `forward`, a unit lattice-axis direction (its first d coordinates; z = 0
// in 2D). In 3D the body's left axis is +z x forward for a horizontal
// heading and +y for a vertical one.
Eigen::MatrixXd HeadingRotation(int d, const Eigen::Vector3d& forward);

// Checks the options every generator shares: loop-closure probability in
// [0, 1], kappa, tau and the lattice spacing finite and positive. Returns
// false with a message otherwise.
bool CheckNoiseOptions(double loop_closure_probability, double kappa,
                       double tau, double spacing, std::string* error);

// Appends to `graph` the measurement of pose j relative to pose i drawn from
// the model (10):
//   t~_ij = R_i^T (t_j - t_i) + N(0, tau^-1 I_d),
//   R~_ij = R_i^T R_j * Langevin(I_d, kappa)   (SampleIsotropicLangevin),
// with precisions kappa and tau. Draws the rotation noise first, then the d
// translation components, from `rng`.
void AddNoisyMeasurement(const Poses& truth, int i, int j, double kappa,
                         double tau, std::mt19937_64* rng, PoseGraph* graph);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SYNTHETIC_GRAPH_H_
