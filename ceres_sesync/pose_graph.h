// Pose-graph data model shared by every part of ceres_sesync.
//
// A pose graph has n poses x_i = (R_i, t_i) in SE(d), d = 2 or 3, and m
// relative measurements on directed edges (i, j). It may also have L point
// landmarks p_l in R^d observed from the poses, and priors that tie poses to
// a fixed world frame w = (I, 0). The maximum-likelihood objective (Rosen et
// al., IJRR 2019, eq. 12, extended by the landmark and prior terms) is
//
//   F(x, p) = sum_(i,j) kappa_ij ||R_j - R_i R~_ij||_F^2           (edges)
//                     + tau_ij   ||t_j - t_i - R_i t~_ij||_2^2
//           + sum_(i,l) nu_il    ||p_l - t_i - R_i z_il||_2^2 (landmarks)
//           + sum_k     kappa_k  ||R_i(k) - R~_k||_F^2               (priors)
//                     + tau_k    ||t_i(k) - g_k||_2^2,
//
// and every objective value this library reports is on that scale. Each
// term is the translational or rotational part of a relative measurement:
//  - a landmark measurement is the translation term of an edge from pose i
//    to a "pose" p_l that has no rotation: z_il ~ R_i^T (p_l - t_i);
//  - a prior k on pose i(k) is an edge from the world pose w = (I, 0):
//    R~_k ~ R_i, g_k ~ t_i. A position prior has kappa_k = 0, a rotation
//    prior tau_k = 0, a full pose prior both positive.
// So the translational unknowns are [t_1 .. t_n, p_1 .. p_L] (the landmarks
// join the translations), the rotational ones [R_1 .. R_n], and the priors
// are terms against the constant world pose. Without priors F is invariant
// under a global rigid motion (the gauge; see PoseGraph::fixed_pose); priors
// fix it (partly: e.g. position priors at a single point leave the rotation
// about that point free), and solutions are then in the world frame.
//
// Weights follow one convention: translation-type precisions (tau, nu, and
// the position part of a prior) are d / tr(I^-1) for a d x d translational
// information matrix I, rotation-type ones (kappa) as for edges (see
// g2o_io.h).

#ifndef CERES_SESYNC_POSE_GRAPH_H_
#define CERES_SESYNC_POSE_GRAPH_H_

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "Eigen/Core"

namespace ceres_sesync {

// A measurement of the pose of j relative to the pose of i:
//   R~_ij ~ R_i^T R_j,  t~_ij ~ R_i^T (t_j - t_i).
struct RelativePoseMeasurement {
  int i = 0;          // Dense index of the source pose.
  int j = 0;          // Dense index of the target pose.
  Eigen::MatrixXd R;  // d x d measured relative rotation.
  Eigen::VectorXd t;  // d measured relative translation.
  double kappa = 0;   // Rotational precision (> 0).
  double tau = 0;     // Translational precision (> 0).
};

// A measurement of landmark l from pose i, in the frame of pose i:
//   z_il ~ R_i^T (p_l - t_i).
struct LandmarkMeasurement {
  int i = 0;          // Dense index of the observing pose.
  int l = 0;          // Dense index of the landmark.
  Eigen::VectorXd z;  // d measured position of the landmark in pose i's frame.
  double nu = 0;      // Translational precision (> 0): d / tr(I^-1).
};

// A prior on pose i in the world frame: R~ ~ R_i (weight kappa), g ~ t_i
// (weight tau). kappa = 0 makes it a position-only prior (R is then not
// used and may be empty), tau = 0 a rotation-only prior (t may be empty);
// at least one of them is positive.
struct PosePrior {
  int i = 0;          // Dense index of the pose.
  Eigen::MatrixXd R;  // d x d prior rotation R~ (used if kappa > 0).
  Eigen::VectorXd t;  // d prior position g (used if tau > 0).
  double kappa = 0;   // Rotational precision (>= 0).
  double tau = 0;     // Translational precision (>= 0).

  bool has_rotation() const { return kappa > 0; }
  bool has_position() const { return tau > 0; }
};

// A pose in SE(d): rotation R (d x d) and translation t (d).
struct Pose {
  Eigen::MatrixXd R;
  Eigen::VectorXd t;
};
using Poses = std::vector<Pose>;

// One position (a d-vector) per landmark, in dense landmark order.
using LandmarkPositions = std::vector<Eigen::VectorXd>;

// Values of every unknown of a graph: one pose per pose (dense order) and
// one position per landmark (dense landmark order; empty for a graph
// without landmarks).
struct Solution {
  Poses poses;
  LandmarkPositions landmarks;
};

struct PoseGraph {
  // Dimension d of the poses and landmarks: 2 or 3.
  int dimension = 0;
  // Number of poses n. Poses are addressed by a dense index 0..n-1.
  int num_poses = 0;
  // The measurements (parallel edges allowed; no self-loops).
  std::vector<RelativePoseMeasurement> measurements;
  // Original vertex id of each dense index (size num_poses).
  std::vector<int64_t> vertex_ids;
  // Inverse of vertex_ids.
  std::unordered_map<int64_t, int> index_of_vertex_id;
  // Initial guess per pose, from VERTEX lines: either empty or of size
  // num_poses.
  Poses initial_poses;
  // Dense index of the pose fixed as gauge (g2o `FIX`), or -1. Only for
  // graphs without priors (priors fix the gauge themselves).
  int fixed_pose = -1;

  // Number of landmarks L, addressed by a dense index 0..L-1.
  int num_landmarks = 0;
  // Pose-to-landmark measurements (several per pair allowed).
  std::vector<LandmarkMeasurement> landmark_measurements;
  // Original vertex id of each landmark (size num_landmarks). Poses and
  // landmarks share one id space, as in g2o: no landmark id is a pose id.
  std::vector<int64_t> landmark_ids;
  // Inverse of landmark_ids.
  std::unordered_map<int64_t, int> index_of_landmark_id;
  // Initial guess per landmark: either empty or of size num_landmarks.
  LandmarkPositions initial_landmarks;
  // Priors on poses (several per pose allowed; they add up).
  std::vector<PosePrior> priors;

  // Returns the dense index of `vertex_id`, adding a new pose if it is new.
  int AddVertex(int64_t vertex_id);
  // Returns the dense index of `vertex_id`, or -1 if there is none.
  int FindVertex(int64_t vertex_id) const;
  // The same for landmarks (dense landmark indices).
  int AddLandmark(int64_t landmark_id);
  int FindLandmark(int64_t landmark_id) const;

  // Whether the graph has terms beyond eq. (12): landmarks or priors.
  bool has_landmarks_or_priors() const {
    return num_landmarks > 0 || !landmark_measurements.empty() ||
           !priors.empty();
  }
};

// Labels the poses and landmarks with their connected components in the
// (undirected) graph whose edges are the measurements, the landmark
// measurements, and the priors (edges to one world node, so all poses with
// priors are connected to each other). Returns the number of components;
// `component` (if not null) gets one label in 0..k-1 per pose, followed by
// one per landmark (num_poses + num_landmarks entries).
int ConnectedComponents(const PoseGraph& graph, std::vector<int>* component);

// The same for the translational terms only: edges, landmark measurements
// and the priors with a position term (tau > 0). Rotation-only priors tie a
// pose to the world frame in rotation only, so a part of the graph linked to
// the rest only by them has a translation of its own to fix (a gauge
// freedom, like a disconnected pose graph); ValidatePoseGraph rejects that.
// Without priors this equals ConnectedComponents.
int TranslationalComponents(const PoseGraph& graph,
                            std::vector<int>* component);

struct ValidationOptions {
  // A disconnected graph passes when false (each component is then a pose
  // graph of its own; see component_solver.h).
  bool require_connected = true;
};

// Checks the structural and numerical invariants every solver relies on:
// d in {2, 3}; indices in range; no self-loops; finite, positive kappa and
// tau; rotations in SO(d) to 1e-6; initial poses and landmarks (if any) of
// the right size; fixed_pose -1 or a pose index; landmark ids distinct and
// distinct from the pose ids; finite landmark measurements with nu > 0;
// every landmark observed at least once; priors with finite kappa, tau >= 0,
// not both 0, and a rotation / position where they are used; no fixed_pose
// together with priors; and a connected graph of poses and landmarks (see
// ConnectedComponents: with priors, components linked through the world
// frame count as connected) whose translational terms are connected too
// (TranslationalComponents; with options.require_connected = false a
// disconnected graph passes). A landmark seen by a single pose is fine.
// Returns false with a message otherwise.
bool ValidatePoseGraph(const PoseGraph& graph, const ValidationOptions& options,
                       std::string* error);
// The same with the default ValidationOptions.
bool ValidatePoseGraph(const PoseGraph& graph, std::string* error);

// Evaluates the objective F(x, p) above (eq. (12) for a graph without
// landmarks and priors). `poses` must hold graph.num_poses poses and
// `landmarks` graph.num_landmarks positions (it may be omitted for a graph
// without landmarks); if a size differs, the result is NaN.
double EvaluateObjective(const PoseGraph& graph, const Poses& poses,
                         const LandmarkPositions& landmarks = {});
inline double EvaluateObjective(const PoseGraph& graph,
                                const Solution& solution) {
  return EvaluateObjective(graph, solution.poses, solution.landmarks);
}

// The landmark positions that minimize F for fixed `poses` (one pose per
// pose of `graph`): a landmark's position enters only its own measurements'
// terms, so it is their nu-weighted mean of the positions t_i + R_i z they
// imply. A landmark without measurements is left at the origin.
LandmarkPositions OptimalLandmarkPositions(const PoseGraph& graph,
                                           const Poses& poses);

// Identity poses for the graph's dimension.
Poses IdentityPoses(int dimension, int num_poses);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_POSE_GRAPH_H_
