#include "ceres_sesync/langevin.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace ceres_sesync {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Wraps an angle to [-pi, pi].
double WrapAngle(double theta) { return std::remainder(theta, 2 * kPi); }

// e^-x I_nu(x) for nu in {0, 1} and x > 50 from the asymptotic expansion
// (DLMF 10.40.1); the terms decrease down to ~1e-40 relative at x = 50.
double ScaledBesselIAsymptotic(int nu, double x) {
  const double mu = 4.0 * nu * nu;
  double term = 1, sum = 1;
  for (int k = 1; k <= 30; ++k) {
    const double odd = 2.0 * k - 1;
    term *= -(mu - odd * odd) / (k * 8.0 * x);
    sum += term;
    if (std::abs(term) < 1e-17 * std::abs(sum)) break;
  }
  return sum / std::sqrt(2 * kPi * x);
}

}  // namespace

double SampleUniform01(std::mt19937_64* rng) {
  // The top 53 bits of a 64-bit word, scaled by 2^-53.
  return static_cast<double>((*rng)() >> 11) * 0x1.0p-53;
}

double SampleStandardNormal(std::mt19937_64* rng) {
  while (true) {
    const double u = 2 * SampleUniform01(rng) - 1;
    const double v = 2 * SampleUniform01(rng) - 1;
    const double s = u * u + v * v;
    if (s > 0 && s < 1) return u * std::sqrt(-2 * std::log(s) / s);
  }
}

double SampleVonMises(double mu, double concentration, std::mt19937_64* rng) {
  const double k = concentration;
  if (!(k >= 0) || !std::isfinite(mu)) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (std::isinf(k)) return WrapAngle(mu);
  // Below 1e-12 the density differs from uniform by < 1e-12 relative.
  if (k < 1e-12) return WrapAngle(mu + kPi * (2 * SampleUniform01(rng) - 1));

  // Best & Fisher (1979): a wrapped-Cauchy envelope with parameter rho,
  // r = (1 + rho^2) / (2 rho). We keep r - 1 and 1 - f (f = cos of the
  // proposed angle) explicitly: both are tiny for large k and would be lost
  // to cancellation in the textbook form.
  const double sq = std::sqrt(1 + 4 * k * k);
  const double tau = 1 + sq;
  const double rho = 2 * k * tau / ((sq + 1) * (tau + std::sqrt(2 * tau)));
  double one_minus_rho;
  if (k >= 1) {
    one_minus_rho = (std::sqrt(2 * tau) - 1 - 1 / (2 * k + sq)) / (2 * k);
  } else {
    one_minus_rho = 1 - rho;
  }
  const double r_minus_1 = one_minus_rho * one_minus_rho / (2 * rho);

  while (true) {
    const double u1 = SampleUniform01(rng);
    const double u2 = SampleUniform01(rng);
    const double u3 = SampleUniform01(rng);
    // z = cos(pi u1): 1 + z = 2 cos^2(pi u1 / 2), 1 - z = 2 sin^2(pi u1 / 2).
    const double h = 0.5 * kPi * u1;
    const double one_plus_z = 2 * std::cos(h) * std::cos(h);
    const double one_minus_z = 2 * std::sin(h) * std::sin(h);
    const double r_plus_z = r_minus_1 + one_plus_z;
    if (!(r_plus_z > 0)) continue;
    // f = (1 + r z) / (r + z)  =>  1 - f = (r - 1)(1 - z) / (r + z).
    const double one_minus_f =
        std::min(2.0, r_minus_1 * one_minus_z / r_plus_z);
    const double c = k * (r_minus_1 + one_minus_f);  // k (r - f)
    const bool accept =
        c * (2 - c) - u2 > 0 || u2 == 0 || std::log(c / u2) + 1 - c >= 0;
    if (!accept) continue;
    // acos(f) = 2 asin(sqrt((1 - f) / 2)), accurate near f = 1.
    const double angle = 2 * std::asin(std::sqrt(0.5 * one_minus_f));
    return WrapAngle(u3 < 0.5 ? mu - angle : mu + angle);
  }
}

Eigen::MatrixXd SampleIsotropicLangevin(int d, double kappa,
                                        std::mt19937_64* rng) {
  if ((d != 2 && d != 3) || !(kappa >= 0)) return Eigen::MatrixXd();
  const double theta = SampleVonMises(0, 2 * kappa, rng);
  const double c = std::cos(theta), s = std::sin(theta);
  if (d == 2) {
    Eigen::MatrixXd P(2, 2);
    P << c, -s, s, c;
    return P;
  }
  // Axis uniform on S^2 (Archimedes: z uniform on [-1, 1], azimuth uniform).
  const double z = 2 * SampleUniform01(rng) - 1;
  const double phi = 2 * kPi * SampleUniform01(rng);
  const double rho = std::sqrt(std::max(0.0, 1 - z * z));
  const Eigen::Vector3d v(rho * std::cos(phi), rho * std::sin(phi), z);
  Eigen::Matrix3d K;
  K << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  // Rodrigues: exp(theta [v]x) = I + sin(theta) K + (1 - cos(theta)) K^2,
  // with 1 - cos(theta) = 2 sin^2(theta / 2) for accuracy at small angles.
  const double half_sin = std::sin(0.5 * theta);
  const Eigen::Matrix3d P =
      Eigen::Matrix3d::Identity() + s * K + 2 * half_sin * half_sin * K * K;
  return P;
}

double VonMisesMeanCosine(double concentration) {
  const double x = concentration;
  if (!(x >= 0)) return std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(x)) return 1;
  if (x == 0) return 0;
  if (x <= 50) return std::cyl_bessel_i(1.0, x) / std::cyl_bessel_i(0.0, x);
  return ScaledBesselIAsymptotic(1, x) / ScaledBesselIAsymptotic(0, x);
}

double LangevinAngularStandardDeviation(double kappa) {
  if (!(kappa >= 0)) return std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(kappa)) return 0;
  // SD^2 = int theta^2 w / int w with w = exp(2 kappa (cos theta - 1)) (the
  // normalizer 2 pi I0(2 kappa) equals int w up to the same e^{2 kappa}
  // factor). The integrand is even; beyond 40 standard deviations w is
  // below e^-800, so integrate [0, L] with L = min(pi, 40 / sqrt(2 kappa)).
  const double length =
      kappa > 0 ? std::min(kPi, 40 / std::sqrt(2 * kappa)) : kPi;
  const int intervals = 20000;  // even, for Simpson's rule
  const double h = length / intervals;
  double numerator = 0, denominator = 0;
  for (int i = 0; i <= intervals; ++i) {
    const double theta = i * h;
    // cos(theta) - 1 = -2 sin^2(theta / 2), exact near 0.
    const double half_sin = std::sin(0.5 * theta);
    const double w = std::exp(-4 * kappa * half_sin * half_sin);
    const double weight = (i == 0 || i == intervals) ? 1 : (i % 2 ? 4 : 2);
    numerator += weight * theta * theta * w;
    denominator += weight * w;
  }
  return std::sqrt(numerator / denominator);
}

}  // namespace ceres_sesync
