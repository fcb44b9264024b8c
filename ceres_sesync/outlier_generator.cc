#include "ceres_sesync/outlier_generator.h"

#include <algorithm>
#include <cmath>
#include <random>

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

}  // namespace ceres_sesync
