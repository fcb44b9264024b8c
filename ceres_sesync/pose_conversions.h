// Conversions between ceres_sesync::Pose / PoseGraph and the pose types that
// Ceres users already have, so that existing code can be certified or
// warm-started without glue code.
//
//  1. Single poses and vectors of poses <-> Eigen::Isometry2d/3d,
//     (Eigen::Quaterniond, Eigen::Vector3d), (x, y, yaw) and plain arrays.
//
//  2. Adapters for the data layout of Ceres's own examples/slam programs.
//     They are templates that accept ANY type with the right members
//     ("duck typing"), so the user's own structs work unchanged:
//
//       2D (pose_graph_2d style):
//         struct Pose2d { double x, y, yaw_radians; };
//         std::map<int, Pose2d> poses;
//         struct Constraint2d {
//           int id_begin, id_end;
//           double x, y, yaw_radians;     // Pose of `end` in frame `begin`.
//           Eigen::Matrix3d information;  // Order x, y, yaw.
//         };
//
//       3D (pose_graph_3d style):
//         struct Pose3d { Eigen::Vector3d p; Eigen::Quaterniond q; };
//         std::map<int, Pose3d, std::less<int>,
//                  Eigen::aligned_allocator<std::pair<const int, Pose3d>>>
//             poses;
//         struct Constraint3d {
//           int id_begin, id_end;
//           Pose3d t_be;                             // Pose of `end` in
//                                                    // frame `begin`.
//           Eigen::Matrix<double, 6, 6> information;  // Order p, then
//                                                     // rotation.
//         };
//
//     Typical use (certify the result of an existing ceres::Solve):
//
//       ceres_sesync::PoseGraph graph;
//       std::string error;
//       if (!ceres_sesync::PoseGraphFromCeres3d(poses, constraints, &graph,
//                                               &error)) { ... }
//       ceres_sesync::Poses candidate;
//       ceres_sesync::PosesFromCeres3dMap(graph, poses, &candidate, &error);
//       ceres_sesync::Certificate certificate;
//       ceres_sesync::Certify(graph, candidate, {}, &certificate, &error);
//
// Information matrices become the isotropic precisions (kappa, tau) of the
// SE-Sync model with exactly the convention of the g2o reader (g2o_io.h):
//
//   2D: tau = 2 / trace(inverse(I_tt)),   kappa = I_33;
//   3D: tau = 3 / trace(inverse(I_tt)),   kappa = 3 / (2 trace(inverse(I_RR))),
//
// where I_tt is the translational and I_RR the rotational diagonal block (only
// the upper triangle of the information matrix is read, as in a g2o line). An
// isotropic information diag(tau I, kappa) (2D) or diag(tau I, 2 kappa I) (3D)
// therefore maps to exactly (kappa, tau), and PoseGraphToCeres2dConstraints /
// PoseGraphToCeres3dConstraints write those matrices.
//
// Important: SE-Sync certifies the chordal maximum-likelihood objective of
// Rosen et al. (IJRR 2019, eq. 12). A Ceres problem whose residual is a
// different function of the same data (for example the quaternion or angle
// error of Ceres's examples) has a slightly different optimum; its solution
// can still be certified against eq. (12), with a correspondingly small
// suboptimality. See examples/certify_ceres_pose_graph.cc.
//
// Rotations that leave this library (to Isometry, quaternion, yaw, maps) are
// first projected to the nearest element of SO(d), which is a no-op (to
// rounding) for valid rotations. Functions returning bool never crash on bad
// input: they return false with a message in `error` (if not null).

#ifndef CERES_SESYNC_POSE_CONVERSIONS_H_
#define CERES_SESYNC_POSE_CONVERSIONS_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "Eigen/Geometry"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

// ---------------------------------------------------------------------------
// Single poses.
// ---------------------------------------------------------------------------

// A 2D / 3D pose from an Eigen isometry (its linear part is taken as the
// rotation, as is).
Pose PoseFromIsometry(const Eigen::Isometry2d& transform);
Pose PoseFromIsometry(const Eigen::Isometry3d& transform);

// A 3D pose from a quaternion (normalized here; a zero or non-finite
// quaternion gives a non-finite rotation, which Certify and
// ValidatePoseGraph reject) and a translation.
Pose PoseFromQuaternionTranslation(const Eigen::Quaterniond& q,
                                   const Eigen::Vector3d& t);

// A 2D pose from a position and a heading (radians, counter-clockwise).
Pose PoseFromXYYaw(double x, double y, double yaw_radians);

// The pose as an isometry. Returns false if the pose is not of the isometry's
// dimension or has non-finite entries.
bool PoseToIsometry(const Pose& pose, Eigen::Isometry2d* transform,
                    std::string* error = nullptr);
bool PoseToIsometry(const Pose& pose, Eigen::Isometry3d* transform,
                    std::string* error = nullptr);

// A 3D pose as a unit quaternion (w >= 0) and a translation. Returns false
// for a pose that is not 3D or has non-finite entries.
bool PoseToQuaternionTranslation(const Pose& pose, Eigen::Quaterniond* q,
                                 Eigen::Vector3d* t,
                                 std::string* error = nullptr);

// A 2D pose as a position and a heading in (-pi, pi]. Returns false for a
// pose that is not 2D or has non-finite entries.
bool PoseToXYYaw(const Pose& pose, double* x, double* y, double* yaw_radians,
                 std::string* error = nullptr);

// ---------------------------------------------------------------------------
// Vectors of poses.
// ---------------------------------------------------------------------------

// One pose per isometry (Eigen::Isometry2d or Eigen::Isometry3d; any
// allocator, e.g. Eigen::aligned_allocator).
template <typename Isometry, typename Allocator>
Poses PosesFromIsometries(const std::vector<Isometry, Allocator>& transforms);

// One isometry per pose; `transforms` is overwritten. Returns false (naming
// the first bad pose) if a pose has the wrong dimension or non-finite
// entries.
template <typename Isometry, typename Allocator>
bool PosesToIsometries(const Poses& poses,
                       std::vector<Isometry, Allocator>* transforms,
                       std::string* error = nullptr);

// Poses from plain arrays: `rotations` holds num_poses column-major d x d
// matrices back to back (d * d * num_poses doubles) and `translations`
// num_poses vectors of d doubles. Rotations are taken as given (Certify
// projects them). Returns false for d not in {2, 3}, num_poses < 0, null
// arrays (with num_poses > 0) or non-finite values.
bool PosesFromArrays(int dimension, int num_poses, const double* rotations,
                     const double* translations, Poses* poses,
                     std::string* error = nullptr);

// The inverse of PosesFromArrays: fills d * d * n and d * n doubles (the
// caller provides the storage). Rotations are copied as they are. Returns
// false if the poses do not all have dimension `dimension` or an array is
// null.
bool PosesToArrays(int dimension, const Poses& poses, double* rotations,
                   double* translations, std::string* error = nullptr);

// ---------------------------------------------------------------------------
// Ceres examples/slam adapters (duck-typed templates; see the top).
// ---------------------------------------------------------------------------

// Poses of `graph` (one per dense index, matched by graph.vertex_ids) from a
// map keyed by vertex id whose values have members x, y, yaw_radians (2D) or
// an Eigen::Vector3d p and an Eigen::Quaterniond q (3D; normalized here).
// Entries of the map that are not vertices of the graph are ignored. Returns
// false, naming the first vertex id that is missing from the map or whose
// pose is not finite, or if the graph is not of the adapter's dimension.
template <typename Map>
bool PosesFromCeres2dMap(const PoseGraph& graph, const Map& poses, Poses* out,
                         std::string* error = nullptr);
template <typename Map>
bool PosesFromCeres3dMap(const PoseGraph& graph, const Map& poses, Poses* out,
                         std::string* error = nullptr);

// Writes `poses` (one per dense index of `graph`) into `map`, keyed by
// graph.vertex_ids: existing entries get their pose members overwritten
// (other members are kept), missing ones are inserted with operator[].
// Returns false (map untouched) if the graph is not of the adapter's
// dimension, a vertex id does not fit the map's key type, or `poses` does not
// hold one finite pose of that dimension per vertex.
template <typename Map>
bool PosesToCeres2dMap(const PoseGraph& graph, const Poses& poses, Map* map,
                       std::string* error = nullptr);
template <typename Map>
bool PosesToCeres3dMap(const PoseGraph& graph, const Poses& poses, Map* map,
                       std::string* error = nullptr);

// A pose graph from a range of Ceres-example constraints (see the top),
// converting each information matrix to (kappa, tau) as the g2o reader does.
// Poses are numbered in order of first appearance of their ids (id_begin,
// then id_end, constraint by constraint); the graph has no initial poses and
// no fixed pose. Returns false (naming the constraint) for a self-loop, an
// information matrix whose translational or rotational block is not
// symmetric positive definite (upper triangle read), a quaternion further
// than 1e-2 from unit length, non-finite values, an empty range, or a
// disconnected graph (ValidatePoseGraph).
template <typename Constraints>
bool PoseGraphFromCeres2dConstraints(const Constraints& constraints,
                                     PoseGraph* graph,
                                     std::string* error = nullptr);
template <typename Constraints>
bool PoseGraphFromCeres3dConstraints(const Constraints& constraints,
                                     PoseGraph* graph,
                                     std::string* error = nullptr);

// As above, but the poses come from the user's map: the dense order is the
// map's iteration order (ascending ids for a std::map), graph.initial_poses
// holds the map's poses, and a constraint that refers to an id not in the map
// is an error. With initial poses present, SE-Sync expresses its solution in
// the frame of the first pose at its initial value: the pose that Ceres's
// examples hold constant (the map's first entry).
template <typename Map, typename Constraints>
bool PoseGraphFromCeres2d(const Map& poses, const Constraints& constraints,
                          PoseGraph* graph, std::string* error = nullptr);
template <typename Map, typename Constraints>
bool PoseGraphFromCeres3d(const Map& poses, const Constraints& constraints,
                          PoseGraph* graph, std::string* error = nullptr);

// The reverse: one Ceres-example constraint per measurement of `graph`
// (appended to `constraints`, e.g. a std::vector<Constraint2d>), with ids
// from graph.vertex_ids and the isotropic information matrix that reproduces
// (kappa, tau) under the convention above: 2D diag(tau, tau, kappa), 3D
// diag(tau, tau, tau, 2 kappa, 2 kappa, 2 kappa). Returns false (nothing
// appended) if the graph is not of the adapter's dimension or fails
// ValidatePoseGraph.
template <typename Constraints>
bool PoseGraphToCeres2dConstraints(const PoseGraph& graph,
                                   Constraints* constraints,
                                   std::string* error = nullptr);
template <typename Constraints>
bool PoseGraphToCeres3dConstraints(const PoseGraph& graph,
                                   Constraints* constraints,
                                   std::string* error = nullptr);

// ---------------------------------------------------------------------------
// Implementation details of the templates above.
// ---------------------------------------------------------------------------
namespace internal {

// Sets *error (if not null) and returns false.
bool ConversionFail(const std::string& message, std::string* error);

// Checks that `pose` is a finite pose of dimension d. `what` names it in the
// message.
bool CheckPoseForConversion(const Pose& pose, int d, const std::string& what,
                            std::string* error);

// Checks that `output` is not null (message "ADAPTER: null OUTPUT_NAME"),
// graph.dimension == d and the vertex id table; `adapter` names the caller in
// the messages.
bool CheckAdapterCall(const void* output, const char* output_name,
                      const PoseGraph& graph, int d, const char* adapter,
                      std::string* error);

// Builds the measurement of one Ceres-example constraint (number `index` in
// the range, ids for messages).
bool MeasurementFromCeres2d(int index, int64_t id_begin, int64_t id_end,
                            double x, double y, double yaw_radians,
                            const Eigen::Matrix3d& information,
                            RelativePoseMeasurement* m, std::string* error);
bool MeasurementFromCeres3d(int index, int64_t id_begin, int64_t id_end,
                            const Eigen::Vector3d& p,
                            const Eigen::Quaterniond& q,
                            const Eigen::Matrix<double, 6, 6>& information,
                            RelativePoseMeasurement* m, std::string* error);

// Resolves the two ids of measurement `index` to dense indices (adding
// vertices if `add_vertices`, else failing for unknown ids) and appends it.
bool AddCeresMeasurement(int index, int64_t id_begin, int64_t id_end,
                         bool add_vertices, RelativePoseMeasurement m,
                         PoseGraph* graph, std::string* error);

// Validates the assembled graph and moves it into `out`.
bool FinishCeresPoseGraph(int num_constraints, PoseGraph* assembled,
                          PoseGraph* out, std::string* error);

// Converts a map key to int64 and back, failing if it does not fit.
template <typename Key>
bool VertexIdToKey(int64_t id, Key* key) {
  *key = static_cast<Key>(id);
  return static_cast<int64_t>(*key) == id;
}

// What differs between the data layouts of Ceres's pose_graph_2d and
// pose_graph_3d examples (see the top): the pose members of a map value and
// of a constraint, and the isotropic information matrix. Each adapter below
// is written once, for a Layout.
struct Ceres2dLayout {
  static constexpr int kDimension = 2;

  template <typename Value>
  static Pose ToPose(const Value& value) {
    return PoseFromXYYaw(value.x, value.y, value.yaw_radians);
  }
  template <typename Value>
  static void FromPose(const Pose& pose, Value* value) {
    PoseToXYYaw(pose, &value->x, &value->y, &value->yaw_radians);
  }
  template <typename Constraint>
  static bool ToMeasurement(int index, int64_t id_begin, int64_t id_end,
                            const Constraint& c, RelativePoseMeasurement* m,
                            std::string* error) {
    return MeasurementFromCeres2d(index, id_begin, id_end, c.x, c.y,
                                  c.yaw_radians, c.information, m, error);
  }
  template <typename Constraint>
  static void FromMeasurement(const RelativePoseMeasurement& m, Constraint* c) {
    c->x = m.t(0);
    c->y = m.t(1);
    c->yaw_radians = std::atan2(m.R(1, 0), m.R(0, 0));
    c->information =
        Eigen::Vector3d(m.tau, m.tau, m.kappa).asDiagonal().toDenseMatrix();
  }
};

struct Ceres3dLayout {
  static constexpr int kDimension = 3;

  template <typename Value>
  static Pose ToPose(const Value& value) {
    return PoseFromQuaternionTranslation(value.q, value.p);
  }
  template <typename Value>
  static void FromPose(const Pose& pose, Value* value) {
    Eigen::Quaterniond q;
    Eigen::Vector3d t;
    PoseToQuaternionTranslation(pose, &q, &t);
    value->p = t;
    value->q = q;
  }
  template <typename Constraint>
  static bool ToMeasurement(int index, int64_t id_begin, int64_t id_end,
                            const Constraint& c, RelativePoseMeasurement* m,
                            std::string* error) {
    return MeasurementFromCeres3d(index, id_begin, id_end, c.t_be.p, c.t_be.q,
                                  c.information, m, error);
  }
  template <typename Constraint>
  static void FromMeasurement(const RelativePoseMeasurement& m, Constraint* c) {
    FromPose(Pose{m.R, m.t}, &c->t_be);
    Eigen::Matrix<double, 6, 1> diagonal;
    diagonal << m.tau, m.tau, m.tau, 2 * m.kappa, 2 * m.kappa, 2 * m.kappa;
    c->information = diagonal.asDiagonal().toDenseMatrix();
  }
};

// PosesFromCeres2dMap / PosesFromCeres3dMap; `adapter` names the caller in
// messages.
template <typename Layout, typename Map>
bool PosesFromCeresMap(const PoseGraph& graph, const Map& poses,
                       const char* adapter, Poses* out, std::string* error) {
  constexpr int d = Layout::kDimension;
  if (!CheckAdapterCall(out, "output", graph, d, adapter, error)) return false;
  Poses result(graph.num_poses);
  for (int i = 0; i < graph.num_poses; ++i) {
    const int64_t id = graph.vertex_ids[i];
    typename Map::key_type key;
    auto it = VertexIdToKey(id, &key) ? poses.find(key) : poses.end();
    if (it == poses.end()) {
      return ConversionFail(std::string(adapter) + ": vertex id " +
                                std::to_string(id) +
                                " of the pose graph is not in the map",
                            error);
    }
    result[i] = Layout::ToPose(it->second);
    if (!CheckPoseForConversion(
            result[i], d, "pose of vertex id " + std::to_string(id), error)) {
      return false;
    }
  }
  *out = std::move(result);
  return true;
}

// PosesToCeres2dMap / PosesToCeres3dMap.
template <typename Layout, typename Map>
bool PosesToCeresMap(const PoseGraph& graph, const Poses& poses,
                     const char* adapter, Map* map, std::string* error) {
  constexpr int d = Layout::kDimension;
  if (!CheckAdapterCall(map, "map", graph, d, adapter, error)) return false;
  if (static_cast<int>(poses.size()) != graph.num_poses) {
    return ConversionFail(std::string(adapter) + ": " +
                              std::to_string(poses.size()) +
                              " poses for a graph of " +
                              std::to_string(graph.num_poses) + " vertices",
                          error);
  }
  std::vector<typename Map::key_type> keys(graph.num_poses);
  for (int i = 0; i < graph.num_poses; ++i) {
    const int64_t id = graph.vertex_ids[i];
    if (!VertexIdToKey(id, &keys[i])) {
      return ConversionFail(std::string(adapter) + ": vertex id " +
                                std::to_string(id) +
                                " does not fit the map's key type",
                            error);
    }
    if (!CheckPoseForConversion(
            poses[i], d, "pose of vertex id " + std::to_string(id), error)) {
      return false;
    }
  }
  for (int i = 0; i < graph.num_poses; ++i) {
    Layout::FromPose(poses[i], &(*map)[keys[i]]);
  }
  return true;
}

// Appends one measurement per constraint to `assembled` (adding their
// vertices if `add_vertices`, else requiring them to be there), then
// validates it and moves it into `out`.
template <typename Layout, typename Constraints>
bool FinishFromCeresConstraints(const Constraints& constraints,
                                bool add_vertices, PoseGraph* assembled,
                                PoseGraph* out, std::string* error) {
  int index = 0;
  for (const auto& c : constraints) {
    const int64_t id_begin = static_cast<int64_t>(c.id_begin);
    const int64_t id_end = static_cast<int64_t>(c.id_end);
    RelativePoseMeasurement m;
    if (!Layout::ToMeasurement(index, id_begin, id_end, c, &m, error) ||
        !AddCeresMeasurement(index, id_begin, id_end, add_vertices,
                             std::move(m), assembled, error)) {
      return false;
    }
    ++index;
  }
  return FinishCeresPoseGraph(index, assembled, out, error);
}

// PoseGraphFromCeres2dConstraints / PoseGraphFromCeres3dConstraints.
template <typename Layout, typename Constraints>
bool PoseGraphFromCeresConstraints(const Constraints& constraints,
                                   PoseGraph* graph, std::string* error) {
  PoseGraph assembled;
  assembled.dimension = Layout::kDimension;
  return FinishFromCeresConstraints<Layout>(constraints, /*add_vertices=*/true,
                                            &assembled, graph, error);
}

// PoseGraphFromCeres2d / PoseGraphFromCeres3d.
template <typename Layout, typename Map, typename Constraints>
bool PoseGraphFromCeresMap(const Map& poses, const Constraints& constraints,
                           const char* adapter, PoseGraph* graph,
                           std::string* error) {
  PoseGraph assembled;
  assembled.dimension = Layout::kDimension;
  for (const auto& [id, value] : poses) {
    const int64_t vertex_id = static_cast<int64_t>(id);
    assembled.AddVertex(vertex_id);
    assembled.initial_poses.push_back(Layout::ToPose(value));
    if (!CheckPoseForConversion(assembled.initial_poses.back(),
                                Layout::kDimension,
                                std::string(adapter) + ": pose of vertex id " +
                                    std::to_string(vertex_id),
                                error)) {
      return false;
    }
  }
  if (static_cast<int>(assembled.initial_poses.size()) != assembled.num_poses) {
    return ConversionFail(
        std::string(adapter) + ": duplicate vertex ids in the map", error);
  }
  return FinishFromCeresConstraints<Layout>(constraints, /*add_vertices=*/false,
                                            &assembled, graph, error);
}

// PoseGraphToCeres2dConstraints / PoseGraphToCeres3dConstraints.
template <typename Layout, typename Constraints>
bool PoseGraphToCeresConstraints(const PoseGraph& graph,
                                 Constraints* constraints, const char* adapter,
                                 std::string* error) {
  if (!CheckAdapterCall(constraints, "output", graph, Layout::kDimension,
                        adapter, error)) {
    return false;
  }
  std::string message;
  if (!ValidatePoseGraph(graph, &message)) {
    return ConversionFail(std::string(adapter) + ": " + message, error);
  }
  using Id = decltype(typename Constraints::value_type().id_begin);
  for (int64_t id : graph.vertex_ids) {
    Id key;
    if (!VertexIdToKey(id, &key)) {
      return ConversionFail(std::string(adapter) + ": vertex id " +
                                std::to_string(id) +
                                " does not fit the id type",
                            error);
    }
  }
  for (const RelativePoseMeasurement& m : graph.measurements) {
    typename Constraints::value_type c;
    c.id_begin = static_cast<Id>(graph.vertex_ids[m.i]);
    c.id_end = static_cast<Id>(graph.vertex_ids[m.j]);
    Layout::FromMeasurement(m, &c);
    constraints->push_back(c);
  }
  return true;
}

}  // namespace internal

// ---------------------------------------------------------------------------
// Template definitions.
// ---------------------------------------------------------------------------

template <typename Isometry, typename Allocator>
Poses PosesFromIsometries(const std::vector<Isometry, Allocator>& transforms) {
  Poses poses;
  poses.reserve(transforms.size());
  for (const Isometry& transform : transforms) {
    poses.push_back(PoseFromIsometry(transform));
  }
  return poses;
}

template <typename Isometry, typename Allocator>
bool PosesToIsometries(const Poses& poses,
                       std::vector<Isometry, Allocator>* transforms,
                       std::string* error) {
  if (transforms == nullptr) {
    return internal::ConversionFail("PosesToIsometries: null output", error);
  }
  std::vector<Isometry, Allocator> result(poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    std::string message;
    if (!PoseToIsometry(poses[i], &result[i], &message)) {
      return internal::ConversionFail(
          "PosesToIsometries: pose " + std::to_string(i) + ": " + message,
          error);
    }
  }
  *transforms = std::move(result);
  return true;
}

template <typename Map>
bool PosesFromCeres2dMap(const PoseGraph& graph, const Map& poses, Poses* out,
                         std::string* error) {
  return internal::PosesFromCeresMap<internal::Ceres2dLayout>(
      graph, poses, "PosesFromCeres2dMap", out, error);
}

template <typename Map>
bool PosesFromCeres3dMap(const PoseGraph& graph, const Map& poses, Poses* out,
                         std::string* error) {
  return internal::PosesFromCeresMap<internal::Ceres3dLayout>(
      graph, poses, "PosesFromCeres3dMap", out, error);
}

template <typename Map>
bool PosesToCeres2dMap(const PoseGraph& graph, const Poses& poses, Map* map,
                       std::string* error) {
  return internal::PosesToCeresMap<internal::Ceres2dLayout>(
      graph, poses, "PosesToCeres2dMap", map, error);
}

template <typename Map>
bool PosesToCeres3dMap(const PoseGraph& graph, const Poses& poses, Map* map,
                       std::string* error) {
  return internal::PosesToCeresMap<internal::Ceres3dLayout>(
      graph, poses, "PosesToCeres3dMap", map, error);
}

template <typename Constraints>
bool PoseGraphFromCeres2dConstraints(const Constraints& constraints,
                                     PoseGraph* graph, std::string* error) {
  return internal::PoseGraphFromCeresConstraints<internal::Ceres2dLayout>(
      constraints, graph, error);
}

template <typename Constraints>
bool PoseGraphFromCeres3dConstraints(const Constraints& constraints,
                                     PoseGraph* graph, std::string* error) {
  return internal::PoseGraphFromCeresConstraints<internal::Ceres3dLayout>(
      constraints, graph, error);
}

template <typename Map, typename Constraints>
bool PoseGraphFromCeres2d(const Map& poses, const Constraints& constraints,
                          PoseGraph* graph, std::string* error) {
  return internal::PoseGraphFromCeresMap<internal::Ceres2dLayout>(
      poses, constraints, "PoseGraphFromCeres2d", graph, error);
}

template <typename Map, typename Constraints>
bool PoseGraphFromCeres3d(const Map& poses, const Constraints& constraints,
                          PoseGraph* graph, std::string* error) {
  return internal::PoseGraphFromCeresMap<internal::Ceres3dLayout>(
      poses, constraints, "PoseGraphFromCeres3d", graph, error);
}

template <typename Constraints>
bool PoseGraphToCeres2dConstraints(const PoseGraph& graph,
                                   Constraints* constraints,
                                   std::string* error) {
  return internal::PoseGraphToCeresConstraints<internal::Ceres2dLayout>(
      graph, constraints, "PoseGraphToCeres2dConstraints", error);
}

template <typename Constraints>
bool PoseGraphToCeres3dConstraints(const PoseGraph& graph,
                                   Constraints* constraints,
                                   std::string* error) {
  return internal::PoseGraphToCeresConstraints<internal::Ceres3dLayout>(
      graph, constraints, "PoseGraphToCeres3dConstraints", error);
}

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_POSE_CONVERSIONS_H_
