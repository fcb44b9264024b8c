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

enum class Tag {
  kVertexSE2,    // VERTEX_SE2, VERTEX2
  kVertexSE3,    // VERTEX_SE3:QUAT
  kEdgeSE2,      // EDGE_SE2
  kEdge2,        // EDGE2 (TORO information order)
  kEdgeSE3,      // EDGE_SE3:QUAT
  kFix,          // FIX
  kLegacy3D,     // VERTEX3, EDGE3
  kUnsupported,  // anything else
};

Tag Classify(std::string_view tag) {
  if (tag == "VERTEX_SE2" || tag == "VERTEX2") return Tag::kVertexSE2;
  if (tag == "VERTEX_SE3:QUAT") return Tag::kVertexSE3;
  if (tag == "EDGE_SE2") return Tag::kEdgeSE2;
  if (tag == "EDGE2") return Tag::kEdge2;
  if (tag == "EDGE_SE3:QUAT") return Tag::kEdgeSE3;
  if (tag == "FIX") return Tag::kFix;
  if (tag == "VERTEX3" || tag == "EDGE3") return Tag::kLegacy3D;
  return Tag::kUnsupported;
}

int DimensionOf(Tag tag) {
  switch (tag) {
    case Tag::kVertexSE2:
    case Tag::kEdgeSE2:
    case Tag::kEdge2:
      return 2;
    case Tag::kVertexSE3:
    case Tag::kEdgeSE3:
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
    case Tag::kFix:
      return 1;
    default:
      return 0;
  }
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

std::string UnsupportedTagMessage(std::string_view tag) {
  if (Classify(tag) == Tag::kLegacy3D) {
    return "unsupported legacy tag '" + std::string(tag) +
           "' (TORO 3D files are not supported; convert to VERTEX_SE3:QUAT / "
           "EDGE_SE3:QUAT)";
  }
  return "unsupported tag '" + std::string(tag) +
         "' (only SE(2)/SE(3) pose vertices and edges are supported; "
         "landmarks and priors can be skipped with --skip_unsupported_tags)";
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
  std::vector<int> first_line;  // Per dense index: line of first appearance.
  struct EdgeIds {
    int64_t i, j;
    int line;
  };
  std::vector<EdgeIds> edge_ids;
  int64_t fix_id = -1;
  int fix_line = 0;

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
        const int before = graph->num_poses;
        const int index = graph->AddVertex(id);
        if (graph->num_poses == before) {
          return at.Fail("duplicate VERTEX id " + std::to_string(id) +
                         " (first defined on line " +
                         std::to_string(first_line[index]) + ")");
        }
        first_line.push_back(number);
        graph->initial_poses.push_back(std::move(pose));
        return true;
      }
      case Tag::kEdgeSE2:
      case Tag::kEdge2:
      case Tag::kEdgeSE3: {
        EdgeIds ids{0, 0, number};
        RelativePoseMeasurement m;
        if (!ParseEdge(at, tag, tokens, &ids.i, &ids.j, &m, &counts)) {
          return false;
        }
        edge_ids.push_back(ids);
        graph->measurements.push_back(std::move(m));
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
  if (graph->measurements.empty()) {
    return at.Fail(
        "end of file: no EDGE lines (a pose graph needs at least "
        "one measurement)");
  }

  // Resolve the vertex ids of the edges to dense indices.
  const bool has_vertex_lines = graph->num_poses > 0;
  for (size_t k = 0; k < edge_ids.size(); ++k) {
    const EdgeIds& ids = edge_ids[k];
    RelativePoseMeasurement& m = graph->measurements[k];
    if (has_vertex_lines) {
      m.i = graph->FindVertex(ids.i);
      m.j = graph->FindVertex(ids.j);
      if (m.i < 0 || m.j < 0) {
        at.line = ids.line;
        return at.Fail("edge refers to vertex " +
                       std::to_string(m.i < 0 ? ids.i : ids.j) +
                       ", which has no VERTEX line (the file has VERTEX lines "
                       "for other vertices)");
      }
    } else {
      for (int64_t id : {ids.i, ids.j}) {
        if (graph->FindVertex(id) < 0) first_line.push_back(ids.line);
        graph->AddVertex(id);
      }
      m.i = graph->FindVertex(ids.i);
      m.j = graph->FindVertex(ids.j);
    }
  }

  if (fix_line != 0) {
    graph->fixed_pose = graph->FindVertex(fix_id);
    if (graph->fixed_pose < 0) {
      at.line = fix_line;
      return at.Fail("FIX refers to vertex " + std::to_string(fix_id) +
                     ", which is not in the graph");
    }
  }

  std::vector<int> component;
  const int num_components = ConnectedComponents(*graph, &component);
  if (num_components > 1 && !options.allow_disconnected) {
    std::vector<int> sizes(num_components, 0);
    for (int c : component) ++sizes[c];
    // The first pose outside the component of pose 0.
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
    s << "; vertex " << graph->vertex_ids[stray]
      << " (first seen here) is not connected to vertex "
      << graph->vertex_ids[0];
    at.line = first_line[stray];
    return at.Fail(s.str());
  }

  std::string invalid;
  if (!ValidatePoseGraph(*graph, &invalid, !options.allow_disconnected)) {
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

}  // namespace

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
  if (d == 2) {
    // tr([[I11, I12], [I12, I22]]^-1) = (I11 + I22) / det.
    const double det =
        info_tt(0, 0) * info_tt(1, 1) - info_tt(0, 1) * info_tt(0, 1);
    *tau = 2 * det / (info_tt(0, 0) + info_tt(1, 1));
    *kappa = info_RR(0, 0);
  } else {
    *tau = 3 / info_tt.inverse().trace();
    *kappa = 3 / (2 * info_RR.inverse().trace());
  }
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
  if (!CheckGraphForWriting(graph, error)) return false;
  if (!poses.empty() && !CheckPoses(graph, poses, error)) return false;
  std::string out;
  out.reserve(64 * graph.num_poses + 256 * graph.measurements.size());
  if (!poses.empty()) AppendVertexLines(graph, poses, &out);
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

bool ReadG2oPoses(const std::string& path, const PoseGraph& graph, Poses* poses,
                  std::string* error) {
  if (graph.dimension != 2 && graph.dimension != 3) {
    return Fail(error, "pose graph dimension must be 2 or 3");
  }
  std::string text;
  if (!internal::ReadFileToString(path, &text, error)) return false;
  Location at{path, 0, error};
  std::vector<int> line_of_pose(graph.num_poses, 0);
  Poses result(graph.num_poses);
  int num_normalized = 0;
  std::vector<std::string_view> tokens;
  auto visit = [&](int number, std::string_view line) {
    at.line = number;
    Tokenize(line, &tokens);
    if (tokens.empty() || tokens[0][0] == '#') return true;
    const Tag tag = Classify(tokens[0]);
    if (tag == Tag::kEdgeSE2 || tag == Tag::kEdge2 || tag == Tag::kEdgeSE3 ||
        tag == Tag::kFix) {
      return true;  // Only the vertices matter here.
    }
    if (tag != Tag::kVertexSE2 && tag != Tag::kVertexSE3) {
      return at.Fail(UnsupportedTagMessage(tokens[0]));
    }
    if (DimensionOf(tag) != graph.dimension) {
      return at.Fail(std::string(tokens[0]) + " in a poses file for a " +
                     std::to_string(graph.dimension) + "D pose graph");
    }
    if (!CheckFieldCount(at, tokens, FieldCount(tag))) return false;
    int64_t id;
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
  const int missing =
      static_cast<int>(std::count(line_of_pose.begin(), line_of_pose.end(), 0));
  if (missing > 0) {
    const int first = static_cast<int>(
        std::find(line_of_pose.begin(), line_of_pose.end(), 0) -
        line_of_pose.begin());
    at.line = std::max(num_lines, 1);
    return at.Fail("end of file: no VERTEX line for vertex " +
                   std::to_string(graph.vertex_ids[first]) + " (" +
                   std::to_string(missing) + " of " +
                   std::to_string(graph.num_poses) + " poses missing)");
  }
  *poses = std::move(result);
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
