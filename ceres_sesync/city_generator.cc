#include "ceres_sesync/city_generator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

#include "ceres_sesync/internal/synthetic_graph.h"
#include "ceres_sesync/langevin.h"

namespace ceres_sesync {

namespace {

using LatticePoint = std::array<int, 3>;

// The 6 lattice-axis directions -x, +x, -y, +y, -z, +z; direction k is
// along axis k / 2, and k ^ 1 is its reverse.
LatticePoint Direction(int k) {
  LatticePoint step = {0, 0, 0};
  step[k / 2] = k % 2 == 0 ? -1 : 1;
  return step;
}

// The walk of city_generator.h: the lattice node of every pose.
std::vector<LatticePoint> CityWalk(int n, int side, int height,
                                   double turn_probability,
                                   std::mt19937_64* rng) {
  const int extent[3] = {side, side, height};
  auto inside = [&](const LatticePoint& p, int k) {
    const int axis = k / 2;
    const int c = p[axis] + (k % 2 == 0 ? -1 : 1);
    return c >= 0 && c < extent[axis];
  };
  std::vector<LatticePoint> walk(static_cast<size_t>(n));
  walk[0] = {side / 2, side / 2, 0};
  int heading = 1;  // +x
  const int num_directions = height > 1 ? 6 : 4;
  for (int j = 0; j + 1 < n; ++j) {
    const LatticePoint& p = walk[j];
    int turns[4];
    int num_turns = 0;
    for (int k = 0; k < num_directions; ++k) {
      if (k / 2 != heading / 2 && inside(p, k)) turns[num_turns++] = k;
    }
    const bool straight = inside(p, heading);
    const bool turn = SampleUniform01(rng) < turn_probability || !straight;
    if (turn && num_turns > 0) {
      heading = turns[static_cast<int>(SampleUniform01(rng) * num_turns)];
    } else if (!straight) {
      heading ^= 1;  // A dead end: reverse (unreachable for side >= 2).
    }
    const LatticePoint step = Direction(heading);
    for (int a = 0; a < 3; ++a) walk[j + 1][a] = p[a] + step[a];
  }
  return walk;
}

}  // namespace

bool GenerateCity(const CityOptions& options, PoseGraph* graph,
                  Poses* ground_truth, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const int d = options.dimension;
  const int n = options.num_poses;
  if (d != 2 && d != 3) return fail("city dimension must be 2 or 3");
  if (n < 2 || n > internal::kMaxSyntheticPoses) {
    std::ostringstream m;
    m << "city poses must be in [2, " << internal::kMaxSyntheticPoses
      << "], got " << n;
    return fail(m.str());
  }
  const double p_lc = options.loop_closure_probability;
  std::string noise_error;
  if (!internal::CheckNoiseOptions(p_lc, options.kappa, options.tau,
                                   options.spacing, &noise_error)) {
    return fail(noise_error);
  }
  if (!(options.lattice_scale > 0 && options.lattice_scale <= 2)) {
    return fail("city lattice scale must be in (0, 2]");
  }
  if (options.levels < 1 || options.levels > 100) {
    return fail("city levels must be in [1, 100]");
  }
  if (!(options.turn_probability >= 0 && options.turn_probability <= 1)) {
    return fail("city turn probability must be in [0, 1]");
  }
  if (options.max_loop_closures_per_visit < 0) {
    return fail("city max loop closures per visit must be >= 0");
  }
  const int height = d == 3 ? options.levels : 1;
  const int side = std::max(
      2,
      static_cast<int>(std::ceil(options.lattice_scale *
                                 std::sqrt(static_cast<double>(n) / height))));

  std::mt19937_64 rng(options.seed);
  const std::vector<LatticePoint> walk =
      CityWalk(n, side, height, options.turn_probability, &rng);

  // Ground truth: spacing times the lattice coordinates relative to the
  // start; each pose faces its next step.
  Poses truth(n);
  for (int i = 0; i < n; ++i) {
    const int a = i + 1 < n ? i : i - 1;  // heading from a to a + 1
    Eigen::Vector3d forward;
    for (int k = 0; k < 3; ++k) forward[k] = walk[a + 1][k] - walk[a][k];
    truth[i].R = internal::HeadingRotation(d, forward);
    truth[i].t.resize(d);
    for (int k = 0; k < d; ++k) {
      truth[i].t[k] = options.spacing * (walk[i][k] - walk[0][k]);
    }
  }

  // The poses at each node in increasing order, as compressed lists:
  // poses_at[first[v] .. first[v + 1]) for node v.
  const size_t num_nodes = static_cast<size_t>(side) * side * height;
  auto node_of = [&](const LatticePoint& p) {
    return static_cast<size_t>(p[0]) +
           static_cast<size_t>(side) *
               (p[1] + static_cast<size_t>(side) * p[2]);
  };
  std::vector<int> first(num_nodes + 1, 0);
  for (const LatticePoint& p : walk) ++first[node_of(p) + 1];
  for (size_t v = 0; v < num_nodes; ++v) first[v + 1] += first[v];
  std::vector<int> poses_at(static_cast<size_t>(n));
  std::vector<int> filled(first.begin(), first.end() - 1);

  // Measurements, in order of the later pose. The earlier poses at j's node
  // are poses_at[first[v] .. filled[v]) when j is reached.
  PoseGraph g;
  g.dimension = d;
  for (int i = 0; i < n; ++i) g.AddVertex(i);
  const int cap = options.max_loop_closures_per_visit;
  const double log_keep = std::log1p(-p_lc);  // -inf for p_lc = 1.
  for (int j = 0; j < n; ++j) {
    const size_t v = node_of(walk[j]);
    if (j > 0) {
      internal::AddNoisyMeasurement(truth, j - 1, j, options.kappa, options.tau,
                                    &rng, &g);
      // Newest first: candidate c = filled[v] - 1 - (skipped so far). The
      // number of rejections before the next acceptance is geometric,
      // floor(log(U) / log(1 - p)) for U uniform in (0, 1].
      long next = filled[v];
      for (int drawn = 0; p_lc > 0 && drawn < cap; ++drawn) {
        double skip = 0;
        if (p_lc < 1) {
          skip = std::floor(std::log(1 - SampleUniform01(&rng)) / log_keep);
        }
        if (!(skip < next - first[v])) break;  // Ran out of earlier poses.
        next -= static_cast<long>(skip) + 1;
        internal::AddNoisyMeasurement(truth, poses_at[next], j, options.kappa,
                                      options.tau, &rng, &g);
      }
    }
    poses_at[filled[v]++] = j;
  }
  if (graph) *graph = std::move(g);
  if (ground_truth) *ground_truth = std::move(truth);
  return true;
}

}  // namespace ceres_sesync
