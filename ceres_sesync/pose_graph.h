// Pose-graph data model shared by every part of ceres_sesync.
//
// A pose graph has n poses x_i = (R_i, t_i) in SE(d), d = 2 or 3, and m
// relative measurements on directed edges (i, j). The maximum-likelihood
// objective (Rosen et al., IJRR 2019, eq. 12) is
//
//   F(x) = sum_(i,j) kappa_ij ||R_j - R_i R~_ij||_F^2
//                  + tau_ij   ||t_j - t_i - R_i t~_ij||_2^2,
//
// and every objective value this library reports is on that scale.

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

// A pose in SE(d): rotation R (d x d) and translation t (d).
struct Pose {
  Eigen::MatrixXd R;
  Eigen::VectorXd t;
};
using Poses = std::vector<Pose>;

struct PoseGraph {
  // Dimension d of the poses: 2 or 3.
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
  // Dense index of the pose fixed as gauge (g2o `FIX`), or -1.
  int fixed_pose = -1;

  // Returns the dense index of `vertex_id`, adding a new pose if it is new.
  int AddVertex(int64_t vertex_id);
  // Returns the dense index of `vertex_id`, or -1 if there is none.
  int FindVertex(int64_t vertex_id) const;
};

// Labels each pose with its connected component in the (undirected)
// measurement graph. Returns the number of components; `component` (if not
// null) gets one label in 0..k-1 per pose.
int ConnectedComponents(const PoseGraph& graph, std::vector<int>* component);

// Checks the structural and numerical invariants every solver relies on:
// d in {2, 3}; indices in range; no self-loops; finite, positive kappa and
// tau; rotations in SO(d) to 1e-6; a connected measurement graph; initial
// poses (if any) of the right size; fixed_pose -1 or a pose index. Returns
// false with a message otherwise. With require_connected = false a
// disconnected graph passes (each component is then a pose graph of its own;
// see component_solver.h).
bool ValidatePoseGraph(const PoseGraph& graph, std::string* error,
                       bool require_connected = true);

// Evaluates the maximum-likelihood objective F(x) of eq. (12).
double EvaluateObjective(const PoseGraph& graph, const Poses& poses);

// Identity poses for the graph's dimension.
Poses IdentityPoses(int dimension, int num_poses);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_POSE_GRAPH_H_
