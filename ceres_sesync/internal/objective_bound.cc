#include "ceres_sesync/internal/objective_bound.h"

#include <cmath>

#include "ceres_sesync/internal/double_double.h"

namespace ceres_sesync::internal {
namespace {

// Accumulates the squared residual entries r = x - y - sum_k A(p, k) z(k)
// (y and A may be absent: null) into *value and their error bound into
// *error (see ObjectiveUpperBound).
struct ResidualBound {
  int d;
  double g;
  double value = 0, error = 0;
  void Add(double r, double magnitude) {
    const double entry_error = g * magnitude;
    value += r * r;
    error += 2 * std::abs(r) * entry_error + 2 * entry_error * entry_error;
  }
  // x - y - A z (the translation residuals).
  void Translation(const Eigen::VectorXd& x, const Eigen::VectorXd& y,
                   const Eigen::MatrixXd& A, const Eigen::VectorXd& z) {
    for (int p = 0; p < d; ++p) {
      double r = x(p) - y(p);
      double magnitude = std::abs(x(p)) + std::abs(y(p));
      for (int k = 0; k < d; ++k) {
        r -= A(p, k) * z(k);
        magnitude += std::abs(A(p, k) * z(k));
      }
      Add(r, magnitude);
    }
  }
};

}  // namespace

double ObjectiveUpperBound(const PoseGraph& graph, const Poses& poses,
                           const LandmarkPositions& landmarks,
                           const MeasurementWeights& weights) {
  const int d = graph.dimension;
  const double g = DoubleGamma(d + 2);
  double f = 0, error = 0;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Precisions w = WeightedPrecisions(e, weights, k);
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    // Rotation residual R_j - R_i R~: entries (p, q).
    ResidualBound rotation{d, g};
    for (int p = 0; p < d; ++p) {
      for (int q = 0; q < d; ++q) {
        double r = b.R(p, q), magnitude = std::abs(b.R(p, q));
        for (int k = 0; k < d; ++k) {
          r -= a.R(p, k) * e.R(k, q);
          magnitude += std::abs(a.R(p, k) * e.R(k, q));
        }
        rotation.Add(r, magnitude);
      }
    }
    // Translation residual t_j - t_i - R_i t~.
    ResidualBound translation{d, g};
    translation.Translation(b.t, a.t, a.R, e.t);
    f += w.kappa * rotation.value + w.tau * translation.value;
    error += w.kappa * rotation.error + w.tau * translation.error;
  }
  // Landmark residuals p_l - t_i - R_i z.
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    const double nu = WeightedPrecision(o, weights, LandmarkTerm(graph, q));
    const Pose& a = poses[o.i];
    ResidualBound translation{d, g};
    translation.Translation(landmarks[o.l], a.t, a.R, o.z);
    f += nu * translation.value;
    error += nu * translation.error;
  }
  // Prior residuals R_i - R~ and t_i - g.
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    const PosePrior& p = graph.priors[q];
    const Precisions w = WeightedPrecisions(p, weights, PriorTerm(graph, q));
    const Pose& a = poses[p.i];
    if (p.has_rotation()) {
      ResidualBound rotation{d, g};
      for (int q = 0; q < d * d; ++q) {
        rotation.Add(a.R(q) - p.R(q), std::abs(a.R(q)) + std::abs(p.R(q)));
      }
      f += w.kappa * rotation.value;
      error += w.kappa * rotation.error;
    }
    if (p.has_position()) {
      ResidualBound translation{d, g};
      for (int q = 0; q < d; ++q) {
        translation.Add(a.t(q) - p.t(q), std::abs(a.t(q)) + std::abs(p.t(q)));
      }
      f += w.tau * translation.value;
      error += w.tau * translation.error;
    }
  }
  // The sums (squares of entries, weights, terms) and this computation's
  // own rounding: gamma over all terms, relative to their (nonnegative)
  // values; the margin (1 + 1e-6) covers the rounding of the small terms.
  const double terms =
      (graph.measurements.size() + graph.landmark_measurements.size() +
       2.0 * graph.priors.size()) *
      (2.0 * d * d + 4);
  return f + (2 * DoubleGamma(terms) * (f + error) + error) * (1 + 1e-6);
}

double TotalPrecision(const PoseGraph& graph,
                      const MeasurementWeights& weights) {
  double total = 0;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const Precisions w = WeightedPrecisions(graph.measurements[k], weights, k);
    total += w.kappa + w.tau;
  }
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    total += WeightedPrecision(graph.landmark_measurements[q], weights,
                               LandmarkTerm(graph, q));
  }
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    const Precisions w =
        WeightedPrecisions(graph.priors[q], weights, PriorTerm(graph, q));
    total += w.kappa + w.tau;
  }
  return total;
}

}  // namespace ceres_sesync::internal
