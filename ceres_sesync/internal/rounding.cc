#include "ceres_sesync/internal/rounding.h"

#include "Eigen/Eigenvalues"
#include "Eigen/LU"
#include "Eigen/SVD"

namespace ceres_sesync::internal {

Eigen::MatrixXd ProjectToRotation(const Eigen::MatrixXd& M) {
  if (M.rows() == 2 && M.cols() == 2) {
    return ProjectToRotation<2>(Eigen::Matrix2d(M));
  }
  if (M.rows() == 3 && M.cols() == 3) {
    return ProjectToRotation<3>(Eigen::Matrix3d(M));
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(
      M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::MatrixXd U = svd.matrixU();
  if ((U * svd.matrixV().transpose()).determinant() < 0) {
    U.col(U.cols() - 1) *= -1;
  }
  return U * svd.matrixV().transpose();
}

Eigen::MatrixXd ProjectBlocksToRotations(const Eigen::MatrixXd& X, int d) {
  Eigen::MatrixXd R(X.rows(), X.cols());
  for (int i = 0; i < X.cols() / d; ++i) {
    if (d == 2) {
      R.middleCols<2>(2 * i) =
          ProjectToRotation<2>(Eigen::Matrix2d(X.middleCols<2>(2 * i)));
    } else if (d == 3) {
      R.middleCols<3>(3 * i) =
          ProjectToRotation<3>(Eigen::Matrix3d(X.middleCols<3>(3 * i)));
    } else {
      R.middleCols(d * i, d) = ProjectToRotation(X.middleCols(d * i, d));
    }
  }
  return R;
}

Eigen::MatrixXd RoundSolution(const Eigen::MatrixXd& Y, int d) {
  // Y = U S V^T, so S_d V_d^T = U_d^T Y, with U from the r x r Gram matrix.
  const Eigen::MatrixXd gram = Y * Y.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  // Eigenvalues ascend: the top d eigenvectors are the last d columns,
  // ordered by decreasing singular value.
  Eigen::MatrixXd Ud = eig.eigenvectors().rightCols(d).rowwise().reverse();
  Eigen::MatrixXd R = Ud.transpose() * Y;
  const int n = static_cast<int>(Y.cols() / d);
  int negative = 0;
  for (int i = 0; i < n; ++i) {
    // Fixed sizes: a closed-form determinant, no LU with heap allocation.
    const double det = d == 2   ? R.middleCols<2>(2 * i).determinant()
                       : d == 3 ? R.middleCols<3>(3 * i).determinant()
                                : R.middleCols(d * i, d).determinant();
    if (det < 0) ++negative;
  }
  if (2 * negative > n) R.row(d - 1) *= -1;
  return ProjectBlocksToRotations(R, d);
}

}  // namespace ceres_sesync::internal
