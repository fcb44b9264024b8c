#include "ceres_sesync/pose_graph.h"

#include <cmath>
#include <numeric>
#include <sstream>

#include "Eigen/LU"

namespace ceres_sesync {

int PoseGraph::AddVertex(int64_t vertex_id) {
  auto [it, inserted] = index_of_vertex_id.emplace(vertex_id, num_poses);
  if (inserted) {
    vertex_ids.push_back(vertex_id);
    ++num_poses;
  }
  return it->second;
}

int PoseGraph::FindVertex(int64_t vertex_id) const {
  auto it = index_of_vertex_id.find(vertex_id);
  return it == index_of_vertex_id.end() ? -1 : it->second;
}

namespace {
int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

bool IsRotation(const Eigen::MatrixXd& R, int d, double tolerance) {
  if (R.rows() != d || R.cols() != d || !R.allFinite()) return false;
  const double orthogonality =
      (R.transpose() * R - Eigen::MatrixXd::Identity(d, d)).norm();
  return orthogonality <= tolerance &&
         std::abs(R.determinant() - 1) <= tolerance;
}
}  // namespace

int ConnectedComponents(const PoseGraph& graph, std::vector<int>* component) {
  const int n = graph.num_poses;
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& e : graph.measurements) {
    if (e.i < 0 || e.j < 0 || e.i >= n || e.j >= n) continue;
    parent[FindRoot(parent, e.i)] = FindRoot(parent, e.j);
  }
  std::vector<int> label(n, -1), root_label(n, -1);
  int k = 0;
  for (int v = 0; v < n; ++v) {
    const int root = FindRoot(parent, v);
    if (root_label[root] < 0) root_label[root] = k++;
    label[v] = root_label[root];
  }
  if (component) *component = std::move(label);
  return k;
}

bool ValidatePoseGraph(const PoseGraph& graph, std::string* error,
                       bool require_connected) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const int d = graph.dimension;
  if (d != 2 && d != 3) return fail("pose graph dimension must be 2 or 3");
  if (graph.num_poses < 1) return fail("pose graph has no poses");
  if (static_cast<int>(graph.vertex_ids.size()) != graph.num_poses) {
    return fail("vertex_ids must have one entry per pose");
  }
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const auto& e = graph.measurements[k];
    auto where = [&] {
      return "measurement " + std::to_string(k) + " (" + std::to_string(e.i) +
             " -> " + std::to_string(e.j) + "): ";
    };
    if (e.i < 0 || e.j < 0 || e.i >= graph.num_poses ||
        e.j >= graph.num_poses) {
      return fail(where() + "pose index out of range");
    }
    if (e.i == e.j) return fail(where() + "self-loop");
    if (!IsRotation(e.R, d, 1e-6)) {
      return fail(where() + "rotation is not in SO(d)");
    }
    if (e.t.size() != d || !e.t.allFinite()) {
      return fail(where() + "translation is not a finite d-vector");
    }
    if (!(std::isfinite(e.kappa) && e.kappa > 0 && std::isfinite(e.tau) &&
          e.tau > 0)) {
      return fail(where() + "kappa and tau must be finite and positive");
    }
  }
  if (graph.fixed_pose < -1 || graph.fixed_pose >= graph.num_poses) {
    return fail("fixed_pose is not a pose index (or -1)");
  }
  if (!graph.initial_poses.empty()) {
    if (static_cast<int>(graph.initial_poses.size()) != graph.num_poses) {
      return fail("initial_poses must be empty or have one pose per vertex");
    }
    for (const auto& p : graph.initial_poses) {
      if (!IsRotation(p.R, d, 1e-6) || p.t.size() != d || !p.t.allFinite()) {
        return fail("an initial pose is not a finite pose in SE(d)");
      }
    }
  }
  if (!require_connected) return true;
  const int k = ConnectedComponents(graph, nullptr);
  if (k != 1) {
    std::ostringstream s;
    s << "measurement graph is disconnected: " << k << " components";
    return fail(s.str());
  }
  return true;
}

double EvaluateObjective(const PoseGraph& graph, const Poses& poses) {
  double f = 0;
  for (const auto& e : graph.measurements) {
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    f += e.kappa * (b.R - a.R * e.R).squaredNorm() +
         e.tau * (b.t - a.t - a.R * e.t).squaredNorm();
  }
  return f;
}

Poses IdentityPoses(int dimension, int num_poses) {
  return Poses(num_poses, Pose{Eigen::MatrixXd::Identity(dimension, dimension),
                               Eigen::VectorXd::Zero(dimension)});
}

}  // namespace ceres_sesync
