#include "ceres_sesync/pose_graph.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_set>

#include "Eigen/LU"
#include "ceres_sesync/internal/measurement_weights.h"

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

int PoseGraph::AddLandmark(int64_t landmark_id) {
  auto [it, inserted] =
      index_of_landmark_id.emplace(landmark_id, num_landmarks);
  if (inserted) {
    landmark_ids.push_back(landmark_id);
    ++num_landmarks;
  }
  return it->second;
}

int PoseGraph::FindLandmark(int64_t landmark_id) const {
  auto it = index_of_landmark_id.find(landmark_id);
  return it == index_of_landmark_id.end() ? -1 : it->second;
}

namespace {
int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

template <int kD>
bool IsRotationOfSize(const Eigen::MatrixXd& R, int d, double tolerance) {
  using Matrix = Eigen::Matrix<double, kD, kD>;
  const Matrix M = R;
  const double orthogonality =
      (M.transpose() * M - Matrix::Identity(d, d)).norm();
  return orthogonality <= tolerance &&
         std::abs(M.determinant() - 1) <= tolerance;
}

bool IsRotation(const Eigen::MatrixXd& R, int d, double tolerance) {
  if (R.rows() != d || R.cols() != d || !R.allFinite()) return false;
  // Fixed sizes for d = 2, 3: no heap allocation and a closed-form
  // determinant (this runs for every measurement of every solve).
  if (d == 2) return IsRotationOfSize<2>(R, d, tolerance);
  if (d == 3) return IsRotationOfSize<3>(R, d, tolerance);
  return IsRotationOfSize<Eigen::Dynamic>(R, d, tolerance);
}
}  // namespace

namespace {

// Components of poses and landmarks linked by the measurements, landmark
// measurements and priors; with `translations_only`, priors link their pose
// to the world node only if they have a position term.
int Components(const PoseGraph& graph, bool translations_only,
               std::vector<int>* component) {
  const int n = graph.num_poses;
  const int L = std::max(graph.num_landmarks, 0);
  // Nodes: poses 0..n-1, landmarks n..n+L-1, the world node n+L.
  const int world = n + L;
  std::vector<int> parent(world + 1);
  std::iota(parent.begin(), parent.end(), 0);
  auto unite = [&](int a, int b) {
    parent[FindRoot(parent, a)] = FindRoot(parent, b);
  };
  auto is_pose = [n](int i) { return i >= 0 && i < n; };
  for (const auto& e : graph.measurements) {
    if (is_pose(e.i) && is_pose(e.j)) unite(e.i, e.j);
  }
  for (const auto& o : graph.landmark_measurements) {
    if (is_pose(o.i) && o.l >= 0 && o.l < L) unite(o.i, n + o.l);
  }
  for (const auto& p : graph.priors) {
    if (is_pose(p.i) && (!translations_only || p.tau > 0)) unite(p.i, world);
  }
  std::vector<int> label(n + L, -1), root_label(world + 1, -1);
  int k = 0;
  for (int v = 0; v < n + L; ++v) {
    const int root = FindRoot(parent, v);
    if (root_label[root] < 0) root_label[root] = k++;
    label[v] = root_label[root];
  }
  if (component) *component = std::move(label);
  return k;
}

}  // namespace

int ConnectedComponents(const PoseGraph& graph, std::vector<int>* component) {
  return Components(graph, false, component);
}

int TranslationalComponents(const PoseGraph& graph,
                            std::vector<int>* component) {
  return Components(graph, true, component);
}

bool ValidatePoseGraph(const PoseGraph& graph, std::string* error) {
  return ValidatePoseGraph(graph, ValidationOptions(), error);
}

bool ValidatePoseGraph(const PoseGraph& graph, const ValidationOptions& options,
                       std::string* error) {
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

  // Landmarks.
  const int L = graph.num_landmarks;
  if (L < 0) return fail("num_landmarks is negative");
  if (static_cast<int>(graph.landmark_ids.size()) != L) {
    return fail("landmark_ids must have one entry per landmark");
  }
  if (L > 0) {
    std::unordered_set<int64_t> ids(graph.vertex_ids.begin(),
                                    graph.vertex_ids.end());
    for (int64_t id : graph.landmark_ids) {
      if (!ids.insert(id).second) {
        return fail("landmark id " + std::to_string(id) +
                    " is used twice or is also a pose id (poses and "
                    "landmarks share one id space)");
      }
    }
  }
  std::vector<char> observed(L, 0);
  for (size_t k = 0; k < graph.landmark_measurements.size(); ++k) {
    const auto& o = graph.landmark_measurements[k];
    auto where = [&] {
      return "landmark measurement " + std::to_string(k) + " (pose " +
             std::to_string(o.i) + " -> landmark " + std::to_string(o.l) +
             "): ";
    };
    if (o.i < 0 || o.i >= graph.num_poses) {
      return fail(where() + "pose index out of range");
    }
    if (o.l < 0 || o.l >= L) {
      return fail(where() + "landmark index out of range");
    }
    if (o.z.size() != d || !o.z.allFinite()) {
      return fail(where() + "measurement is not a finite d-vector");
    }
    if (!(std::isfinite(o.nu) && o.nu > 0)) {
      return fail(where() + "nu must be finite and positive");
    }
    observed[o.l] = 1;
  }
  for (int l = 0; l < L; ++l) {
    if (!observed[l]) {
      return fail("landmark " + std::to_string(graph.landmark_ids[l]) +
                  " is not observed by any pose");
    }
  }
  if (!graph.initial_landmarks.empty()) {
    if (static_cast<int>(graph.initial_landmarks.size()) != L) {
      return fail(
          "initial_landmarks must be empty or have one position per "
          "landmark");
    }
    for (const auto& p : graph.initial_landmarks) {
      if (p.size() != d || !p.allFinite()) {
        return fail("an initial landmark position is not a finite d-vector");
      }
    }
  }

  // Priors.
  for (size_t k = 0; k < graph.priors.size(); ++k) {
    const auto& p = graph.priors[k];
    auto where = [&] {
      return "prior " + std::to_string(k) + " (pose " + std::to_string(p.i) +
             "): ";
    };
    if (p.i < 0 || p.i >= graph.num_poses) {
      return fail(where() + "pose index out of range");
    }
    if (!(std::isfinite(p.kappa) && p.kappa >= 0 && std::isfinite(p.tau) &&
          p.tau >= 0 && (p.kappa > 0 || p.tau > 0))) {
      return fail(where() +
                  "kappa and tau must be finite and non-negative, and not "
                  "both zero");
    }
    if (p.has_rotation() && !IsRotation(p.R, d, 1e-6)) {
      return fail(where() + "rotation is not in SO(d)");
    }
    if (p.has_position() && (p.t.size() != d || !p.t.allFinite())) {
      return fail(where() + "position is not a finite d-vector");
    }
  }
  if (!graph.priors.empty() && graph.fixed_pose >= 0) {
    return fail(
        "fixed_pose (FIX) together with priors: the priors fix the gauge, "
        "and a fixed pose on top of them would be a hard constraint, which "
        "the model does not have");
  }

  if (options.require_connected) {
    const int k = ConnectedComponents(graph, nullptr);
    if (k != 1) {
      std::ostringstream s;
      s << "measurement graph is disconnected: " << k << " components";
      return fail(s.str());
    }
    if (!graph.priors.empty()) {  // Else the same as ConnectedComponents.
      const int kt = TranslationalComponents(graph, nullptr);
      if (kt != 1) {
        std::ostringstream s;
        s << "the translational terms are disconnected: " << kt
          << " components (a part tied to the rest only by rotation priors "
             "would have a free translation)";
        return fail(s.str());
      }
    }
  }
  return true;
}

double EvaluateObjective(const PoseGraph& graph, const Poses& poses,
                         const LandmarkPositions& landmarks) {
  if (static_cast<int>(poses.size()) != graph.num_poses ||
      static_cast<int>(landmarks.size()) != graph.num_landmarks) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return internal::WeightedObjective(graph, {}, poses, landmarks);
}

LandmarkPositions OptimalLandmarkPositions(const PoseGraph& graph,
                                           const Poses& poses) {
  LandmarkPositions p(graph.num_landmarks,
                      Eigen::VectorXd::Zero(graph.dimension));
  std::vector<double> weight(graph.num_landmarks, 0);
  for (const LandmarkMeasurement& o : graph.landmark_measurements) {
    p[o.l] += o.nu * (poses[o.i].t + poses[o.i].R * o.z);
    weight[o.l] += o.nu;
  }
  for (int l = 0; l < graph.num_landmarks; ++l) {
    if (weight[l] > 0) p[l] /= weight[l];
  }
  return p;
}

Poses IdentityPoses(int dimension, int num_poses) {
  return Poses(num_poses, Pose{Eigen::MatrixXd::Identity(dimension, dimension),
                               Eigen::VectorXd::Zero(dimension)});
}

}  // namespace ceres_sesync
