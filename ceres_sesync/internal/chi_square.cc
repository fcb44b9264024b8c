#include "ceres_sesync/internal/chi_square.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ceres_sesync::internal {

double ChiSquareCdf(double x, int k) {
  if (!(x > 0)) return 0;
  if (std::isinf(x)) return 1;
  const double h = x / 2;
  double sum = 0;
  if (k % 2 == 0) {  // P(m, h) = 1 - e^-h sum_{i<m} h^i / i!, m = k/2.
    double term = 1;
    for (int i = 0; i < k / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return std::max(0.0, 1 - std::exp(-h) * sum);
  }
  // Odd k: P(1/2, h) = erf(sqrt h), P(a + 1, h) = P(a, h) - h^a e^-h /
  // Gamma(a + 1) for a = 1/2, 3/2, ..., k/2 - 1.
  double term = std::sqrt(h) / std::tgamma(1.5);  // a = 1/2.
  for (int j = 0; j < (k - 1) / 2; ++j) {
    sum += term;
    term *= h / (j + 1.5);  // Gamma(a + 2) = (a + 1) Gamma(a + 1).
  }
  return std::max(0.0, std::erf(std::sqrt(h)) - std::exp(-h) * sum);
}

double ChiSquareQuantile(double p, int k) {
  if (!(p > 0 && p < 1) || k < 1) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  double lo = 0, hi = k + 10.0;
  while (ChiSquareCdf(hi, k) < p) hi *= 2;
  for (int it = 0; it < 200 && hi - lo > 4e-16 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareCdf(mid, k) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace ceres_sesync::internal
