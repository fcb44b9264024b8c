#include "ceres_sesync/outlier_generator.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "Eigen/Geometry"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/robust_solver.h"

namespace ceres_sesync {
namespace {

constexpr double kPi = 3.14159265358979323846;

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

// A uniform integer in [0, n), from raw words (bias below 2^-40 for the
// sizes here).
int UniformIndex(int n, std::mt19937_64* rng) {
  return std::min(n - 1, static_cast<int>(SampleUniform01(rng) * n));
}

// A Haar-uniform rotation: a uniform angle (2D) or a normalized Gaussian
// quaternion (3D).
Eigen::MatrixXd RandomRotation(int d, std::mt19937_64* rng) {
  if (d == 2) {
    const double theta = kPi * (2 * SampleUniform01(rng) - 1);
    Eigen::MatrixXd R(2, 2);
    R << std::cos(theta), -std::sin(theta), std::sin(theta), std::cos(theta);
    return R;
  }
  Eigen::Vector4d q;
  do {
    for (int k = 0; k < 4; ++k) q[k] = SampleStandardNormal(rng);
  } while (q.norm() < 1e-6);
  q.normalize();
  return Eigen::Quaterniond(q[3], q[0], q[1], q[2]).toRotationMatrix();
}

// Uniform in the ball of radius rho in R^d.
Eigen::VectorXd RandomTranslation(int d, double rho, std::mt19937_64* rng) {
  Eigen::VectorXd v(d);
  do {
    for (int k = 0; k < d; ++k) v[k] = SampleStandardNormal(rng);
  } while (v.norm() < 1e-6);
  return v.normalized() * (rho * std::pow(SampleUniform01(rng), 1.0 / d));
}

// The reference trajectory for consistent clusters: the initial poses, else
// dead reckoning along odometry (false if a consecutive pair has none).
bool ReferenceTrajectory(const PoseGraph& graph, Poses* poses) {
  if (!graph.initial_poses.empty()) {
    *poses = graph.initial_poses;
    return true;
  }
  const int n = graph.num_poses, d = graph.dimension;
  std::vector<int> step(n, -1);  // Measurement between i and i + 1.
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const int low = std::min(e.i, e.j);
    if (IsOdometry(e) && step[low] < 0) step[low] = static_cast<int>(k);
  }
  *poses = IdentityPoses(d, n);
  for (int i = 0; i + 1 < n; ++i) {
    if (step[i] < 0) return false;
    const RelativePoseMeasurement& e = graph.measurements[step[i]];
    const Pose& a = (*poses)[i];
    Pose& b = (*poses)[i + 1];
    if (e.i == i) {  // x_{i+1} = x_i x~
      b.R = a.R * e.R;
      b.t = a.t + a.R * e.t;
    } else {  // x_i = x_{i+1} x~  =>  x_{i+1} = x_i x~^-1
      b.R = a.R * e.R.transpose();
      b.t = a.t - b.R * e.t;
    }
  }
  return true;
}

// Moves dead-reckoned poses rigidly onto the graph's position priors (least
// squares over the prior positions: Kabsch's rotation with det +1, then the
// translation), so that they are in the priors' world frame. Fewer than two
// position priors: the translation only (none: unchanged).
void AlignToPositionPriors(const PoseGraph& graph, Poses* poses) {
  const int d = graph.dimension;
  std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> pairs;
  for (const PosePrior& p : graph.priors) {
    if (p.has_position()) pairs.emplace_back((*poses)[p.i].t, p.t);
  }
  if (pairs.empty()) return;
  Eigen::VectorXd mean_a = Eigen::VectorXd::Zero(d), mean_b = mean_a;
  for (const auto& [a, b] : pairs) {
    mean_a += a / pairs.size();
    mean_b += b / pairs.size();
  }
  Eigen::MatrixXd R = Eigen::MatrixXd::Identity(d, d);
  if (pairs.size() >= 2) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(d, d);
    for (const auto& [a, b] : pairs)
      H += (b - mean_b) * (a - mean_a).transpose();
    R = internal::ProjectToRotation(H);
  }
  const Eigen::VectorXd t = mean_b - R * mean_a;
  for (Pose& x : *poses) {
    x.R = R * x.R;
    x.t = R * x.t + t;
  }
}

}  // namespace

bool AddOutliers(const PoseGraph& graph, const OutlierOptions& options,
                 PoseGraph* corrupted, std::vector<int>* outlier_indices,
                 std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!(options.fraction >= 0 && options.fraction < 1)) {
    return fail("the outlier fraction must be in [0, 1)");
  }
  const bool clustered = options.mode == OutlierOptions::Mode::kClustered;
  if (clustered && options.cluster_size < 1) {
    return fail("the cluster size must be >= 1");
  }
  std::string why;
  if (!ValidatePoseGraph(graph, &why)) return fail("invalid graph: " + why);
  const int d = graph.dimension, n = graph.num_poses;
  std::vector<double> kappas, taus;
  double rho = 0, rho_all = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    rho_all = std::max(rho_all, e.t.norm());
    if (IsOdometry(e)) continue;
    kappas.push_back(e.kappa);
    taus.push_back(e.tau);
    rho = std::max(rho, e.t.norm());
  }
  const int loop_closures = static_cast<int>(kappas.size());
  if (loop_closures == 0) {
    return fail(
        "the graph has no loop closures (the outlier fraction is relative "
        "to them)");
  }
  const int span = clustered ? options.cluster_size : 1;
  if (n < span + 2) {
    return fail(
        "the graph has too few poses (" + std::to_string(n) + ") for outliers" +
        (clustered ? " in clusters of " + std::to_string(options.cluster_size)
                   : std::string()));
  }
  Poses reference;
  if (clustered && !ReferenceTrajectory(graph, &reference)) {
    return fail(
        "clustered outliers need a reference trajectory: the graph has no "
        "initial poses and its odometry chain is incomplete");
  }
  if (rho == 0) rho = rho_all;
  rho = std::max(rho, 1e-3);
  const double kappa = Median(kappas), tau = Median(taus);
  const int count = static_cast<int>(
      std::lround(options.fraction * loop_closures / (1 - options.fraction)));

  PoseGraph out = graph;
  out.measurements.reserve(graph.measurements.size() + count);
  std::mt19937_64 rng(options.seed);
  std::vector<int> added;
  added.reserve(count);
  auto add = [&](int i, int j, const Eigen::MatrixXd& R,
                 const Eigen::VectorXd& t) {
    RelativePoseMeasurement e;
    e.i = i;
    e.j = j;
    e.R = internal::ProjectToRotation(R);
    e.t = t;
    e.kappa = kappa;
    e.tau = tau;
    added.push_back(static_cast<int>(out.measurements.size()));
    out.measurements.push_back(std::move(e));
  };
  while (static_cast<int>(added.size()) < count) {
    // Two distinct, non-consecutive starts whose segments fit.
    int a, b;
    do {
      a = UniformIndex(n - span + 1, &rng);
      b = UniformIndex(n - span + 1, &rng);
    } while (std::abs(a - b) < 2);
    const Eigen::MatrixXd R = RandomRotation(d, &rng);
    const Eigen::VectorXd t = RandomTranslation(d, rho, &rng);
    if (!clustered) {
      add(a, b, R, t);
      continue;
    }
    // X_a T X_b^-1: where the segment around b is placed.
    const Pose& xa = reference[a];
    const Pose& xb = reference[b];
    const Eigen::MatrixXd M_R = xa.R * R * xb.R.transpose();
    const Eigen::VectorXd M_t = xa.R * t + xa.t - M_R * xb.t;
    for (int s = 0; s < span && static_cast<int>(added.size()) < count; ++s) {
      const Pose& p = reference[a + s];
      const Pose& q = reference[b + s];
      // X_p^-1 M X_q.
      add(a + s, b + s, p.R.transpose() * M_R * q.R,
          p.R.transpose() * (M_R * q.t + M_t - p.t));
    }
  }
  *corrupted = std::move(out);
  if (outlier_indices) *outlier_indices = std::move(added);
  return true;
}

bool AddLandmarkOutliers(const PoseGraph& graph,
                         const LandmarkOutlierOptions& options,
                         PoseGraph* corrupted,
                         std::vector<int>* landmark_outliers,
                         std::vector<int>* prior_outliers, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const double f_l = options.landmark_fraction, f_p = options.prior_fraction;
  if (!(f_l >= 0 && f_l < 1) || !(f_p >= 0 && f_p < 1)) {
    return fail("the outlier fractions must be in [0, 1)");
  }
  std::string why;
  if (!ValidatePoseGraph(graph, &why)) return fail("invalid graph: " + why);
  const int d = graph.dimension, n = graph.num_poses;
  const int M = static_cast<int>(graph.landmark_measurements.size());
  if (f_l > 0 && graph.num_landmarks < 2) {
    return fail("wrong landmark associations need at least two landmarks");
  }
  std::vector<double> taus;
  for (const PosePrior& p : graph.priors) {
    if (p.has_position()) taus.push_back(p.tau);
  }
  const int P = static_cast<int>(taus.size());
  Poses reference;
  if (f_p > 0) {
    if (P == 0) {
      return fail(
          "false position fixes need position priors (the fraction is "
          "relative to them)");
    }
    if (!ReferenceTrajectory(graph, &reference)) {
      return fail(
          "false position fixes need a reference trajectory: the graph has "
          "no initial poses and its odometry chain is incomplete");
    }
    if (graph.initial_poses.empty()) AlignToPositionPriors(graph, &reference);
  }
  PoseGraph out = graph;
  std::mt19937_64 rng(options.seed);
  std::vector<int> added_l, added_p;
  const int count_l = static_cast<int>(std::lround(f_l * M / (1 - f_l)));
  const int64_t L = graph.num_landmarks;
  if (count_l > L * (L - 1)) {
    return fail("too many wrong associations for " + std::to_string(L) +
                " landmarks (each pair of landmarks is used once)");
  }
  std::set<int64_t> pairs;  // l * L + l' of the wrong associations so far.
  while (static_cast<int>(added_l.size()) < count_l) {
    LandmarkMeasurement o = graph.landmark_measurements[UniformIndex(M, &rng)];
    // Another landmark, uniformly.
    const int other = UniformIndex(graph.num_landmarks - 1, &rng);
    const int l = other < o.l ? other : other + 1;
    if (!pairs.insert(o.l * L + l).second) continue;
    o.l = l;
    added_l.push_back(static_cast<int>(out.landmark_measurements.size()));
    out.landmark_measurements.push_back(std::move(o));
  }
  const int count_p = static_cast<int>(std::lround(f_p * P / (1 - f_p)));
  if (count_p > 0) {
    const double tau = Median(taus);
    const double sigma = 1 / std::sqrt(tau);
    for (int k = 0; k < count_p; ++k) {
      PosePrior p;
      p.i = UniformIndex(n, &rng);
      Eigen::VectorXd u = RandomTranslation(d, 1.0, &rng);
      u.normalize();
      p.t = reference[p.i].t + u * (sigma * (10 + 30 * SampleUniform01(&rng)));
      p.tau = tau;
      added_p.push_back(static_cast<int>(out.priors.size()));
      out.priors.push_back(std::move(p));
    }
  }
  *corrupted = std::move(out);
  if (landmark_outliers) *landmark_outliers = std::move(added_l);
  if (prior_outliers) *prior_outliers = std::move(added_p);
  return true;
}

}  // namespace ceres_sesync
