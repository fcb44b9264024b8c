// Statistical tests of the von Mises and isotropic Langevin samplers against
// closed forms (Bessel ratios, the paper's eq. 63) and of the quadrature of
// eq. (63) against the numbers the paper states.
//
// Statistical tolerances: sample means are compared with their expectation
// within 5 estimated standard errors (a false alarm rate of ~6e-7 per check
// for a correct sampler; the seeds are fixed, so the tests are
// deterministic).

#include "ceres_sesync/langevin.h"

#include <cmath>
#include <random>
#include <vector>

#include "Eigen/LU"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegree = kPi / 180;

// Mean and standard error of a sample.
struct Moments {
  double mean = 0;
  double standard_error = 0;
};
Moments ComputeMoments(const std::vector<double>& x) {
  double sum = 0, sum2 = 0;
  for (double v : x) sum += v;
  const double mean = sum / x.size();
  for (double v : x) sum2 += (v - mean) * (v - mean);
  const double variance = sum2 / (x.size() - 1);
  return {mean, std::sqrt(variance / x.size())};
}

void ExpectWithinStandardErrors(const Moments& m, double expected,
                                const char* what) {
  EXPECT_LE(std::abs(m.mean - expected), 5 * m.standard_error + 1e-15)
      << what << ": sample mean " << m.mean << " expected " << expected
      << " standard error " << m.standard_error;
}

TEST(VonMisesMeanCosine, MatchesBesselRatio) {
  // Both branches (cyl_bessel_i ratio below 50, asymptotic series above)
  // against std::cyl_bessel_i directly, which is finite up to ~700.
  for (double x : {0.1, 1.0, 10.0, 49.0, 50.5, 60.0, 200.0, 600.0}) {
    const double expected =
        std::cyl_bessel_i(1.0, x) / std::cyl_bessel_i(0.0, x);
    EXPECT_NEAR(VonMisesMeanCosine(x), expected, 1e-13 * expected) << x;
  }
  EXPECT_EQ(VonMisesMeanCosine(0), 0);
  // Large argument: I1/I0 = 1 - 1/(2x) - 1/(8x^2) + O(x^-3).
  const double x = 1e8;
  EXPECT_NEAR(VonMisesMeanCosine(x), 1 - 1 / (2 * x) - 1 / (8 * x * x), 1e-15);
  EXPECT_TRUE(std::isnan(VonMisesMeanCosine(-1)));
}

TEST(SampleVonMises, MeanCosineIsBesselRatio) {
  std::mt19937_64 rng(1);
  const int kSamples = 200000;
  for (double concentration : {0.5, 2.0, 33.34, 300.0}) {
    for (double mu : {0.0, 2.5}) {
      std::vector<double> cosines(kSamples), sines(kSamples);
      for (int s = 0; s < kSamples; ++s) {
        const double theta = SampleVonMises(mu, concentration, &rng);
        ASSERT_GE(theta, -kPi);
        ASSERT_LE(theta, kPi);
        cosines[s] = std::cos(theta - mu);
        sines[s] = std::sin(theta - mu);
      }
      SCOPED_TRACE(concentration);
      ExpectWithinStandardErrors(ComputeMoments(cosines),
                                 std::cyl_bessel_i(1.0, concentration) /
                                     std::cyl_bessel_i(0.0, concentration),
                                 "E cos");
      ExpectWithinStandardErrors(ComputeMoments(sines), 0, "E sin");
    }
  }
}

TEST(SampleVonMises, HistogramMatchesDensity) {
  // Pearson chi-square over 24 equal bins of [-pi, pi] at concentration 2;
  // bin probabilities by Simpson quadrature of the density (59). With 23
  // degrees of freedom the statistic has mean 23 and sd 6.8; 60 is ~5.5 sd.
  const double k = 2;
  const int kBins = 24, kSamples = 240000;
  std::vector<double> counts(kBins, 0);
  std::mt19937_64 rng(7);
  for (int s = 0; s < kSamples; ++s) {
    const double theta = SampleVonMises(0, k, &rng);
    const int bin = std::min(
        kBins - 1, static_cast<int>((theta + kPi) / (2 * kPi) * kBins));
    counts[bin] += 1;
  }
  const double normalizer = 2 * kPi * std::cyl_bessel_i(0.0, k);
  double chi2 = 0;
  for (int b = 0; b < kBins; ++b) {
    const double lo = -kPi + 2 * kPi * b / kBins;
    const double width = 2 * kPi / kBins;
    const int kSteps = 200;
    double integral = 0;
    for (int i = 0; i <= kSteps; ++i) {
      const double w = (i == 0 || i == kSteps) ? 1 : (i % 2 ? 4 : 2);
      integral += w * std::exp(k * std::cos(lo + width * i / kSteps));
    }
    const double p = integral * width / (3 * kSteps) / normalizer;
    const double expected = p * kSamples;
    chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
  }
  EXPECT_LT(chi2, 60);
}

TEST(SampleVonMises, LargeConcentrationIsGaussian) {
  // For concentration 1e12 the distribution is N(0, 1e-12) to ~1e-12
  // relative (eq. 62): E[k theta^2] = 1 and E[theta] = 0. This exercises the
  // cancellation-free arithmetic of the sampler (a textbook Best-Fisher loses
  // all digits of such angles).
  const double k = 1e12;
  std::mt19937_64 rng(3);
  const int kSamples = 100000;
  std::vector<double> scaled_square(kSamples), scaled(kSamples);
  for (int s = 0; s < kSamples; ++s) {
    const double theta = SampleVonMises(0, k, &rng);
    scaled_square[s] = k * theta * theta;
    scaled[s] = std::sqrt(k) * theta;
  }
  ExpectWithinStandardErrors(ComputeMoments(scaled_square), 1, "E k theta^2");
  ExpectWithinStandardErrors(ComputeMoments(scaled), 0, "E sqrt(k) theta");
}

TEST(SampleVonMises, EdgeCases) {
  std::mt19937_64 rng(5);
  // Concentration 0: uniform, E[theta^2] = pi^2 / 3.
  std::vector<double> squares(100000);
  for (double& v : squares) {
    const double theta = SampleVonMises(0, 0, &rng);
    v = theta * theta;
  }
  ExpectWithinStandardErrors(ComputeMoments(squares), kPi * kPi / 3,
                             "uniform E theta^2");
  EXPECT_EQ(SampleVonMises(1.0, INFINITY, &rng), 1.0);
  EXPECT_TRUE(std::isnan(SampleVonMises(0, -1, &rng)));
  EXPECT_TRUE(std::isnan(SampleVonMises(0, NAN, &rng)));
  EXPECT_TRUE(std::isnan(SampleVonMises(NAN, 1, &rng)));
}

TEST(SampleStandardNormal, FirstMoments) {
  std::mt19937_64 rng(11);
  std::vector<double> x(200000), x2(200000);
  for (size_t s = 0; s < x.size(); ++s) {
    x[s] = SampleStandardNormal(&rng);
    x2[s] = x[s] * x[s];
  }
  ExpectWithinStandardErrors(ComputeMoments(x), 0, "E x");
  ExpectWithinStandardErrors(ComputeMoments(x2), 1, "E x^2");
}

TEST(SampleIsotropicLangevin, RotationsInSOd) {
  std::mt19937_64 rng(13);
  for (int d : {2, 3}) {
    for (double kappa : {0.0, 0.3, 16.67, 1e12}) {
      for (int s = 0; s < 200; ++s) {
        const Eigen::MatrixXd P = SampleIsotropicLangevin(d, kappa, &rng);
        ASSERT_EQ(P.rows(), d);
        ASSERT_EQ(P.cols(), d);
        EXPECT_LT((P.transpose() * P - Eigen::MatrixXd::Identity(d, d)).norm(),
                  1e-14);
        EXPECT_NEAR(P.determinant(), 1, 1e-14);
      }
    }
  }
  EXPECT_EQ(SampleIsotropicLangevin(4, 1, &rng).size(), 0);
  EXPECT_EQ(SampleIsotropicLangevin(3, -1, &rng).size(), 0);
}

// Rotation angle in [0, pi] of P in SO(d).
double RotationAngle(const Eigen::MatrixXd& P) {
  if (P.rows() == 2) return std::abs(std::atan2(P(1, 0), P(0, 0)));
  // Robust form: angle = atan2(|vee(P - P^T)| / 2, (tr P - 1) / 2).
  const Eigen::Vector3d w(P(2, 1) - P(1, 2), P(0, 2) - P(2, 0),
                          P(1, 0) - P(0, 1));
  return std::atan2(0.5 * w.norm(), 0.5 * (P.trace() - 1));
}

TEST(SampleIsotropicLangevin, RmsAngleMatchesEquation63) {
  // The angle theta of the sample has E[theta^2] = SD[theta]^2 of eq. (63)
  // (theta ~ vM(0, 2 kappa) is symmetric, so its SD is its RMS).
  std::mt19937_64 rng(17);
  const int kSamples = 100000;
  for (int d : {2, 3}) {
    for (double kappa : {1.0, 16.67, 150.0}) {
      std::vector<double> squares(kSamples);
      for (double& v : squares) {
        const double theta =
            RotationAngle(SampleIsotropicLangevin(d, kappa, &rng));
        v = theta * theta;
      }
      const double sd = LangevinAngularStandardDeviation(kappa);
      SCOPED_TRACE(::testing::Message() << "d=" << d << " kappa=" << kappa);
      ExpectWithinStandardErrors(ComputeMoments(squares), sd * sd, "E theta^2");
    }
  }
}

TEST(SampleIsotropicLangevin, MeanMatrixMatchesClosedForm) {
  // With A = E cos(theta) = I1(2 kappa) / I0(2 kappa) and a uniform axis v
  // (E[v v^T] = I / 3, E sin(theta) = 0):
  //   d = 2: E[P] = A I;   d = 3: E[P] = I - (2/3)(1 - A) I
  // (Rodrigues, E[[v]x^2] = E[v v^T] - I). Checked entrywise; this also
  // tests the axis distribution.
  std::mt19937_64 rng(19);
  const int kSamples = 100000;
  const double kappa = 1.5;
  const double a = VonMisesMeanCosine(2 * kappa);
  for (int d : {2, 3}) {
    std::vector<std::vector<double>> entries(d * d,
                                             std::vector<double>(kSamples));
    for (int s = 0; s < kSamples; ++s) {
      const Eigen::MatrixXd P = SampleIsotropicLangevin(d, kappa, &rng);
      for (int e = 0; e < d * d; ++e) entries[e][s] = P(e % d, e / d);
    }
    const double diagonal = d == 2 ? a : 1 - 2.0 / 3.0 * (1 - a);
    for (int e = 0; e < d * d; ++e) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " entry " << e);
      ExpectWithinStandardErrors(ComputeMoments(entries[e]),
                                 e % d == e / d ? diagonal : 0, "E P");
    }
  }
}

TEST(LangevinAngularStandardDeviation, MatchesPaperStatements) {
  // Appendix A / Section 6.1: kappa = 16.67 gives ~10 deg RMS, kappa = 150 an
  // angular SD of 3.31 deg (both as printed, so to their last digit).
  EXPECT_NEAR(LangevinAngularStandardDeviation(16.67) / kDegree, 10.0, 0.05);
  EXPECT_NEAR(LangevinAngularStandardDeviation(150) / kDegree, 3.31, 0.005);
  // The Gaussian approximation 1/sqrt(2 kappa) (eq. 64) is within 1% for
  // kappa > 12.87 (11.41 deg) and within 0.1% for kappa > 125.3 (3.62 deg).
  auto relative_error = [](double kappa) {
    return std::abs(
        LangevinAngularStandardDeviation(kappa) * std::sqrt(2 * kappa) - 1);
  };
  EXPECT_NEAR(relative_error(12.87), 0.01, 0.0005);
  EXPECT_NEAR(relative_error(125.3), 0.001, 0.00005);
  EXPECT_NEAR(LangevinAngularStandardDeviation(12.87) / kDegree, 11.41, 0.005);
  EXPECT_NEAR(LangevinAngularStandardDeviation(125.3) / kDegree, 3.62, 0.005);
  // Closed forms: kappa = 0 is uniform on [-pi, pi): SD = pi / sqrt(3); for
  // kappa -> infinity SD -> 1 / sqrt(2 kappa) (error O(1/kappa)).
  EXPECT_NEAR(LangevinAngularStandardDeviation(0), kPi / std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(LangevinAngularStandardDeviation(1e10) * std::sqrt(2e10), 1,
              1e-9);
  EXPECT_TRUE(std::isnan(LangevinAngularStandardDeviation(-1)));
}

}  // namespace
}  // namespace ceres_sesync
