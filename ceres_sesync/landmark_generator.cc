#include "ceres_sesync/landmark_generator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ceres_sesync/internal/synthetic_graph.h"
#include "ceres_sesync/langevin.h"

namespace ceres_sesync {
namespace {

constexpr int kMaxCount = 10000000;

// An integer in [0, k) from the portable uniform sampler.
int SampleIndex(int k, std::mt19937_64* rng) {
  return std::min(k - 1, static_cast<int>(SampleUniform01(rng) * k));
}

// Lattice points of the walk (in steps), pose by pose (see the header).
struct Walk {
  std::vector<std::array<int, 3>> points;
  std::vector<std::array<int, 3>> headings;  // Unit axis vector per pose.
};

Walk ManhattanWalk(const LandmarkGraphOptions& o, std::mt19937_64* rng) {
  const int d = o.dimension, B = o.block_length;
  // Largest |coordinate| (in steps) of an intersection inside the box.
  const int reach = static_cast<int>(
      std::floor(o.world_size / 2 / (o.step_length * B) + 1e-9));
  auto inside = [&](const std::array<int, 3>& p, const std::array<int, 3>& h) {
    for (int k = 0; k < d; ++k) {
      const int next = p[k] + B * h[k];  // The next intersection.
      if (next < -reach * B || next > reach * B) return false;
    }
    return true;
  };
  Walk walk;
  std::array<int, 3> p = {0, 0, 0}, h = {1, 0, 0};
  for (int i = 0; i < o.num_poses; ++i) {
    const bool intersection = p[0] % B == 0 && p[1] % B == 0 && p[2] % B == 0;
    if (intersection) {
      std::vector<std::array<int, 3>> turns;
      for (int axis = 0; axis < d; ++axis) {
        if (h[axis] != 0) continue;  // Straight or reverse.
        for (int sign : {-1, 1}) {
          std::array<int, 3> t = {0, 0, 0};
          t[axis] = sign;
          if (inside(p, t)) turns.push_back(t);
        }
      }
      const bool straight = inside(p, h);
      // reach >= 1 (checked), so at least one turn is always possible.
      if (!turns.empty() &&
          (!straight || SampleUniform01(rng) < o.turn_probability)) {
        h = turns[SampleIndex(static_cast<int>(turns.size()), rng)];
      }
    }
    walk.points.push_back(p);
    walk.headings.push_back(h);
    for (int k = 0; k < 3; ++k) p[k] += h[k];
  }
  return walk;
}

Eigen::VectorXd GaussianNoise(int d, double precision, bool noiseless,
                              std::mt19937_64* rng) {
  Eigen::VectorXd v = Eigen::VectorXd::Zero(d);
  if (noiseless) return v;
  const double sigma = 1 / std::sqrt(precision);
  for (int k = 0; k < d; ++k) v[k] = sigma * SampleStandardNormal(rng);
  return v;
}

Eigen::MatrixXd LangevinNoise(int d, double kappa, bool noiseless,
                              std::mt19937_64* rng) {
  if (noiseless) return Eigen::MatrixXd::Identity(d, d);
  return SampleIsotropicLangevin(d, kappa, rng);
}

bool PositiveFinite(double x) { return x > 0 && std::isfinite(x); }

double RotationTermExpectation(double kappa) {
  return 4 * kappa * (1 - VonMisesMeanCosine(2 * kappa));
}

}  // namespace

LandmarkGraphOptions VictoriaParkLikeOptions() {
  LandmarkGraphOptions o;
  o.dimension = 2;
  o.num_poses = 2000;
  o.step_length = 0.5;
  o.block_length = 20;
  o.turn_probability = 0.5;
  o.world_size = 120;
  o.num_landmarks = 1500;
  o.sensor_range = 12;
  o.detection_probability = 0.8;
  return o;
}

bool GenerateLandmarkGraph(const LandmarkGraphOptions& o, PoseGraph* graph,
                           Solution* ground_truth, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const int d = o.dimension;
  if (d != 2 && d != 3) return fail("dimension must be 2 or 3");
  if (o.num_poses < 2 || o.num_poses > kMaxCount) {
    return fail("num_poses must be in [2, 10^7]");
  }
  if (o.num_landmarks < 1 || o.num_landmarks > kMaxCount) {
    return fail("num_landmarks must be in [1, 10^7]");
  }
  if (!PositiveFinite(o.step_length)) {
    return fail("step_length must be finite and positive");
  }
  if (o.block_length < 1) return fail("block_length must be at least 1");
  if (!(o.turn_probability >= 0 && o.turn_probability <= 1)) {
    return fail("turn_probability must be in [0, 1]");
  }
  if (!(std::isfinite(o.world_size) &&
        o.world_size >= 2 * o.block_length * o.step_length)) {
    return fail(
        "world_size must be finite and at least 2 block_length step_length "
        "(one block each way from the start)");
  }
  if (!PositiveFinite(o.sensor_range)) {
    return fail("sensor_range must be finite and positive");
  }
  if (!(o.detection_probability > 0 && o.detection_probability <= 1)) {
    return fail("detection_probability must be in (0, 1]");
  }
  if (o.max_observations_per_pose < 0) {
    return fail("max_observations_per_pose must be >= 0 (0: no limit)");
  }
  if (!PositiveFinite(o.kappa) || !PositiveFinite(o.tau)) {
    return fail("kappa and tau must be finite and positive");
  }
  if (!PositiveFinite(o.landmark_nu)) {
    return fail("landmark_nu must be finite and positive");
  }
  if (o.gps_interval < 0) return fail("gps_interval must be >= 0 (0: none)");
  if (!PositiveFinite(o.gps_tau)) {
    return fail("gps_tau must be finite and positive");
  }
  if (o.start_prior && (!PositiveFinite(o.start_prior_kappa) ||
                        !PositiveFinite(o.start_prior_tau))) {
    return fail(
        "start_prior_kappa and start_prior_tau must be finite and "
        "positive");
  }
  const int n = o.num_poses;
  std::mt19937_64 rng(o.seed);

  // Ground-truth poses along the walk.
  const Walk walk = ManhattanWalk(o, &rng);
  Solution truth;
  truth.poses.resize(n);
  for (int i = 0; i < n; ++i) {
    const int a = i + 1 < n ? i : i - 1;  // Heading of the step a -> a + 1.
    Eigen::Vector3d forward;
    for (int k = 0; k < 3; ++k) forward[k] = walk.headings[a][k];
    truth.poses[i].R = internal::HeadingRotation(d, forward);
    truth.poses[i].t.resize(d);
    for (int k = 0; k < d; ++k) {
      truth.poses[i].t[k] = o.step_length * walk.points[i][k];
    }
  }

  PoseGraph g;
  g.dimension = d;
  for (int i = 0; i < n; ++i) g.AddVertex(i);
  for (int i = 1; i < n; ++i) {
    const Pose& a = truth.poses[i - 1];
    const Pose& b = truth.poses[i];
    RelativePoseMeasurement e;
    e.i = i - 1;
    e.j = i;
    e.kappa = o.kappa;
    e.tau = o.tau;
    e.R = a.R.transpose() * b.R * LangevinNoise(d, o.kappa, o.noiseless, &rng);
    e.t = a.R.transpose() * (b.t - a.t) +
          GaussianNoise(d, o.tau, o.noiseless, &rng);
    g.measurements.push_back(std::move(e));
  }

  // Landmarks, bucketed in cubes of side sensor_range.
  const double half = o.world_size / 2 + o.sensor_range;
  std::vector<Eigen::VectorXd> points(o.num_landmarks, Eigen::VectorXd(d));
  for (Eigen::VectorXd& p : points) {
    for (int k = 0; k < d; ++k) p[k] = -half + 2 * half * SampleUniform01(&rng);
  }
  const double cell = o.sensor_range;
  auto cell_of = [&](const Eigen::VectorXd& x) {
    std::array<int64_t, 3> c = {0, 0, 0};
    for (int k = 0; k < d; ++k) {
      c[k] = static_cast<int64_t>(std::floor((x[k] + half) / cell));
    }
    return c;
  };
  // Unsigned arithmetic: wraps instead of overflowing; a collision only
  // merges buckets (distances are checked anyway).
  auto key_of = [](const std::array<int64_t, 3>& c) {
    return (static_cast<uint64_t>(c[0]) * 1000003u +
            static_cast<uint64_t>(c[1])) *
               1000033u +
           static_cast<uint64_t>(c[2]);
  };
  std::unordered_map<uint64_t, std::vector<int>> buckets;
  for (int l = 0; l < o.num_landmarks; ++l) {
    buckets[key_of(cell_of(points[l]))].push_back(l);
  }

  // Observations.
  std::vector<int> dense(o.num_landmarks, -1);
  const double range2 = o.sensor_range * o.sensor_range;
  std::vector<std::pair<double, int>> seen;  // (squared distance, landmark)
  for (int i = 0; i < n; ++i) {
    const Pose& x = truth.poses[i];
    const std::array<int64_t, 3> c = cell_of(x.t);
    seen.clear();
    const int reach_z = d == 3 ? 1 : 0;
    for (int64_t dx = -1; dx <= 1; ++dx) {
      for (int64_t dy = -1; dy <= 1; ++dy) {
        for (int64_t dz = -reach_z; dz <= reach_z; ++dz) {
          const auto it =
              buckets.find(key_of({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == buckets.end()) continue;
          for (int l : it->second) {
            const double r2 = (points[l] - x.t).squaredNorm();
            if (r2 <= range2) seen.emplace_back(r2, l);
          }
        }
      }
    }
    // Candidates in landmark order, so that the random stream does not
    // depend on the bucket layout.
    std::sort(seen.begin(), seen.end(),
              [](const auto& a, const auto& b) { return a.second < b.second; });
    std::vector<std::pair<double, int>> detected;
    for (const auto& candidate : seen) {
      if (o.detection_probability >= 1 ||
          SampleUniform01(&rng) < o.detection_probability) {
        detected.push_back(candidate);
      }
    }
    if (o.max_observations_per_pose > 0 &&
        static_cast<int>(detected.size()) > o.max_observations_per_pose) {
      std::stable_sort(
          detected.begin(), detected.end(),
          [](const auto& a, const auto& b) { return a.first < b.first; });
      detected.resize(o.max_observations_per_pose);
      std::sort(
          detected.begin(), detected.end(),
          [](const auto& a, const auto& b) { return a.second < b.second; });
    }
    for (const auto& [r2, l] : detected) {
      if (dense[l] < 0) {
        dense[l] = g.AddLandmark(n + g.num_landmarks);
        truth.landmarks.push_back(points[l]);
      }
      LandmarkMeasurement m;
      m.i = i;
      m.l = dense[l];
      m.nu = o.landmark_nu;
      m.z = x.R.transpose() * (points[l] - x.t) +
            GaussianNoise(d, o.landmark_nu, o.noiseless, &rng);
      g.landmark_measurements.push_back(std::move(m));
    }
  }

  // Priors.
  if (o.start_prior) {
    PosePrior p;
    p.i = 0;
    p.kappa = o.start_prior_kappa;
    p.tau = o.start_prior_tau;
    p.R = truth.poses[0].R *
          LangevinNoise(d, o.start_prior_kappa, o.noiseless, &rng);
    p.t = truth.poses[0].t +
          GaussianNoise(d, o.start_prior_tau, o.noiseless, &rng);
    g.priors.push_back(std::move(p));
  }
  if (o.gps_interval > 0) {
    for (int i = 0; i < n; i += o.gps_interval) {
      PosePrior p;
      p.i = i;
      p.tau = o.gps_tau;
      p.t = truth.poses[i].t + GaussianNoise(d, o.gps_tau, o.noiseless, &rng);
      g.priors.push_back(std::move(p));
    }
  }
  if (graph) *graph = std::move(g);
  if (ground_truth) *ground_truth = std::move(truth);
  return true;
}

double ExpectedGroundTruthObjective(const PoseGraph& graph) {
  const int d = graph.dimension;
  double f = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    f += RotationTermExpectation(e.kappa) + d;
  }
  f += static_cast<double>(d) * graph.landmark_measurements.size();
  for (const PosePrior& p : graph.priors) {
    if (p.has_rotation()) f += RotationTermExpectation(p.kappa);
    if (p.has_position()) f += d;
  }
  return f;
}

}  // namespace ceres_sesync
