#include "ceres_sesync/cube_generator.h"

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

// The boustrophedon path through the lattice (see cube_generator.h).
std::vector<LatticePoint> RectilinearPath(int d, int s) {
  std::vector<LatticePoint> layer;
  layer.reserve(static_cast<size_t>(s) * s);
  for (int y = 0; y < s; ++y) {
    for (int k = 0; k < s; ++k) {
      layer.push_back({y % 2 == 0 ? k : s - 1 - k, y, 0});
    }
  }
  if (d == 2) return layer;
  std::vector<LatticePoint> path;
  path.reserve(layer.size() * s);
  for (int z = 0; z < s; ++z) {
    for (size_t k = 0; k < layer.size(); ++k) {
      LatticePoint p = z % 2 == 0 ? layer[k] : layer[layer.size() - 1 - k];
      p[2] = z;
      path.push_back(p);
    }
  }
  return path;
}

// The lattice offsets of the loop-closure candidates of a pose: every
// nonzero integer offset o (in the first d coordinates) with |o| <= radius.
// The 2d unit offsets come first, in the order -x, +x, -y, +y, -z, +z (the
// order of the generator before longer offsets existed), then the others in
// lexicographic order.
std::vector<LatticePoint> LoopClosureOffsets(int d, double radius) {
  std::vector<LatticePoint> offsets;
  for (int axis = 0; axis < d; ++axis) {
    for (int step : {-1, 1}) {
      LatticePoint o = {0, 0, 0};
      o[axis] = step;
      offsets.push_back(o);
    }
  }
  // Squared lengths are integers, so a tolerance of 1e-3 on the squared
  // radius changes nothing else and admits sqrt(k) given to a few digits
  // (1.732 for sqrt(3)).
  const double max_squared = radius * radius + 1e-3;
  const int reach = static_cast<int>(std::floor(std::sqrt(max_squared)));
  const int reach_z = d == 3 ? reach : 0;
  for (int x = -reach; x <= reach; ++x) {
    for (int y = -reach; y <= reach; ++y) {
      for (int z = -reach_z; z <= reach_z; ++z) {
        const int squared = x * x + y * y + z * z;
        if (squared <= 1 || squared > max_squared) continue;
        offsets.push_back({x, y, z});
      }
    }
  }
  return offsets;
}

}  // namespace

double ExpectedGroundTruthObjective(int dimension, int num_measurements,
                                    double kappa) {
  return num_measurements *
         (4 * kappa * (1 - VonMisesMeanCosine(2 * kappa)) + dimension);
}

bool GenerateCube(const CubeOptions& options, PoseGraph* graph,
                  Poses* ground_truth, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const int d = options.dimension;
  const int s = options.side;
  if (d != 2 && d != 3) return fail("cube dimension must be 2 or 3");
  if (s < 2) return fail("cube side must be at least 2");
  int64_t n64 = 1;
  for (int k = 0; k < d; ++k) {
    n64 *= s;
    if (n64 > internal::kMaxSyntheticPoses) {
      std::ostringstream m;
      m << "cube side " << s << " gives more than "
        << internal::kMaxSyntheticPoses << " poses";
      return fail(m.str());
    }
  }
  const double p_lc = options.loop_closure_probability;
  std::string noise_error;
  if (!internal::CheckNoiseOptions(p_lc, options.kappa, options.tau,
                                   options.spacing, &noise_error)) {
    return fail(noise_error);
  }
  if (!(options.loop_closure_radius >= 1 && options.loop_closure_radius <= 4)) {
    return fail("loop closure radius must be in [1, 4] lattice units");
  }
  const int n = static_cast<int>(n64);

  // Ground truth along the path.
  const std::vector<LatticePoint> path = RectilinearPath(d, s);
  std::vector<int> index_of_point(static_cast<size_t>(n));
  auto flat = [s](const LatticePoint& p) {
    return static_cast<size_t>(p[0]) +
           static_cast<size_t>(s) * (p[1] + static_cast<size_t>(s) * p[2]);
  };
  for (int i = 0; i < n; ++i) index_of_point[flat(path[i])] = i;
  Poses truth(n);
  for (int i = 0; i < n; ++i) {
    const int a = i + 1 < n ? i : i - 1;  // heading from a to a + 1
    Eigen::Vector3d forward;
    for (int k = 0; k < 3; ++k) forward[k] = path[a + 1][k] - path[a][k];
    truth[i].R = internal::HeadingRotation(d, forward);
    truth[i].t.resize(d);
    for (int k = 0; k < d; ++k) truth[i].t[k] = options.spacing * path[i][k];
  }

  // Measurements.
  PoseGraph g;
  g.dimension = d;
  for (int i = 0; i < n; ++i) g.AddVertex(i);
  std::mt19937_64 rng(options.seed);
  auto add_measurement = [&](int i, int j) {
    internal::AddNoisyMeasurement(truth, i, j, options.kappa, options.tau, &rng,
                                  &g);
  };
  // The offset set is symmetric, so each unordered pair is met twice; it is
  // drawn once, from its later pose.
  const std::vector<LatticePoint> offsets =
      LoopClosureOffsets(d, options.loop_closure_radius);
  for (int j = 1; j < n; ++j) {
    add_measurement(j - 1, j);
    for (const LatticePoint& o : offsets) {
      LatticePoint q = path[j];
      bool inside = true;
      for (int k = 0; k < 3; ++k) {
        q[k] += o[k];
        inside = inside && q[k] >= 0 && (k >= d ? q[k] == 0 : q[k] < s);
      }
      if (!inside) continue;
      const int i = index_of_point[flat(q)];
      if (i >= j - 1) continue;  // later, or the odometry predecessor
      if (SampleUniform01(&rng) < p_lc) add_measurement(i, j);
    }
  }
  if (graph) *graph = std::move(g);
  if (ground_truth) *ground_truth = std::move(truth);
  return true;
}

}  // namespace ceres_sesync
