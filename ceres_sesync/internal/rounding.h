// Rounding a Burer-Monteiro factor to rotations (Rosen et al. 2019,
// Algorithm 2) and projections onto SO(d).

#ifndef CERES_SESYNC_INTERNAL_ROUNDING_H_
#define CERES_SESYNC_INTERNAL_ROUNDING_H_

#include "Eigen/Core"

namespace ceres_sesync::internal {

// The nearest rotation to the d x d matrix M in the Frobenius norm (SVD with
// the sign of the last singular direction fixed so that det = +1).
Eigen::MatrixXd ProjectToRotation(const Eigen::MatrixXd& M);

// Projects every d x d block of the d x dn matrix X to SO(d).
Eigen::MatrixXd ProjectBlocksToRotations(const Eigen::MatrixXd& X, int d);

// Algorithm 2: from Y (r x dn) take the rank-d factor Sigma_d V_d^T of its
// thin SVD, reflect it if most blocks have negative determinant, and project
// every block to SO(d). Returns R (d x dn).
Eigen::MatrixXd RoundSolution(const Eigen::MatrixXd& Y, int d);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_ROUNDING_H_
