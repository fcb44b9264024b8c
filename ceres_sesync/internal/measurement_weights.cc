#include "ceres_sesync/internal/measurement_weights.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace ceres_sesync::internal {
namespace {

int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

bool CheckMeasurementWeights(const PoseGraph& graph,
                             const MeasurementWeights& weights,
                             std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (weights.empty()) return true;
  const size_t terms = NumWeightedTerms(graph);
  if (weights.size() != terms) {
    return fail("measurement weights: " + std::to_string(weights.size()) +
                " weights for " + std::to_string(terms) + " terms");
  }
  for (size_t k = 0; k < terms; ++k) {
    if (!(std::isfinite(weights[k]) && weights[k] >= 0)) {
      return fail("measurement weights: weight " + std::to_string(k) +
                  " is not a finite number >= 0");
    }
  }
  // Vertices: the poses, the landmarks (n + l) and, with priors, the world
  // frame (n + L). `all` joins along every positive term; `translational`
  // along the translation terms only, and has the world only if some prior
  // has a position term (ProblemLayout's world translation node).
  const int n = graph.num_poses, L = graph.num_landmarks;
  const int world = n + L;
  const bool has_world = !graph.priors.empty();
  const bool has_world_translation =
      std::any_of(graph.priors.begin(), graph.priors.end(),
                  [](const PosePrior& p) { return p.has_position(); });
  struct Components {
    std::vector<int> parent;
    int count;
    Components(int size) : parent(size), count(size) {
      std::iota(parent.begin(), parent.end(), 0);
    }
    void Join(int a, int b) {
      a = FindRoot(parent, a);
      b = FindRoot(parent, b);
      if (a != b) {
        parent[a] = b;
        --count;
      }
    }
  };
  Components all(n + L + (has_world ? 1 : 0));
  Components translational(n + L + (has_world_translation ? 1 : 0));
  const size_t m = graph.measurements.size();
  for (size_t k = 0; k < m; ++k) {
    if (weights[k] == 0) continue;
    const RelativePoseMeasurement& e = graph.measurements[k];
    all.Join(e.i, e.j);
    if (has_world) translational.Join(e.i, e.j);
  }
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    if (weights[LandmarkTerm(graph, q)] == 0) continue;
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    all.Join(o.i, n + o.l);
    if (has_world) translational.Join(o.i, n + o.l);
  }
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    if (weights[PriorTerm(graph, q)] == 0) continue;
    const PosePrior& p = graph.priors[q];
    all.Join(p.i, world);
    if (p.has_position()) translational.Join(p.i, world);
  }
  // (Without priors the translational terms connect what all terms do.)
  Components* broken = all.count > 1                          ? &all
                       : has_world && translational.count > 1 ? &translational
                                                              : nullptr;
  if (broken == nullptr) return true;
  const int root = FindRoot(broken->parent, 0);
  int other = 0;
  while (FindRoot(broken->parent, other) == root) ++other;
  auto name = [&](int v) {
    if (v < n) {
      return "pose " +
             std::to_string(graph.vertex_ids.empty() ? v : graph.vertex_ids[v]);
    }
    if (v < n + L) {
      return "landmark " + std::to_string(graph.landmark_ids.empty()
                                              ? v - n
                                              : graph.landmark_ids[v - n]);
    }
    return std::string("the world frame of the priors");
  };
  std::ostringstream s;
  s << "the " << (broken == &all ? "" : "translational ")
    << "terms of positive weight leave the graph in " << broken->count
    << " components (e.g. " << name(other) << " is not connected to " << name(0)
    << "): the relative placement of the components is "
    << "undetermined";
  return fail(s.str());
}

double WeightedObjective(const PoseGraph& graph,
                         const MeasurementWeights& weights, const Poses& poses,
                         const LandmarkPositions& landmarks) {
  double f = 0;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Precisions p = WeightedPrecisions(e, weights, k);
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    f += p.kappa * (b.R - a.R * e.R).squaredNorm() +
         p.tau * (b.t - a.t - a.R * e.t).squaredNorm();
  }
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    const Pose& a = poses[o.i];
    f += WeightedPrecision(o, weights, LandmarkTerm(graph, q)) *
         (landmarks[o.l] - a.t - a.R * o.z).squaredNorm();
  }
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    const PosePrior& p = graph.priors[q];
    const Precisions w = WeightedPrecisions(p, weights, PriorTerm(graph, q));
    const Pose& a = poses[p.i];
    if (p.has_rotation()) f += w.kappa * (a.R - p.R).squaredNorm();
    if (p.has_position()) f += w.tau * (a.t - p.t).squaredNorm();
  }
  return f;
}

}  // namespace ceres_sesync::internal
