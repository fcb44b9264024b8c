// The orientation of a robot travelling along a lattice axis, shared by the
// synthetic generators (cube_generator.cc, landmark_generator.cc).

#ifndef CERES_SESYNC_INTERNAL_HEADING_ROTATION_H_
#define CERES_SESYNC_INTERNAL_HEADING_ROTATION_H_

#include <cmath>

#include "Eigen/Core"
#include "Eigen/Geometry"

namespace ceres_sesync::internal {

// A rotation whose first column (the body's forward axis) is `forward`, a
// lattice axis direction (unit vector; its z component is ignored in 2D). In
// 3D the body's left axis is z x forward for horizontal headings and +y for
// vertical ones.
inline Eigen::MatrixXd HeadingRotation(int d, const Eigen::Vector3d& forward) {
  if (d == 2) {
    Eigen::MatrixXd R(2, 2);
    R << forward.x(), -forward.y(), forward.y(), forward.x();
    return R;
  }
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d left = std::abs(forward.z()) > 0.5
                                   ? Eigen::Vector3d::UnitY().eval()
                                   : up.cross(forward).eval();
  Eigen::MatrixXd R(3, 3);
  R.col(0) = forward;
  R.col(1) = left;
  R.col(2) = forward.cross(left);
  return R;
}

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_HEADING_ROTATION_H_
