#include "ceres_sesync/internal/measurement_weights.h"

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
  const size_t m = graph.measurements.size();
  if (weights.size() != m) {
    return fail("measurement weights: " + std::to_string(weights.size()) +
                " weights for " + std::to_string(m) + " measurements");
  }
  const int n = graph.num_poses;
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  int components = n;
  for (size_t k = 0; k < m; ++k) {
    if (!(std::isfinite(weights[k]) && weights[k] >= 0)) {
      return fail("measurement weights: weight " + std::to_string(k) +
                  " is not a finite number >= 0");
    }
    if (weights[k] == 0) continue;
    const RelativePoseMeasurement& e = graph.measurements[k];
    const int a = FindRoot(parent, e.i), b = FindRoot(parent, e.j);
    if (a != b) {
      parent[a] = b;
      --components;
    }
  }
  if (components > 1) {
    const int root = FindRoot(parent, 0);
    int other = 0;
    while (FindRoot(parent, other) == root) ++other;
    std::ostringstream s;
    s << "the measurements of positive weight leave the graph in " << components
      << " components (e.g. pose "
      << (graph.vertex_ids.empty() ? other : graph.vertex_ids[other])
      << " is not connected to pose "
      << (graph.vertex_ids.empty() ? 0 : graph.vertex_ids[0])
      << "): the relative placement of the components is undetermined";
    return fail(s.str());
  }
  return true;
}

double WeightedObjective(const PoseGraph& graph,
                         const MeasurementWeights& weights,
                         const Poses& poses) {
  double f = 0;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Precisions p = WeightedPrecisions(e, weights, k);
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    f += p.kappa * (b.R - a.R * e.R).squaredNorm() +
         p.tau * (b.t - a.t - a.R * e.t).squaredNorm();
  }
  return f;
}

}  // namespace ceres_sesync::internal
