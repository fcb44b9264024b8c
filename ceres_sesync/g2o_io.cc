#include "ceres_sesync/g2o_io.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "Eigen/Cholesky"
#include "Eigen/Geometry"
#include "ceres_sesync/internal/file_util.h"
#include "glog/logging.h"

namespace ceres_sesync {
namespace {

// Quaternions whose norm is within this of 1 are normalized; others are an
// error.
constexpr double kQuaternionTolerance = 1e-2;
// Normalizations larger than this are counted in the summary.
constexpr double kQuaternionCountThreshold = 1e-12;
// The writers' PARAMS_SE3OFFSET: the identity offset, id 0.
constexpr int64_t kIdentityOffsetId = 0;

enum class Tag {
  kVertexSE2,        // VERTEX_SE2, VERTEX2
  kVertexSE3,        // VERTEX_SE3:QUAT
  kEdgeSE2,          // EDGE_SE2
  kEdge2,            // EDGE2 (TORO information order)
  kEdgeSE3,          // EDGE_SE3:QUAT
  kVertexXY,         // VERTEX_XY (2D point landmark)
  kVertexTrackXYZ,   // VERTEX_TRACKXYZ (3D point landmark)
  kEdgeSE2XY,        // EDGE_SE2_XY (pose -> 2D landmark)
  kEdgeSE3TrackXYZ,  // EDGE_SE3_TRACKXYZ (pose -> 3D landmark, offset param)
  kPriorSE2,         // EDGE_PRIOR_SE2 (2D pose prior)
  kPriorSE2XY,       // EDGE_PRIOR_SE2_XY (2D position prior)
  kPriorSE3,         // EDGE_SE3_PRIOR (3D pose prior, offset param)
  kPriorSE3XYZ,      // EDGE_SE3_XYZ_PRIOR (3D position prior, offset param)
  kParamsSE3Offset,  // PARAMS_SE3OFFSET
  kFix,              // FIX
  kLegacy3D,         // VERTEX3, EDGE3
  kUnsupported,      // anything else
};

Tag Classify(std::string_view tag) {
  if (tag == "VERTEX_SE2" || tag == "VERTEX2") return Tag::kVertexSE2;
  if (tag == "VERTEX_SE3:QUAT") return Tag::kVertexSE3;
  if (tag == "EDGE_SE2") return Tag::kEdgeSE2;
  if (tag == "EDGE2") return Tag::kEdge2;
  if (tag == "EDGE_SE3:QUAT") return Tag::kEdgeSE3;
  if (tag == "VERTEX_XY") return Tag::kVertexXY;
  if (tag == "VERTEX_TRACKXYZ") return Tag::kVertexTrackXYZ;
  if (tag == "EDGE_SE2_XY") return Tag::kEdgeSE2XY;
  if (tag == "EDGE_SE3_TRACKXYZ") return Tag::kEdgeSE3TrackXYZ;
  if (tag == "EDGE_PRIOR_SE2") return Tag::kPriorSE2;
  if (tag == "EDGE_PRIOR_SE2_XY") return Tag::kPriorSE2XY;
  if (tag == "EDGE_SE3_PRIOR") return Tag::kPriorSE3;
  if (tag == "EDGE_SE3_XYZ_PRIOR") return Tag::kPriorSE3XYZ;
  if (tag == "PARAMS_SE3OFFSET") return Tag::kParamsSE3Offset;
  if (tag == "FIX") return Tag::kFix;
  if (tag == "VERTEX3" || tag == "EDGE3") return Tag::kLegacy3D;
  return Tag::kUnsupported;
}

int DimensionOf(Tag tag) {
  switch (tag) {
    case Tag::kVertexSE2:
    case Tag::kEdgeSE2:
    case Tag::kEdge2:
    case Tag::kVertexXY:
    case Tag::kEdgeSE2XY:
    case Tag::kPriorSE2:
    case Tag::kPriorSE2XY:
      return 2;
    case Tag::kVertexSE3:
    case Tag::kEdgeSE3:
    case Tag::kVertexTrackXYZ:
    case Tag::kEdgeSE3TrackXYZ:
    case Tag::kPriorSE3:
    case Tag::kPriorSE3XYZ:
    case Tag::kParamsSE3Offset:
      return 3;
    default:
      return 0;
  }
}

// Number of fields after the tag.
int FieldCount(Tag tag) {
  switch (tag) {
    case Tag::kVertexSE2:
      return 4;
    case Tag::kVertexSE3:
      return 8;
    case Tag::kEdgeSE2:
    case Tag::kEdge2:
      return 11;
    case Tag::kEdgeSE3:
      return 30;
    case Tag::kVertexXY:
      return 3;  // id x y
    case Tag::kVertexTrackXYZ:
      return 4;  // id x y z
    case Tag::kEdgeSE2XY:
      return 7;  // pose landmark x y I11 I12 I22
    case Tag::kEdgeSE3TrackXYZ:
      return 12;  // pose landmark param x y z I(6)
    case Tag::kPriorSE2:
      return 10;  // pose x y theta I(6)
    case Tag::kPriorSE2XY:
      return 6;  // pose x y I11 I12 I22
    case Tag::kPriorSE3:
      return 30;  // pose param x y z qx qy qz qw I(21)
    case Tag::kPriorSE3XYZ:
      return 11;  // pose param x y z I(6)
    case Tag::kParamsSE3Offset:
      return 8;  // id x y z qx qy qz qw
    case Tag::kFix:
      return 1;
    default:
      return 0;
  }
}

bool IsPoseVertex(Tag tag) {
  return tag == Tag::kVertexSE2 || tag == Tag::kVertexSE3;
}
bool IsLandmarkVertex(Tag tag) {
  return tag == Tag::kVertexXY || tag == Tag::kVertexTrackXYZ;
}
bool IsPoseEdge(Tag tag) {
  return tag == Tag::kEdgeSE2 || tag == Tag::kEdge2 || tag == Tag::kEdgeSE3;
}
bool IsLandmarkEdge(Tag tag) {
  return tag == Tag::kEdgeSE2XY || tag == Tag::kEdgeSE3TrackXYZ;
}
bool IsPrior(Tag tag) {
  return tag == Tag::kPriorSE2 || tag == Tag::kPriorSE2XY ||
         tag == Tag::kPriorSE3 || tag == Tag::kPriorSE3XYZ;
}

// Where a message is about, and the error sink.
struct Location {
  const std::string& name;
  int line = 0;
  std::string* error = nullptr;

  bool Fail(const std::string& message) const {
    if (error) *error = name + ":" + std::to_string(line) + ": " + message;
    return false;
  }
};

// Splits `line` at blanks (space, tab, CR, VT, FF).
void Tokenize(std::string_view line, std::vector<std::string_view>* tokens) {
  tokens->clear();
  const auto blank = [](char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
  };
  size_t k = 0;
  while (k < line.size()) {
    while (k < line.size() && blank(line[k])) ++k;
    const size_t start = k;
    while (k < line.size() && !blank(line[k])) ++k;
    if (k > start) tokens->push_back(line.substr(start, k - start));
  }
}

// Copies a token into a NUL-terminated buffer for strtod / strtoll.
class TokenBuffer {
 public:
  explicit TokenBuffer(std::string_view token) {
    if (token.size() < sizeof(small_)) {
      std::memcpy(small_, token.data(), token.size());
      small_[token.size()] = '\0';
      data_ = small_;
    } else {
      large_.assign(token);
      data_ = large_.c_str();
    }
  }
  const char* c_str() const { return data_; }

 private:
  char small_[64];
  std::string large_;
  const char* data_;
};

// Strict parse: the whole token must be a finite number.
bool ParseDouble(std::string_view token, double* value) {
  if (token.empty()) return false;
  const TokenBuffer buffer(token);
  char* end = nullptr;
  *value = std::strtod(buffer.c_str(), &end);
  return end == buffer.c_str() + token.size();
}

// Strict parse of a non-negative integer id.
bool ParseId(std::string_view token, int64_t* value) {
  if (token.empty()) return false;
  const TokenBuffer buffer(token);
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(buffer.c_str(), &end, 10);
  if (errno != 0 || end != buffer.c_str() + token.size() || v < 0) return false;
  *value = v;
  return true;
}

// Parses tokens[first, first + count) as finite numbers.
bool ParseNumbers(const Location& at,
                  const std::vector<std::string_view>& tokens, int first,
                  int count, double* out) {
  for (int k = 0; k < count; ++k) {
    const std::string_view token = tokens[first + k];
    if (!ParseDouble(token, &out[k])) {
      return at.Fail("field " + std::to_string(first + k) + " '" +
                     std::string(token) + "' is not a number");
    }
    if (!std::isfinite(out[k])) {
      return at.Fail("field " + std::to_string(first + k) + " '" +
                     std::string(token) + "' is not finite");
    }
  }
  return true;
}

bool ParseIdField(const Location& at,
                  const std::vector<std::string_view>& tokens, int k,
                  int64_t* id) {
  if (!ParseId(tokens[k], id)) {
    return at.Fail("field " + std::to_string(k) + " '" +
                   std::string(tokens[k]) +
                   "' is not a vertex id (a non-negative integer)");
  }
  return true;
}

// Checks that the line has exactly the fields its tag needs.
bool CheckFieldCount(const Location& at,
                     const std::vector<std::string_view>& tokens,
                     int expected) {
  const int found = static_cast<int>(tokens.size()) - 1;
  if (found == expected) return true;
  std::string message = std::string(tokens[0]) + " needs " +
                        std::to_string(expected) +
                        (expected == 1 ? " field" : " fields") + ", found " +
                        std::to_string(found);
  if (found > expected) {
    message +=
        " (unexpected trailing '" + std::string(tokens[expected + 1]) + "')";
  }
  return at.Fail(message);
}

Eigen::MatrixXd RotationFromAngle(double theta) {
  Eigen::MatrixXd R(2, 2);
  const double c = std::cos(theta), s = std::sin(theta);
  R << c, -s, s, c;
  return R;
}

// Converts (qx, qy, qz, qw) to a rotation matrix, normalizing it if its norm
// is within kQuaternionTolerance of 1.
bool RotationFromQuaternion(const Location& at, const double* q,
                            Eigen::MatrixXd* R, int* num_normalized) {
  Eigen::Quaterniond quaternion(q[3], q[0], q[1], q[2]);
  const double norm = quaternion.norm();
  if (!(std::abs(norm - 1) <= kQuaternionTolerance)) {
    std::ostringstream s;
    s << "quaternion (qx qy qz qw) = (" << q[0] << " " << q[1] << " " << q[2]
      << " " << q[3] << ") has norm " << norm << "; expected 1 (tolerance "
      << kQuaternionTolerance << ")";
    return at.Fail(s.str());
  }
  if (std::abs(norm - 1) > kQuaternionCountThreshold) ++*num_normalized;
  quaternion.coeffs() /= norm;
  *R = quaternion.toRotationMatrix();
  return true;
}

// Parses a VERTEX line (already field-count checked) into an id and a pose.
bool ParseVertex(const Location& at, Tag tag,
                 const std::vector<std::string_view>& tokens, int64_t* id,
                 Pose* pose, int* num_normalized) {
  if (!ParseIdField(at, tokens, 1, id)) return false;
  double v[7];
  if (tag == Tag::kVertexSE2) {
    if (!ParseNumbers(at, tokens, 2, 3, v)) return false;
    pose->t = Eigen::Vector2d(v[0], v[1]);
    pose->R = RotationFromAngle(v[2]);
    return true;
  }
  if (!ParseNumbers(at, tokens, 2, 7, v)) return false;
  pose->t = Eigen::Vector3d(v[0], v[1], v[2]);
  return RotationFromQuaternion(at, v + 3, &pose->R, num_normalized);
}

// (kappa, tau) of an edge. Some benchmark files (5021 edges of cubicle.g2o)
// have cross terms that make the full information matrix indefinite although
// the translation and rotation blocks are positive definite; such edges are
// accepted (only the blocks enter the model) and counted.
bool SetPrecisions(const Location& at, const Eigen::MatrixXd& info,
                   RelativePoseMeasurement* m, G2oReadSummary* counts) {
  std::string message;
  if (!IsotropicPrecisions(info, &m->kappa, &m->tau, &message)) {
    return at.Fail(message);
  }
  if (info.llt().info() != Eigen::Success) ++counts->num_indefinite_information;
  return true;
}

// Parses an EDGE line (already field-count checked) into two ids and a
// measurement with kappa and tau.
bool ParseEdge(const Location& at, Tag tag,
               const std::vector<std::string_view>& tokens, int64_t* id_i,
               int64_t* id_j, RelativePoseMeasurement* m,
               G2oReadSummary* counts) {
  if (!ParseIdField(at, tokens, 1, id_i) ||
      !ParseIdField(at, tokens, 2, id_j)) {
    return false;
  }
  if (*id_i == *id_j) {
    return at.Fail("self-loop: edge from vertex " + std::to_string(*id_i) +
                   " to itself");
  }
  if (tag == Tag::kEdgeSE2 || tag == Tag::kEdge2) {
    double v[9];
    if (!ParseNumbers(at, tokens, 3, 9, v)) return false;
    m->t = Eigen::Vector2d(v[0], v[1]);
    m->R = RotationFromAngle(v[2]);
    const double* u = v + 3;
    // Upper triangle entries I11 I12 I13 I22 I23 I33.
    const double I11 = u[0], I12 = u[1];
    double I13, I22, I23, I33;
    if (tag == Tag::kEdgeSE2) {
      I13 = u[2], I22 = u[3], I23 = u[4], I33 = u[5];
    } else {  // TORO: I11 I12 I22 I33 I13 I23.
      I22 = u[2], I33 = u[3], I13 = u[4], I23 = u[5];
    }
    Eigen::Matrix3d info;
    info << I11, I12, I13, I12, I22, I23, I13, I23, I33;
    if (!SetPrecisions(at, info, m, counts)) return false;
  } else {
    double v[28];
    if (!ParseNumbers(at, tokens, 3, 28, v)) return false;
    m->t = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!RotationFromQuaternion(at, v + 3, &m->R,
                                &counts->num_normalized_quaternions)) {
      return false;
    }
    Eigen::Matrix<double, 6, 6> info;
    const double* u = v + 7;
    for (int r = 0; r < 6; ++r) {
      for (int c = r; c < 6; ++c) info(r, c) = info(c, r) = *u++;
    }
    if (!SetPrecisions(at, info, m, counts)) return false;
  }
  return true;
}

// d / tr(I^-1) of a positive definite d x d information block, d = 2 or 3
// (2D: tr(I^-1) = (I11 + I22) / det).
double TraceInversePrecision(const Eigen::MatrixXd& info) {
  if (info.rows() == 2) {
    const double det = info(0, 0) * info(1, 1) - info(0, 1) * info(0, 1);
    return 2 * det / (info(0, 0) + info(1, 1));
  }
  return 3 / info.inverse().trace();
}

// The symmetric d x d matrix of the upper-triangle entries u (row by row).
Eigen::MatrixXd SymmetricFromUpper(const double* u, int d) {
  Eigen::MatrixXd info(d, d);
  for (int r = 0; r < d; ++r) {
    for (int c = r; c < d; ++c) info(r, c) = info(c, r) = *u++;
  }
  return info;
}

bool ParseParameterId(const Location& at,
                      const std::vector<std::string_view>& tokens, int k,
                      int64_t* id) {
  if (!ParseId(tokens[k], id)) {
    return at.Fail("field " + std::to_string(k) + " '" +
                   std::string(tokens[k]) +
                   "' is not a parameter id (a non-negative integer)");
  }
  return true;
}

// A PARAMS_SE3OFFSET: the pose of the sensor in the frame of the robot
// pose, x_sensor = x_pose * offset.
struct SensorOffset {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  int line = 0;
};
using SensorOffsets = std::unordered_map<int64_t, SensorOffset>;

// Looks up the offset of parameter field k of an edge line.
bool FindOffset(const Location& at, const std::vector<std::string_view>& tokens,
                int k, const SensorOffsets& offsets,
                const SensorOffset** offset) {
  int64_t id;
  if (!ParseParameterId(at, tokens, k, &id)) return false;
  const auto it = offsets.find(id);
  if (it == offsets.end()) {
    return at.Fail("parameter " + std::to_string(id) +
                   " is not defined: a PARAMS_SE3OFFSET line with this id "
                   "must come before the edges that use it (as in g2o)");
  }
  *offset = &it->second;
  return true;
}

// Parses a PARAMS_SE3OFFSET line (id x y z qx qy qz qw).
bool ParseOffset(const Location& at,
                 const std::vector<std::string_view>& tokens, int64_t* id,
                 SensorOffset* offset, int* num_normalized) {
  if (!ParseParameterId(at, tokens, 1, id)) return false;
  double v[7];
  if (!ParseNumbers(at, tokens, 2, 7, v)) return false;
  offset->t = Eigen::Vector3d(v[0], v[1], v[2]);
  Eigen::MatrixXd R;
  if (!RotationFromQuaternion(at, v + 3, &R, num_normalized)) return false;
  offset->R = R;
  offset->line = at.line;
  return true;
}

// Parses a landmark VERTEX line (id and d coordinates).
bool ParseLandmarkVertex(const Location& at, Tag tag,
                         const std::vector<std::string_view>& tokens,
                         int64_t* id, Eigen::VectorXd* position) {
  if (!ParseIdField(at, tokens, 1, id)) return false;
  const int d = tag == Tag::kVertexXY ? 2 : 3;
  double v[3];
  if (!ParseNumbers(at, tokens, 2, d, v)) return false;
  *position = Eigen::Map<const Eigen::VectorXd>(v, d);
  return true;
}

// Parses a pose -> landmark edge:
//   EDGE_SE2_XY pose landmark x y I11 I12 I22
//   EDGE_SE3_TRACKXYZ pose landmark param x y z I11 I12 I13 I22 I23 I33.
// g2o's errors are x_pose^-1 p - z (2D) and (x_pose * offset)^-1 p - z (3D),
// so the measurement in the pose frame is z (2D) and t_off + R_off z (3D);
// nu = d / tr(I^-1) is unchanged by the rotation R_off.
bool ParseLandmarkEdge(const Location& at, Tag tag,
                       const std::vector<std::string_view>& tokens,
                       const SensorOffsets& offsets, int64_t* pose_id,
                       int64_t* landmark_id, LandmarkMeasurement* m) {
  if (!ParseIdField(at, tokens, 1, pose_id) ||
      !ParseIdField(at, tokens, 2, landmark_id)) {
    return false;
  }
  if (*pose_id == *landmark_id) {
    return at.Fail("self-loop: vertex " + std::to_string(*pose_id) +
                   " is both the pose and the landmark of this edge");
  }
  const int d = tag == Tag::kEdgeSE2XY ? 2 : 3;
  const SensorOffset* offset = nullptr;
  if (d == 3 && !FindOffset(at, tokens, 3, offsets, &offset)) return false;
  const int first = d == 2 ? 3 : 4;
  double v[9];
  if (!ParseNumbers(at, tokens, first, d + d * (d + 1) / 2, v)) return false;
  m->z = Eigen::Map<const Eigen::VectorXd>(v, d);
  if (offset) m->z = offset->t + offset->R * m->z;
  std::string message;
  if (!TranslationalPrecision(SymmetricFromUpper(v + d, d), &m->nu, &message)) {
    return at.Fail(message);
  }
  return true;
}

// (kappa, tau) of a pose prior's information matrix (g2o order: position
// block first): as for edges, except that a block may be exactly zero,
// meaning no prior on that part (g2o's own initialEstimate reads an all-zero
// block the same way). Cross terms are not used; priors whose cross terms
// make the matrix indefinite are counted.
bool PriorPrecisions(const Location& at, const Eigen::MatrixXd& info,
                     PosePrior* prior, G2oReadSummary* counts) {
  const int size = static_cast<int>(info.rows());
  const int d = size == 3 ? 2 : 3;
  const Eigen::MatrixXd info_tt = info.topLeftCorner(d, d);
  const Eigen::MatrixXd info_RR = info.bottomRightCorner(size - d, size - d);
  const bool no_position = (info_tt.array() == 0).all();
  const bool no_rotation = (info_RR.array() == 0).all();
  if (no_position && no_rotation) {
    return at.Fail(
        "prior information matrix has zero translational and rotational "
        "blocks (the prior carries no information)");
  }
  prior->tau = 0;
  prior->kappa = 0;
  if (!no_position) {
    if (info_tt.llt().info() != Eigen::Success) {
      return at.Fail(
          "translational information block is neither positive definite "
          "nor zero");
    }
    prior->tau = TraceInversePrecision(info_tt);
  }
  if (!no_rotation) {
    if (info_RR.llt().info() != Eigen::Success) {
      return at.Fail(
          "rotational information block is neither positive definite nor "
          "zero");
    }
    prior->kappa = d == 2 ? info_RR(0, 0) : 3 / (2 * info_RR.inverse().trace());
  }
  if (!(std::isfinite(prior->tau) && prior->tau >= 0 &&
        std::isfinite(prior->kappa) && prior->kappa >= 0)) {
    return at.Fail(
        "information matrix gives non-finite or non-positive precisions");
  }
  const bool cross_terms =
      !(info.topRightCorner(d, size - d).array() == 0).all();
  if (no_position || no_rotation) {
    if (cross_terms) ++counts->num_indefinite_information;
  } else if (info.llt().info() != Eigen::Success) {
    ++counts->num_indefinite_information;
  }
  return true;
}

// Parses a prior line:
//   EDGE_PRIOR_SE2 pose x y theta I11 I12 I13 I22 I23 I33
//   EDGE_PRIOR_SE2_XY pose x y I11 I12 I22
//   EDGE_SE3_PRIOR pose param x y z qx qy qz qw I11 .. I16 I22 .. I66
//   EDGE_SE3_XYZ_PRIOR pose param x y z I11 I12 I13 I22 I23 I33.
// g2o's errors: EDGE_PRIOR_SE2 and EDGE_SE3_PRIOR compare Z^-1 (x * offset)
// with the identity (translation in Z's frame, so the isotropic tau is that
// of the world frame); EDGE_PRIOR_SE2_XY and EDGE_SE3_XYZ_PRIOR compare the
// position with z directly (the latter does not use its offset). An
// EDGE_SE3_PRIOR offset with a rotation R_off only is applied exactly (R~ =
// R_Z R_off^T); a translational offset would couple position and rotation,
// which the model has no term for, and is rejected.
bool ParsePrior(const Location& at, Tag tag,
                const std::vector<std::string_view>& tokens,
                const SensorOffsets& offsets, int64_t* pose_id,
                PosePrior* prior, G2oReadSummary* counts) {
  if (!ParseIdField(at, tokens, 1, pose_id)) return false;
  double v[28];
  std::string message;
  switch (tag) {
    case Tag::kPriorSE2: {
      if (!ParseNumbers(at, tokens, 2, 9, v)) return false;
      prior->t = Eigen::Vector2d(v[0], v[1]);
      prior->R = RotationFromAngle(v[2]);
      return PriorPrecisions(at, SymmetricFromUpper(v + 3, 3), prior, counts);
    }
    case Tag::kPriorSE2XY:
    case Tag::kPriorSE3XYZ: {
      const int d = tag == Tag::kPriorSE2XY ? 2 : 3;
      const SensorOffset* offset = nullptr;
      if (d == 3 && !FindOffset(at, tokens, 2, offsets, &offset)) {
        return false;
      }
      const int first = d == 2 ? 2 : 3;
      if (!ParseNumbers(at, tokens, first, d + d * (d + 1) / 2, v)) {
        return false;
      }
      prior->t = Eigen::Map<const Eigen::VectorXd>(v, d);
      prior->kappa = 0;
      if (!TranslationalPrecision(SymmetricFromUpper(v + d, d), &prior->tau,
                                  &message)) {
        return at.Fail(message);
      }
      return true;
    }
    case Tag::kPriorSE3: {
      const SensorOffset* offset = nullptr;
      if (!FindOffset(at, tokens, 2, offsets, &offset)) return false;
      if (!(offset->t.array() == 0).all()) {
        std::ostringstream s;
        s << "EDGE_SE3_PRIOR with parameter " << tokens[2]
          << ", whose offset (PARAMS_SE3OFFSET on line " << offset->line
          << ") has the translation (" << offset->t.transpose()
          << "): only offsets without translation are supported for pose "
             "priors";
        return at.Fail(s.str());
      }
      if (!ParseNumbers(at, tokens, 3, 28, v)) return false;
      prior->t = Eigen::Vector3d(v[0], v[1], v[2]);
      if (!RotationFromQuaternion(at, v + 3, &prior->R,
                                  &counts->num_normalized_quaternions)) {
        return false;
      }
      prior->R = prior->R * offset->R.transpose();
      return PriorPrecisions(at, SymmetricFromUpper(v + 7, 6), prior, counts);
    }
    default:
      return at.Fail("internal error: not a prior tag");
  }
}

std::string UnsupportedTagMessage(std::string_view tag) {
  if (Classify(tag) == Tag::kLegacy3D) {
    return "unsupported legacy tag '" + std::string(tag) +
           "' (TORO 3D files are not supported; convert to VERTEX_SE3:QUAT / "
           "EDGE_SE3:QUAT)";
  }
  return "unsupported tag '" + std::string(tag) +
         "' (supported: SE(2)/SE(3) pose vertices and edges, point landmarks "
         "VERTEX_XY/EDGE_SE2_XY and VERTEX_TRACKXYZ/EDGE_SE3_TRACKXYZ, pose "
         "priors EDGE_PRIOR_SE2, EDGE_PRIOR_SE2_XY, EDGE_SE3_PRIOR, "
         "EDGE_SE3_XYZ_PRIOR, PARAMS_SE3OFFSET and FIX; other lines can be "
         "skipped with --skip_unsupported_tags)";
}

// Calls visit(line_number, line) for each line of `text`.
template <typename Visit>
bool ForEachLine(std::string_view text, int* num_lines, Visit visit) {
  int number = 0;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    if (!visit(++number, text.substr(start, end - start))) return false;
    start = end + 1;
  }
  *num_lines = number;
  return true;
}

// The parser proper, working on the whole file text.
bool ParseG2oText(std::string_view text, const std::string& name,
                  const G2oReadOptions& options, PoseGraph* graph,
                  std::string* error, G2oReadSummary* summary) {
  *graph = PoseGraph();
  G2oReadSummary counts;
  Location at{name, 0, error};

  int dimension_line = 0;
  std::string dimension_tag;
  std::vector<int> first_line;  // Per dense pose index: line of first use.
  std::vector<int> landmark_first_line;  // The same per landmark.
  // References to pose ids in file order, resolved to dense indices at the
  // end: the slot is field `field` (0: i, 1: j) of record `index` of
  // graph->measurements (kind 0), ->landmark_measurements (1), ->priors (2).
  struct PoseRef {
    int64_t id;
    int line;
    int kind, index, field;
  };
  std::vector<PoseRef> pose_refs;
  struct LandmarkRef {
    int64_t id;
    int line;
  };
  std::vector<LandmarkRef> landmark_refs;  // One per landmark measurement.
  int first_prior_line = 0;
  SensorOffsets offsets;
  int64_t fix_id = -1;
  int fix_line = 0;

  // Line of the VERTEX line that defined pose / landmark vertex `id`, or 0.
  auto vertex_line = [&](int64_t id) {
    const int pose = graph->FindVertex(id);
    if (pose >= 0) return first_line[pose];
    const int landmark = graph->FindLandmark(id);
    return landmark >= 0 ? landmark_first_line[landmark] : 0;
  };

  std::vector<std::string_view> tokens;
  tokens.reserve(32);
  auto visit = [&](int number, std::string_view line) {
    at.line = number;
    Tokenize(line, &tokens);
    if (tokens.empty() || tokens[0][0] == '#') return true;
    const Tag tag = Classify(tokens[0]);
    if (tag == Tag::kUnsupported && options.skip_unsupported_tags) {
      const std::string tag_name(tokens[0]);
      if (counts.skipped_tags[tag_name]++ == 0) {
        LOG(WARNING) << name << ":" << number << ": skipping unsupported tag '"
                     << tag_name << "' (first of possibly many)";
      }
      ++counts.num_skipped_lines;
      return true;
    }
    if (tag == Tag::kUnsupported || tag == Tag::kLegacy3D) {
      return at.Fail(UnsupportedTagMessage(tokens[0]));
    }
    if (!CheckFieldCount(at, tokens, FieldCount(tag))) return false;
    if (const int d = DimensionOf(tag); d != 0) {
      if (graph->dimension == 0) {
        graph->dimension = d;
        dimension_line = number;
        dimension_tag = std::string(tokens[0]);
      } else if (graph->dimension != d) {
        return at.Fail("mixed 2D and 3D tags: " + std::string(tokens[0]) +
                       " here, but " + dimension_tag + " on line " +
                       std::to_string(dimension_line));
      }
    }
    switch (tag) {
      case Tag::kVertexSE2:
      case Tag::kVertexSE3: {
        int64_t id;
        Pose pose;
        if (!ParseVertex(at, tag, tokens, &id, &pose,
                         &counts.num_normalized_quaternions)) {
          return false;
        }
        if (const int previous = vertex_line(id); previous != 0) {
          return at.Fail("duplicate VERTEX id " + std::to_string(id) +
                         " (first defined on line " + std::to_string(previous) +
                         ")");
        }
        graph->AddVertex(id);
        first_line.push_back(number);
        graph->initial_poses.push_back(std::move(pose));
        return true;
      }
      case Tag::kVertexXY:
      case Tag::kVertexTrackXYZ: {
        int64_t id;
        Eigen::VectorXd position;
        if (!ParseLandmarkVertex(at, tag, tokens, &id, &position)) {
          return false;
        }
        if (const int previous = vertex_line(id); previous != 0) {
          return at.Fail("duplicate VERTEX id " + std::to_string(id) +
                         " (first defined on line " + std::to_string(previous) +
                         ")");
        }
        graph->AddLandmark(id);
        landmark_first_line.push_back(number);
        graph->initial_landmarks.push_back(std::move(position));
        return true;
      }
      case Tag::kEdgeSE2:
      case Tag::kEdge2:
      case Tag::kEdgeSE3: {
        int64_t i, j;
        RelativePoseMeasurement m;
        if (!ParseEdge(at, tag, tokens, &i, &j, &m, &counts)) return false;
        const int index = static_cast<int>(graph->measurements.size());
        pose_refs.push_back({i, number, 0, index, 0});
        pose_refs.push_back({j, number, 0, index, 1});
        graph->measurements.push_back(std::move(m));
        return true;
      }
      case Tag::kEdgeSE2XY:
      case Tag::kEdgeSE3TrackXYZ: {
        int64_t i, l;
        LandmarkMeasurement m;
        if (!ParseLandmarkEdge(at, tag, tokens, offsets, &i, &l, &m)) {
          return false;
        }
        const int index = static_cast<int>(graph->landmark_measurements.size());
        pose_refs.push_back({i, number, 1, index, 0});
        landmark_refs.push_back({l, number});
        graph->landmark_measurements.push_back(std::move(m));
        return true;
      }
      case Tag::kPriorSE2:
      case Tag::kPriorSE2XY:
      case Tag::kPriorSE3:
      case Tag::kPriorSE3XYZ: {
        int64_t i;
        PosePrior prior;
        if (!ParsePrior(at, tag, tokens, offsets, &i, &prior, &counts)) {
          return false;
        }
        const int index = static_cast<int>(graph->priors.size());
        pose_refs.push_back({i, number, 2, index, 0});
        graph->priors.push_back(std::move(prior));
        if (first_prior_line == 0) first_prior_line = number;
        return true;
      }
      case Tag::kParamsSE3Offset: {
        int64_t id;
        SensorOffset offset;
        if (!ParseOffset(at, tokens, &id, &offset,
                         &counts.num_normalized_quaternions)) {
          return false;
        }
        const auto [it, inserted] = offsets.emplace(id, offset);
        if (!inserted) {
          return at.Fail("duplicate PARAMS_SE3OFFSET id " + std::to_string(id) +
                         " (first defined on line " +
                         std::to_string(it->second.line) + ")");
        }
        return true;
      }
      case Tag::kFix: {
        int64_t id;
        if (!ParseIdField(at, tokens, 1, &id)) return false;
        if (fix_line != 0 && id != fix_id) {
          return at.Fail("a second FIX vertex (" + std::to_string(id) +
                         "); line " + std::to_string(fix_line) + " fixes " +
                         std::to_string(fix_id) +
                         " and only one fixed vertex is supported");
        }
        fix_id = id;
        fix_line = number;
        return true;
      }
      default:
        return at.Fail(UnsupportedTagMessage(tokens[0]));
    }
  };
  int num_lines = 0;
  if (!ForEachLine(text, &num_lines, visit)) return false;

  // Where to report problems found at the end of the file.
  at.line = std::max(num_lines, 1);
  if (graph->measurements.empty() && graph->landmark_measurements.empty() &&
      graph->priors.empty()) {
    return at.Fail(
        "end of file: no EDGE lines (a pose graph needs at least "
        "one measurement)");
  }

  // Resolve the pose ids to dense indices (file order).
  const bool has_vertex_lines = graph->num_poses > 0;
  for (const PoseRef& ref : pose_refs) {
    at.line = ref.line;
    if (const int landmark = graph->FindLandmark(ref.id); landmark >= 0) {
      return at.Fail("vertex " + std::to_string(ref.id) +
                     " is a landmark (line " +
                     std::to_string(landmark_first_line[landmark]) +
                     "), but this edge uses it as a pose");
    }
    int index = graph->FindVertex(ref.id);
    if (index < 0) {
      if (has_vertex_lines) {
        return at.Fail("edge refers to vertex " + std::to_string(ref.id) +
                       ", which has no VERTEX line (the file has VERTEX "
                       "lines for other vertices)");
      }
      index = graph->AddVertex(ref.id);
      first_line.push_back(ref.line);
    }
    switch (ref.kind) {
      case 0: {
        RelativePoseMeasurement& m = graph->measurements[ref.index];
        (ref.field == 0 ? m.i : m.j) = index;
        break;
      }
      case 1:
        graph->landmark_measurements[ref.index].i = index;
        break;
      default:
        graph->priors[ref.index].i = index;
    }
  }
  // Then the landmark ids.
  const bool has_landmark_vertex_lines = graph->num_landmarks > 0;
  const char* landmark_tag =
      graph->dimension == 2 ? "VERTEX_XY" : "VERTEX_TRACKXYZ";
  std::vector<char> observed(graph->num_landmarks, 0);
  for (size_t k = 0; k < landmark_refs.size(); ++k) {
    const LandmarkRef& ref = landmark_refs[k];
    at.line = ref.line;
    if (const int pose = graph->FindVertex(ref.id); pose >= 0) {
      return at.Fail("vertex " + std::to_string(ref.id) + " is a pose (line " +
                     std::to_string(first_line[pose]) +
                     "), but this edge uses it as a landmark");
    }
    int index = graph->FindLandmark(ref.id);
    if (index < 0) {
      if (has_landmark_vertex_lines) {
        return at.Fail("edge refers to landmark " + std::to_string(ref.id) +
                       ", which has no " + landmark_tag +
                       " line (the file has them for other landmarks)");
      }
      index = graph->AddLandmark(ref.id);
      landmark_first_line.push_back(ref.line);
      observed.push_back(0);
    }
    observed[index] = 1;
    graph->landmark_measurements[k].l = index;
  }
  for (int l = 0; l < graph->num_landmarks; ++l) {
    if (!observed[l]) {
      at.line = landmark_first_line[l];
      return at.Fail(
          std::string("landmark ") + std::to_string(graph->landmark_ids[l]) +
          " is not observed by any " +
          (graph->dimension == 2 ? "EDGE_SE2_XY" : "EDGE_SE3_TRACKXYZ") +
          " line");
    }
  }

  if (fix_line != 0) {
    at.line = fix_line;
    graph->fixed_pose = graph->FindVertex(fix_id);
    if (graph->FindLandmark(fix_id) >= 0) {
      return at.Fail("FIX refers to landmark " + std::to_string(fix_id) +
                     " (only a pose can be fixed)");
    }
    if (graph->fixed_pose < 0) {
      return at.Fail("FIX refers to vertex " + std::to_string(fix_id) +
                     ", which is not in the graph");
    }
    if (!graph->priors.empty()) {
      return at.Fail(
          "FIX together with priors (first prior on line " +
          std::to_string(first_prior_line) +
          "): the priors fix the gauge, and a fixed vertex on top of them "
          "would be a hard constraint the model does not have; remove the "
          "FIX line");
    }
  }

  std::vector<int> component;
  const int num_components = ConnectedComponents(*graph, &component);
  if (num_components > 1 && !options.allow_disconnected) {
    const int n = graph->num_poses;
    std::vector<int> sizes(num_components, 0);
    for (int c : component) ++sizes[c];
    // The first pose (or landmark) outside the component of pose 0.
    int stray = 0;
    while (component[stray] == component[0]) ++stray;
    std::vector<int> sorted = sizes;
    std::sort(sorted.rbegin(), sorted.rend());
    std::ostringstream s;
    s << "measurement graph is disconnected: " << num_components
      << " components of sizes ";
    for (int k = 0; k < std::min(num_components, 5); ++k) {
      s << (k ? ", " : "") << sorted[k];
    }
    if (num_components > 5) s << ", ...";
    s << "; " << (stray < n ? "vertex " : "landmark ")
      << (stray < n ? graph->vertex_ids[stray] : graph->landmark_ids[stray - n])
      << " (first seen here) is not connected to vertex "
      << graph->vertex_ids[0];
    at.line = stray < n ? first_line[stray] : landmark_first_line[stray - n];
    return at.Fail(s.str());
  }

  if (!graph->priors.empty() && !options.allow_disconnected) {
    const int k = TranslationalComponents(*graph, &component);
    if (k > 1) {
      const int n = graph->num_poses;
      int stray = 0;
      while (component[stray] == component[0]) ++stray;
      std::ostringstream s;
      s << "the translational terms are disconnected: " << k << " components; "
        << (stray < n ? "vertex " : "landmark ")
        << (stray < n ? graph->vertex_ids[stray]
                      : graph->landmark_ids[stray - n])
        << " (first seen here) is tied to vertex " << graph->vertex_ids[0]
        << " only through rotation priors, so its translation would be free";
      at.line = stray < n ? first_line[stray] : landmark_first_line[stray - n];
      return at.Fail(s.str());
    }
  }

  std::string invalid;
  ValidationOptions validation;
  validation.require_connected = !options.allow_disconnected;
  if (!ValidatePoseGraph(*graph, validation, &invalid)) {
    if (error) *error = name + ": invalid pose graph: " + invalid;
    return false;
  }
  if (counts.num_skipped_lines > 0) {
    LOG(WARNING) << name << ": skipped " << counts.num_skipped_lines
                 << " lines with unsupported tags";
  }
  if (summary) {
    counts.num_vertices = graph->num_poses;
    counts.num_edges = static_cast<int>(graph->measurements.size());
    counts.num_landmarks = graph->num_landmarks;
    counts.num_landmark_edges =
        static_cast<int>(graph->landmark_measurements.size());
    counts.num_priors = static_cast<int>(graph->priors.size());
    counts.num_offset_parameters = static_cast<int>(offsets.size());
    counts.has_fix = fix_line != 0;
    *summary = std::move(counts);
  }
  return true;
}

// ---- writing ---------------------------------------------------------------

// Appends the shortest decimal form of `value` that reads back exactly.
void AppendDouble(double value, std::string* out) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->push_back(' ');
  out->append(buffer, result.ptr);
}

void AppendInt(int64_t value, std::string* out) {
  out->push_back(' ');
  out->append(std::to_string(value));
}

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

// Checks what the writers rely on.
bool CheckGraphForWriting(const PoseGraph& graph, std::string* error) {
  const int d = graph.dimension;
  if (d != 2 && d != 3)
    return Fail(error, "pose graph dimension must be 2 or 3");
  if (static_cast<int>(graph.vertex_ids.size()) != graph.num_poses) {
    return Fail(error, "pose graph vertex_ids must have one entry per pose");
  }
  for (const auto& m : graph.measurements) {
    if (m.i < 0 || m.j < 0 || m.i >= graph.num_poses ||
        m.j >= graph.num_poses || m.R.rows() != d || m.R.cols() != d ||
        m.t.size() != d || !m.R.allFinite() || !m.t.allFinite() ||
        !std::isfinite(m.kappa) || !std::isfinite(m.tau)) {
      return Fail(error, "pose graph has a malformed measurement");
    }
  }
  if (static_cast<int>(graph.landmark_ids.size()) != graph.num_landmarks) {
    return Fail(error,
                "pose graph landmark_ids must have one entry per landmark");
  }
  for (const auto& m : graph.landmark_measurements) {
    if (m.i < 0 || m.i >= graph.num_poses || m.l < 0 ||
        m.l >= graph.num_landmarks || m.z.size() != d || !m.z.allFinite() ||
        !std::isfinite(m.nu)) {
      return Fail(error, "pose graph has a malformed landmark measurement");
    }
  }
  for (const auto& p : graph.priors) {
    if (p.i < 0 || p.i >= graph.num_poses || !std::isfinite(p.kappa) ||
        !std::isfinite(p.tau) || !(p.has_rotation() || p.has_position()) ||
        (p.has_rotation() &&
         (p.R.rows() != d || p.R.cols() != d || !p.R.allFinite())) ||
        (p.has_position() && (p.t.size() != d || !p.t.allFinite()))) {
      return Fail(error, "pose graph has a malformed prior");
    }
  }
  return true;
}

bool CheckLandmarks(const PoseGraph& graph, const LandmarkPositions& landmarks,
                    std::string* error) {
  if (static_cast<int>(landmarks.size()) != graph.num_landmarks) {
    return Fail(error, "expected " + std::to_string(graph.num_landmarks) +
                           " landmark positions, got " +
                           std::to_string(landmarks.size()));
  }
  for (const Eigen::VectorXd& p : landmarks) {
    if (p.size() != graph.dimension || !p.allFinite()) {
      return Fail(error,
                  "a landmark position is not a finite vector of "
                  "dimension " +
                      std::to_string(graph.dimension));
    }
  }
  return true;
}

bool CheckPoses(const PoseGraph& graph, const Poses& poses,
                std::string* error) {
  if (static_cast<int>(poses.size()) != graph.num_poses) {
    return Fail(error, "expected " + std::to_string(graph.num_poses) +
                           " poses, got " + std::to_string(poses.size()));
  }
  const int d = graph.dimension;
  for (const Pose& p : poses) {
    if (p.R.rows() != d || p.R.cols() != d || p.t.size() != d ||
        !p.R.allFinite() || !p.t.allFinite()) {
      return Fail(error, "a pose is not a finite pose of dimension " +
                             std::to_string(d));
    }
  }
  return true;
}

// Unit quaternion of a 3x3 rotation, with qw >= 0.
Eigen::Quaterniond QuaternionOf(const Eigen::MatrixXd& R) {
  Eigen::Quaterniond q{Eigen::Matrix3d(R)};
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return q;
}

double AngleOf(const Eigen::MatrixXd& R) {
  return std::atan2(R(1, 0), R(0, 0));
}

void AppendVertexLines(const PoseGraph& graph, const Poses& poses,
                       std::string* out) {
  for (int k = 0; k < graph.num_poses; ++k) {
    const Pose& p = poses[k];
    if (graph.dimension == 2) {
      out->append("VERTEX_SE2");
      AppendInt(graph.vertex_ids[k], out);
      for (double v : {p.t(0), p.t(1), AngleOf(p.R)}) AppendDouble(v, out);
    } else {
      out->append("VERTEX_SE3:QUAT");
      AppendInt(graph.vertex_ids[k], out);
      const Eigen::Quaterniond q = QuaternionOf(p.R);
      for (double v : {p.t(0), p.t(1), p.t(2), q.x(), q.y(), q.z(), q.w()}) {
        AppendDouble(v, out);
      }
    }
    out->push_back('\n');
  }
}

void AppendLandmarkVertexLines(const PoseGraph& graph,
                               const LandmarkPositions& landmarks,
                               std::string* out) {
  for (int l = 0; l < graph.num_landmarks; ++l) {
    out->append(graph.dimension == 2 ? "VERTEX_XY" : "VERTEX_TRACKXYZ");
    AppendInt(graph.landmark_ids[l], out);
    for (int k = 0; k < graph.dimension; ++k) {
      AppendDouble(landmarks[l](k), out);
    }
    out->push_back('\n');
  }
}

// The upper triangle of diag(a, .., a (d times), b, .., b (e times)).
void AppendDiagonalInformation(int d, double a, int e, double b,
                               std::string* out) {
  for (int r = 0; r < d + e; ++r) {
    for (int c = r; c < d + e; ++c) {
      AppendDouble(r != c ? 0.0 : r < d ? a : b, out);
    }
  }
}

// Landmark measurements and priors, in the tags the reader maps back to the
// same values (3D ones refer to the identity offset, parameter 0).
void AppendLandmarkAndPriorLines(const PoseGraph& graph, std::string* out) {
  const int d = graph.dimension;
  for (const LandmarkMeasurement& m : graph.landmark_measurements) {
    out->append(d == 2 ? "EDGE_SE2_XY" : "EDGE_SE3_TRACKXYZ");
    AppendInt(graph.vertex_ids[m.i], out);
    AppendInt(graph.landmark_ids[m.l], out);
    if (d == 3) AppendInt(kIdentityOffsetId, out);
    for (int k = 0; k < d; ++k) AppendDouble(m.z(k), out);
    AppendDiagonalInformation(d, m.nu, 0, 0, out);
    out->push_back('\n');
  }
  for (const PosePrior& p : graph.priors) {
    const int64_t id = graph.vertex_ids[p.i];
    if (!p.has_rotation()) {  // Position only.
      out->append(d == 2 ? "EDGE_PRIOR_SE2_XY" : "EDGE_SE3_XYZ_PRIOR");
      AppendInt(id, out);
      if (d == 3) AppendInt(kIdentityOffsetId, out);
      for (int k = 0; k < d; ++k) AppendDouble(p.t(k), out);
      AppendDiagonalInformation(d, p.tau, 0, 0, out);
    } else {  // A zero translational block when there is no position prior.
      const Eigen::VectorXd t =
          p.has_position() ? p.t : Eigen::VectorXd::Zero(d);
      out->append(d == 2 ? "EDGE_PRIOR_SE2" : "EDGE_SE3_PRIOR");
      AppendInt(id, out);
      if (d == 2) {
        for (double v : {t(0), t(1), AngleOf(p.R)}) AppendDouble(v, out);
        AppendDiagonalInformation(2, p.tau, 1, p.kappa, out);
      } else {
        AppendInt(kIdentityOffsetId, out);
        const Eigen::Quaterniond q = QuaternionOf(p.R);
        for (double v : {t(0), t(1), t(2), q.x(), q.y(), q.z(), q.w()}) {
          AppendDouble(v, out);
        }
        AppendDiagonalInformation(3, p.tau, 3, 2 * p.kappa, out);
      }
    }
    out->push_back('\n');
  }
}

}  // namespace

bool TranslationalPrecision(const Eigen::MatrixXd& information, double* nu,
                            std::string* error) {
  auto fail = [&](const char* message) {
    if (error) *error = message;
    return false;
  };
  const int d = static_cast<int>(information.rows());
  if ((d != 2 && d != 3) || information.cols() != d) {
    return fail("translational information matrix must be 2 x 2 or 3 x 3");
  }
  if (!information.allFinite()) {
    return fail("information matrix has non-finite entries");
  }
  if (information.llt().info() != Eigen::Success) {
    return fail("translational information matrix is not positive definite");
  }
  *nu = TraceInversePrecision(information);
  if (!(std::isfinite(*nu) && *nu > 0)) {
    return fail(
        "information matrix gives a non-finite or non-positive "
        "precision");
  }
  return true;
}

bool IsotropicPrecisions(const Eigen::MatrixXd& information, double* kappa,
                         double* tau, std::string* error) {
  auto fail = [&](const char* message) {
    if (error) *error = message;
    return false;
  };
  const int size = static_cast<int>(information.rows());
  if ((size != 3 && size != 6) || information.cols() != size) {
    return fail("information matrix must be 3 x 3 (2D) or 6 x 6 (3D)");
  }
  if (!information.allFinite()) {
    return fail("information matrix has non-finite entries");
  }
  const int d = size == 3 ? 2 : 3;
  const Eigen::MatrixXd info_tt = information.topLeftCorner(d, d);
  const Eigen::MatrixXd info_RR =
      information.bottomRightCorner(size - d, size - d);
  if (info_tt.llt().info() != Eigen::Success) {
    return fail("translational information block is not positive definite");
  }
  if (info_RR.llt().info() != Eigen::Success) {
    return fail("rotational information block is not positive definite");
  }
  *tau = TraceInversePrecision(info_tt);
  *kappa = d == 2 ? info_RR(0, 0) : 3 / (2 * info_RR.inverse().trace());
  if (!(std::isfinite(*tau) && *tau > 0 && std::isfinite(*kappa) &&
        *kappa > 0)) {
    return fail(
        "information matrix gives non-finite or non-positive precisions");
  }
  return true;
}

bool ReadG2oFile(const std::string& path, const G2oReadOptions& options,
                 PoseGraph* graph, std::string* error,
                 G2oReadSummary* summary) {
  std::string text;
  if (!internal::ReadFileToString(path, &text, error)) return false;
  return ParseG2oText(text, path, options, graph, error, summary);
}

bool ReadG2o(std::istream& in, const std::string& name_for_messages,
             const G2oReadOptions& options, PoseGraph* graph,
             std::string* error, G2oReadSummary* summary) {
  std::ostringstream buffer;
  if (in.peek() != std::istream::traits_type::eof()) buffer << in.rdbuf();
  if (in.bad()) return Fail(error, name_for_messages + ": read error");
  return ParseG2oText(buffer.str(), name_for_messages, options, graph, error,
                      summary);
}

bool WriteG2oFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error) {
  return WriteG2oFile(path, graph, poses, {}, error);
}

bool WriteG2oFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, const LandmarkPositions& landmarks,
                  std::string* error) {
  if (!CheckGraphForWriting(graph, error)) return false;
  if (!poses.empty() && !CheckPoses(graph, poses, error)) return false;
  if (!landmarks.empty() && !CheckLandmarks(graph, landmarks, error)) {
    return false;
  }
  std::string out;
  out.reserve(64 * graph.num_poses + 256 * graph.measurements.size() +
              64 * graph.num_landmarks +
              96 * (graph.landmark_measurements.size() + graph.priors.size()));
  if (graph.dimension == 3 &&
      (!graph.landmark_measurements.empty() || !graph.priors.empty())) {
    out.append("PARAMS_SE3OFFSET");
    AppendInt(kIdentityOffsetId, &out);
    out.append(" 0 0 0 0 0 0 1\n");
  }
  if (!poses.empty()) AppendVertexLines(graph, poses, &out);
  if (!landmarks.empty()) AppendLandmarkVertexLines(graph, landmarks, &out);
  for (const auto& m : graph.measurements) {
    if (graph.dimension == 2) {
      out.append("EDGE_SE2");
      AppendInt(graph.vertex_ids[m.i], &out);
      AppendInt(graph.vertex_ids[m.j], &out);
      for (double v : {m.t(0), m.t(1), AngleOf(m.R), m.tau, 0.0, 0.0, m.tau,
                       0.0, m.kappa}) {
        AppendDouble(v, &out);
      }
    } else {
      out.append("EDGE_SE3:QUAT");
      AppendInt(graph.vertex_ids[m.i], &out);
      AppendInt(graph.vertex_ids[m.j], &out);
      const Eigen::Quaterniond q = QuaternionOf(m.R);
      for (double v : {m.t(0), m.t(1), m.t(2), q.x(), q.y(), q.z(), q.w()}) {
        AppendDouble(v, &out);
      }
      // Upper triangle of diag(tau, tau, tau, 2 kappa, 2 kappa, 2 kappa).
      for (int r = 0; r < 6; ++r) {
        for (int c = r; c < 6; ++c) {
          AppendDouble(r != c ? 0.0 : r < 3 ? m.tau : 2 * m.kappa, &out);
        }
      }
    }
    out.push_back('\n');
  }
  AppendLandmarkAndPriorLines(graph, &out);
  if (graph.fixed_pose >= 0) {
    if (graph.fixed_pose >= graph.num_poses) {
      return Fail(error, "pose graph fixed_pose is out of range");
    }
    out.append("FIX");
    AppendInt(graph.vertex_ids[graph.fixed_pose], &out);
    out.push_back('\n');
  }
  return internal::WriteFileAtomically(path, out, error);
}

bool WriteG2oPoses(const std::string& path, const PoseGraph& graph,
                   const Poses& poses, std::string* error) {
  if (!CheckGraphForWriting(graph, error) || !CheckPoses(graph, poses, error)) {
    return false;
  }
  std::string out;
  out.reserve(96 * graph.num_poses);
  AppendVertexLines(graph, poses, &out);
  return internal::WriteFileAtomically(path, out, error);
}

bool WriteG2oSolution(const std::string& path, const PoseGraph& graph,
                      const Solution& solution, std::string* error) {
  if (!CheckGraphForWriting(graph, error) ||
      !CheckPoses(graph, solution.poses, error) ||
      !CheckLandmarks(graph, solution.landmarks, error)) {
    return false;
  }
  std::string out;
  out.reserve(96 * graph.num_poses + 64 * graph.num_landmarks);
  AppendVertexLines(graph, solution.poses, &out);
  AppendLandmarkVertexLines(graph, solution.landmarks, &out);
  return internal::WriteFileAtomically(path, out, error);
}

namespace {

// Reads the pose VERTEX lines of `path` into `poses` and, if `landmarks` is
// not null, the landmark VERTEX lines into `landmarks` (else they are
// ignored), matched by id to `graph`. Edge, prior, parameter and FIX lines
// are ignored.
bool ReadVertexFile(const std::string& path, const PoseGraph& graph,
                    Poses* poses, LandmarkPositions* landmarks,
                    std::string* error) {
  if (graph.dimension != 2 && graph.dimension != 3) {
    return Fail(error, "pose graph dimension must be 2 or 3");
  }
  std::string text;
  if (!internal::ReadFileToString(path, &text, error)) return false;
  Location at{path, 0, error};
  std::vector<int> line_of_pose(graph.num_poses, 0);
  std::vector<int> line_of_landmark(landmarks ? graph.num_landmarks : 0, 0);
  Poses result(graph.num_poses);
  LandmarkPositions positions(line_of_landmark.size());
  int num_normalized = 0;
  std::vector<std::string_view> tokens;
  auto visit = [&](int number, std::string_view line) {
    at.line = number;
    Tokenize(line, &tokens);
    if (tokens.empty() || tokens[0][0] == '#') return true;
    const Tag tag = Classify(tokens[0]);
    if (IsPoseEdge(tag) || IsLandmarkEdge(tag) || IsPrior(tag) ||
        tag == Tag::kParamsSE3Offset || tag == Tag::kFix ||
        (IsLandmarkVertex(tag) && !landmarks)) {
      return true;  // Only the vertices matter here.
    }
    if (!IsPoseVertex(tag) && !IsLandmarkVertex(tag)) {
      return at.Fail(UnsupportedTagMessage(tokens[0]));
    }
    if (DimensionOf(tag) != graph.dimension) {
      return at.Fail(std::string(tokens[0]) + " in a poses file for a " +
                     std::to_string(graph.dimension) + "D pose graph");
    }
    if (!CheckFieldCount(at, tokens, FieldCount(tag))) return false;
    int64_t id;
    if (IsLandmarkVertex(tag)) {
      Eigen::VectorXd position;
      if (!ParseLandmarkVertex(at, tag, tokens, &id, &position)) return false;
      const int index = graph.FindLandmark(id);
      if (index < 0) {
        return at.Fail("vertex " + std::to_string(id) +
                       " is not a landmark of the pose graph");
      }
      if (line_of_landmark[index] != 0) {
        return at.Fail("duplicate VERTEX id " + std::to_string(id) +
                       " (first defined on line " +
                       std::to_string(line_of_landmark[index]) + ")");
      }
      line_of_landmark[index] = number;
      positions[index] = std::move(position);
      return true;
    }
    Pose pose;
    if (!ParseVertex(at, tag, tokens, &id, &pose, &num_normalized))
      return false;
    const int index = graph.FindVertex(id);
    if (index < 0) {
      return at.Fail("vertex " + std::to_string(id) +
                     " is not in the pose graph");
    }
    if (line_of_pose[index] != 0) {
      return at.Fail("duplicate VERTEX id " + std::to_string(id) +
                     " (first defined on line " +
                     std::to_string(line_of_pose[index]) + ")");
    }
    line_of_pose[index] = number;
    result[index] = std::move(pose);
    return true;
  };
  int num_lines = 0;
  if (!ForEachLine(text, &num_lines, visit)) return false;
  at.line = std::max(num_lines, 1);
  const int missing =
      static_cast<int>(std::count(line_of_pose.begin(), line_of_pose.end(), 0));
  if (missing > 0) {
    const int first = static_cast<int>(
        std::find(line_of_pose.begin(), line_of_pose.end(), 0) -
        line_of_pose.begin());
    return at.Fail("end of file: no VERTEX line for vertex " +
                   std::to_string(graph.vertex_ids[first]) + " (" +
                   std::to_string(missing) + " of " +
                   std::to_string(graph.num_poses) + " poses missing)");
  }
  const int missing_landmarks = static_cast<int>(
      std::count(line_of_landmark.begin(), line_of_landmark.end(), 0));
  if (missing_landmarks > 0) {
    const int first = static_cast<int>(
        std::find(line_of_landmark.begin(), line_of_landmark.end(), 0) -
        line_of_landmark.begin());
    return at.Fail("end of file: no VERTEX line for landmark " +
                   std::to_string(graph.landmark_ids[first]) + " (" +
                   std::to_string(missing_landmarks) + " of " +
                   std::to_string(graph.num_landmarks) + " landmarks missing)");
  }
  *poses = std::move(result);
  if (landmarks) *landmarks = std::move(positions);
  return true;
}

}  // namespace

bool ReadG2oPoses(const std::string& path, const PoseGraph& graph, Poses* poses,
                  std::string* error) {
  return ReadVertexFile(path, graph, poses, nullptr, error);
}

bool ReadG2oSolution(const std::string& path, const PoseGraph& graph,
                     Solution* solution, std::string* error) {
  Solution result;
  if (!ReadVertexFile(path, graph, &result.poses, &result.landmarks, error)) {
    return false;
  }
  *solution = std::move(result);
  return true;
}

bool WriteTumFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error) {
  if (!CheckGraphForWriting(graph, error) || !CheckPoses(graph, poses, error)) {
    return false;
  }
  std::string out;
  out.reserve(128 * graph.num_poses);
  for (int k = 0; k < graph.num_poses; ++k) {
    const Pose& p = poses[k];
    out.append(std::to_string(graph.vertex_ids[k]));
    Eigen::Quaterniond q;
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    if (graph.dimension == 2) {
      const double theta = AngleOf(p.R);
      q = Eigen::Quaterniond(std::cos(theta / 2), 0, 0, std::sin(theta / 2));
      t.head<2>() = p.t;
    } else {
      q = QuaternionOf(p.R);
      t = p.t;
    }
    for (double v : {t(0), t(1), t(2), q.x(), q.y(), q.z(), q.w()}) {
      AppendDouble(v, &out);
    }
    out.push_back('\n');
  }
  return internal::WriteFileAtomically(path, out, error);
}

}  // namespace ceres_sesync
