#include "ceres_sesync/internal/objective_bound.h"

#include <cmath>
#include <limits>

namespace ceres_sesync::internal {
namespace {

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;

double Gamma(double k) { return k * kU / (1 - k * kU); }

}  // namespace

double ObjectiveUpperBound(const PoseGraph& graph, const Poses& poses,
                           const MeasurementWeights& weights) {
  const int d = graph.dimension;
  const double g = Gamma(d + 2);
  double f = 0, error = 0;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Precisions w = WeightedPrecisions(e, weights, k);
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    // Rotation residual R_j - R_i R~: entries (p, q).
    double rotation = 0, rotation_error = 0;
    for (int p = 0; p < d; ++p) {
      for (int q = 0; q < d; ++q) {
        double r = b.R(p, q), magnitude = std::abs(b.R(p, q));
        for (int k = 0; k < d; ++k) {
          r -= a.R(p, k) * e.R(k, q);
          magnitude += std::abs(a.R(p, k) * e.R(k, q));
        }
        const double entry_error = g * magnitude;
        rotation += r * r;
        rotation_error +=
            2 * std::abs(r) * entry_error + 2 * entry_error * entry_error;
      }
    }
    // Translation residual t_j - t_i - R_i t~.
    double translation = 0, translation_error = 0;
    for (int p = 0; p < d; ++p) {
      double r = b.t(p) - a.t(p);
      double magnitude = std::abs(b.t(p)) + std::abs(a.t(p));
      for (int k = 0; k < d; ++k) {
        r -= a.R(p, k) * e.t(k);
        magnitude += std::abs(a.R(p, k) * e.t(k));
      }
      const double entry_error = g * magnitude;
      translation += r * r;
      translation_error +=
          2 * std::abs(r) * entry_error + 2 * entry_error * entry_error;
    }
    f += w.kappa * rotation + w.tau * translation;
    error += w.kappa * rotation_error + w.tau * translation_error;
  }
  // The sums (squares of entries, weights, edges) and this computation's
  // own rounding: gamma over all terms, relative to their (nonnegative)
  // values; the margin (1 + 1e-6) covers the rounding of the small terms.
  const double terms = graph.measurements.size() * (2.0 * d * d + 4);
  return f + (2 * Gamma(terms) * (f + error) + error) * (1 + 1e-6);
}

}  // namespace ceres_sesync::internal
