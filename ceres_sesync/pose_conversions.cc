#include "ceres_sesync/pose_conversions.h"

#include <cmath>
#include <string>
#include <utility>

#include "Eigen/Cholesky"
#include "Eigen/LU"
#include "Eigen/SVD"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/rounding.h"

namespace ceres_sesync {
namespace {

std::string Num(double v) { return std::to_string(v); }

std::string ConstraintName(int index, int64_t id_begin, int64_t id_end) {
  return "constraint " + std::to_string(index) + " (" +
         std::to_string(id_begin) + " -> " + std::to_string(id_end) + ")";
}

// The part of MeasurementFromCeres2d/3d after their pose checks: (kappa,
// tau) from the information matrix (the g2o reader's convention) and the
// relative pose.
bool FinishCeresMeasurement(const std::string& name,
                            const Eigen::MatrixXd& information,
                            const Pose& pose, RelativePoseMeasurement* m,
                            std::string* error) {
  std::string message;
  if (!IsotropicPrecisions(information, &m->kappa, &m->tau, &message)) {
    return internal::ConversionFail(name + ": " + message, error);
  }
  m->R = pose.R;
  m->t = pose.t;
  return true;
}

// PoseToIsometry for Eigen::Isometry2d and Eigen::Isometry3d.
template <int kD>
bool PoseToIsometryImpl(
    const Pose& pose, Eigen::Transform<double, kD, Eigen::Isometry>* transform,
    std::string* error) {
  if (transform == nullptr) {
    return internal::ConversionFail("PoseToIsometry: null output", error);
  }
  if (!internal::CheckPoseForConversion(pose, kD, "PoseToIsometry: the pose",
                                        error)) {
    return false;
  }
  transform->setIdentity();
  transform->linear() = internal::ProjectToRotation<kD>(pose.R);
  transform->translation() = pose.t;
  return true;
}

}  // namespace

namespace internal {

bool ConversionFail(const std::string& message, std::string* error) {
  if (error != nullptr) *error = message;
  return false;
}

bool CheckPoseForConversion(const Pose& pose, int d, const std::string& what,
                            std::string* error) {
  if (pose.R.rows() != d || pose.R.cols() != d || pose.t.size() != d) {
    return ConversionFail(what + " is not a " + std::to_string(d) +
                              "D pose (R is " + std::to_string(pose.R.rows()) +
                              " x " + std::to_string(pose.R.cols()) +
                              ", t has " + std::to_string(pose.t.size()) +
                              " entries)",
                          error);
  }
  if (!pose.R.allFinite() || !pose.t.allFinite()) {
    return ConversionFail(what + " has non-finite entries", error);
  }
  return true;
}

bool CheckAdapterCall(const void* output, const char* output_name,
                      const PoseGraph& graph, int d, const char* adapter,
                      std::string* error) {
  if (output == nullptr) {
    return ConversionFail(
        std::string(adapter) + ": null " + std::string(output_name), error);
  }
  if (graph.dimension != d) {
    return ConversionFail(std::string(adapter) + ": the pose graph is " +
                              std::to_string(graph.dimension) + "D, not " +
                              std::to_string(d) + "D",
                          error);
  }
  if (graph.num_poses < 0 ||
      static_cast<int>(graph.vertex_ids.size()) != graph.num_poses) {
    return ConversionFail(std::string(adapter) + ": the pose graph has " +
                              std::to_string(graph.vertex_ids.size()) +
                              " vertex ids for " +
                              std::to_string(graph.num_poses) + " poses",
                          error);
  }
  return true;
}

// The same convention as the g2o reader (g2o_io.cc, ParseEdge).
bool MeasurementFromCeres2d(int index, int64_t id_begin, int64_t id_end,
                            double x, double y, double yaw_radians,
                            const Eigen::Matrix3d& information,
                            RelativePoseMeasurement* m, std::string* error) {
  const std::string name = ConstraintName(index, id_begin, id_end);
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw_radians)) {
    return ConversionFail(name + ": non-finite relative pose", error);
  }
  return FinishCeresMeasurement(name, information,
                                PoseFromXYYaw(x, y, yaw_radians), m, error);
}

bool MeasurementFromCeres3d(int index, int64_t id_begin, int64_t id_end,
                            const Eigen::Vector3d& p,
                            const Eigen::Quaterniond& q,
                            const Eigen::Matrix<double, 6, 6>& information,
                            RelativePoseMeasurement* m, std::string* error) {
  const std::string name = ConstraintName(index, id_begin, id_end);
  if (!p.allFinite() || !q.coeffs().allFinite()) {
    return ConversionFail(name + ": non-finite relative pose", error);
  }
  // The g2o reader's tolerance on the quaternion's length.
  const double norm = q.norm();
  if (!(std::abs(norm - 1) <= 1e-2)) {
    return ConversionFail(name + ": quaternion of length " + Num(norm) +
                              " (more than 1e-2 from unit length)",
                          error);
  }
  return FinishCeresMeasurement(name, information,
                                PoseFromQuaternionTranslation(q, p), m, error);
}

bool AddCeresMeasurement(int index, int64_t id_begin, int64_t id_end,
                         bool add_vertices, RelativePoseMeasurement m,
                         PoseGraph* graph, std::string* error) {
  const std::string name = ConstraintName(index, id_begin, id_end);
  if (id_begin == id_end) {
    return ConversionFail(name + ": self-loop", error);
  }
  if (add_vertices) {
    m.i = graph->AddVertex(id_begin);
    m.j = graph->AddVertex(id_end);
  } else {
    m.i = graph->FindVertex(id_begin);
    m.j = graph->FindVertex(id_end);
    if (m.i < 0 || m.j < 0) {
      return ConversionFail(name + ": vertex id " +
                                std::to_string(m.i < 0 ? id_begin : id_end) +
                                " is not in the poses map",
                            error);
    }
  }
  graph->measurements.push_back(std::move(m));
  return true;
}

bool FinishCeresPoseGraph(int num_constraints, PoseGraph* assembled,
                          PoseGraph* out, std::string* error) {
  if (out == nullptr) {
    return ConversionFail("null output pose graph", error);
  }
  if (num_constraints == 0) {
    return ConversionFail("no constraints: a pose graph needs measurements",
                          error);
  }
  std::string message;
  if (!ValidatePoseGraph(*assembled, &message)) {
    return ConversionFail(
        "the constraints do not form a valid pose graph: " + message, error);
  }
  *out = std::move(*assembled);
  return true;
}

}  // namespace internal

Pose PoseFromIsometry(const Eigen::Isometry2d& transform) {
  return Pose{transform.linear(), transform.translation()};
}

Pose PoseFromIsometry(const Eigen::Isometry3d& transform) {
  return Pose{transform.linear(), transform.translation()};
}

Pose PoseFromQuaternionTranslation(const Eigen::Quaterniond& q,
                                   const Eigen::Vector3d& t) {
  const double norm = q.norm();
  Pose pose;
  if (!(norm > 0) || !std::isfinite(norm)) {
    pose.R = Eigen::Matrix3d::Constant(std::nan(""));
  } else {
    pose.R = Eigen::Quaterniond(q.coeffs() / norm).toRotationMatrix();
  }
  pose.t = t;
  return pose;
}

Pose PoseFromXYYaw(double x, double y, double yaw_radians) {
  Pose pose;
  const double c = std::cos(yaw_radians), s = std::sin(yaw_radians);
  pose.R = (Eigen::Matrix2d() << c, -s, s, c).finished();
  pose.t = Eigen::Vector2d(x, y);
  return pose;
}

bool PoseToIsometry(const Pose& pose, Eigen::Isometry2d* transform,
                    std::string* error) {
  return PoseToIsometryImpl<2>(pose, transform, error);
}

bool PoseToIsometry(const Pose& pose, Eigen::Isometry3d* transform,
                    std::string* error) {
  return PoseToIsometryImpl<3>(pose, transform, error);
}

bool PoseToQuaternionTranslation(const Pose& pose, Eigen::Quaterniond* q,
                                 Eigen::Vector3d* t, std::string* error) {
  if (q == nullptr || t == nullptr) {
    return internal::ConversionFail("PoseToQuaternionTranslation: null output",
                                    error);
  }
  if (!internal::CheckPoseForConversion(
          pose, 3, "PoseToQuaternionTranslation: the pose", error)) {
    return false;
  }
  const Eigen::Matrix3d R = internal::ProjectToRotation<3>(pose.R);
  Eigen::Quaterniond result(R);
  result.normalize();
  if (result.w() < 0) result.coeffs() *= -1;
  *q = result;
  *t = pose.t;
  return true;
}

bool PoseToXYYaw(const Pose& pose, double* x, double* y, double* yaw_radians,
                 std::string* error) {
  if (x == nullptr || y == nullptr || yaw_radians == nullptr) {
    return internal::ConversionFail("PoseToXYYaw: null output", error);
  }
  if (!internal::CheckPoseForConversion(pose, 2, "PoseToXYYaw: the pose",
                                        error)) {
    return false;
  }
  // The angle of the nearest rotation: theta maximizes tr(R(theta)^T R) =
  // cos(theta) (R00 + R11) + sin(theta) (R10 - R01).
  *x = pose.t(0);
  *y = pose.t(1);
  *yaw_radians =
      std::atan2(pose.R(1, 0) - pose.R(0, 1), pose.R(0, 0) + pose.R(1, 1));
  return true;
}

bool PosesFromArrays(int dimension, int num_poses, const double* rotations,
                     const double* translations, Poses* poses,
                     std::string* error) {
  if (poses == nullptr) {
    return internal::ConversionFail("PosesFromArrays: null output", error);
  }
  if (dimension != 2 && dimension != 3) {
    return internal::ConversionFail(
        "PosesFromArrays: dimension must be 2 or 3, not " +
            std::to_string(dimension),
        error);
  }
  if (num_poses < 0) {
    return internal::ConversionFail("PosesFromArrays: negative num_poses",
                                    error);
  }
  if (num_poses > 0 && (rotations == nullptr || translations == nullptr)) {
    return internal::ConversionFail("PosesFromArrays: null input array", error);
  }
  const int d = dimension;
  Poses result(num_poses);
  for (int i = 0; i < num_poses; ++i) {
    result[i].R =
        Eigen::Map<const Eigen::MatrixXd>(rotations + d * d * i, d, d);
    result[i].t = Eigen::Map<const Eigen::VectorXd>(translations + d * i, d);
    if (!internal::CheckPoseForConversion(
            result[i], d, "PosesFromArrays: pose " + std::to_string(i),
            error)) {
      return false;
    }
  }
  *poses = std::move(result);
  return true;
}

bool PosesToArrays(int dimension, const Poses& poses, double* rotations,
                   double* translations, std::string* error) {
  if (dimension != 2 && dimension != 3) {
    return internal::ConversionFail(
        "PosesToArrays: dimension must be 2 or 3, not " +
            std::to_string(dimension),
        error);
  }
  if (!poses.empty() && (rotations == nullptr || translations == nullptr)) {
    return internal::ConversionFail("PosesToArrays: null output array", error);
  }
  const int d = dimension;
  for (size_t i = 0; i < poses.size(); ++i) {
    const Pose& pose = poses[i];
    if (pose.R.rows() != d || pose.R.cols() != d || pose.t.size() != d) {
      return internal::ConversionFail("PosesToArrays: pose " +
                                          std::to_string(i) + " is not " +
                                          std::to_string(d) + "D",
                                      error);
    }
  }
  for (size_t i = 0; i < poses.size(); ++i) {
    Eigen::Map<Eigen::MatrixXd>(rotations + d * d * i, d, d) = poses[i].R;
    Eigen::Map<Eigen::VectorXd>(translations + d * i, d) = poses[i].t;
  }
  return true;
}

}  // namespace ceres_sesync
