// Rounding a Burer-Monteiro factor to rotations (Rosen et al. 2019,
// Algorithm 2) and projections onto SO(d).

#ifndef CERES_SESYNC_INTERNAL_ROUNDING_H_
#define CERES_SESYNC_INTERNAL_ROUNDING_H_

#include <cmath>

#include "Eigen/Core"
#include "Eigen/LU"
#include "Eigen/SVD"

namespace ceres_sesync::internal {

// The nearest rotation to the kD x kD matrix M in the Frobenius norm:
// U diag(1, .., det(U V^T)) V^T from its SVD; for kD = 2 in closed form (the
// angle maximizing tr(R^T M)). Fixed size: no heap allocation.
template <int kD>
Eigen::Matrix<double, kD, kD> ProjectToRotation(
    const Eigen::Matrix<double, kD, kD>& M) {
  if constexpr (kD == 2) {
    const double angle = std::atan2(M(1, 0) - M(0, 1), M(0, 0) + M(1, 1));
    const double c = std::cos(angle), s = std::sin(angle);
    return (Eigen::Matrix2d() << c, -s, s, c).finished();
  } else {
    Eigen::JacobiSVD<Eigen::Matrix<double, kD, kD>> svd(
        M, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix<double, kD, 1> sign = Eigen::Matrix<double, kD, 1>::Ones();
    if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) {
      sign(kD - 1) = -1;
    }
    return svd.matrixU() * sign.asDiagonal() * svd.matrixV().transpose();
  }
}

// The same for a dynamic-size square M (fixed-size kernels for d = 2, 3).
Eigen::MatrixXd ProjectToRotation(const Eigen::MatrixXd& M);

// Projects every d x d block of the d x dn matrix X to SO(d).
Eigen::MatrixXd ProjectBlocksToRotations(const Eigen::MatrixXd& X, int d);

// Algorithm 2: from Y (r x dn) take the rank-d factor Sigma_d V_d^T of its
// thin SVD, reflect it if most blocks have negative determinant, and project
// every block to SO(d). Returns R (d x dn).
Eigen::MatrixXd RoundSolution(const Eigen::MatrixXd& Y, int d);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_ROUNDING_H_
