// Double-double arithmetic (internal/double_double.h) and the sparse
// double-double Cholesky (internal/extended_cholesky.h) against binary128
// (__float128, 113-bit significands: its own rounding, 2^-113 ~ 0.008 u^2,
// is far below the bounds tested).

#include "ceres_sesync/internal/double_double.h"

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "ceres_sesync/internal/extended_cholesky.h"
#include "gtest/gtest.h"

namespace ceres_sesync::internal {
namespace {

using Quad = __float128;
constexpr double u = kUnitRoundoffDouble;

Quad ToQuad(const DoubleDouble& x) { return Quad(x.hi) + Quad(x.lo); }
Quad Abs(Quad x) { return x < 0 ? -x : x; }
double RelativeError(const DoubleDouble& computed, Quad exact) {
  const Quad e = (ToQuad(computed) - exact) / exact;
  return static_cast<double>(e < 0 ? -e : e);
}

// A normalized double-double with a random sign, a significand in [1, 2)
// times 2^e for e in [-exponent_range, exponent_range], and a random low
// part.
DoubleDouble RandomDoubleDouble(std::mt19937_64* rng, int exponent_range) {
  std::uniform_real_distribution<double> significand(1, 2);
  std::uniform_int_distribution<int> exponent(-exponent_range, exponent_range);
  std::uniform_real_distribution<double> low(-0.5, 0.5);
  const double hi =
      std::ldexp(significand(*rng), exponent(*rng)) * ((*rng)() % 2 ? 1 : -1);
  const DoubleDouble x = dd::FastTwoSum(hi, low(*rng) * hi * 2 * u);
  return x;
}

bool Normalized(const DoubleDouble& x) {
  return x.hi + x.lo == x.hi && std::abs(x.lo) <= u * std::abs(x.hi);
}

TEST(DoubleDouble, ErrorFreeTransformationsAreExact) {
  std::mt19937_64 rng(1);
  for (int k = 0; k < 100000; ++k) {
    const double a = RandomDoubleDouble(&rng, 60).hi;
    const double b = RandomDoubleDouble(&rng, 60).hi;
    const DoubleDouble s = dd::TwoSum(a, b);
    EXPECT_TRUE(ToQuad(s) == Quad(a) + Quad(b));
    const DoubleDouble p = dd::TwoProduct(a, b);
    EXPECT_TRUE(ToQuad(p) == Quad(a) * Quad(b));
    if (std::abs(a) >= std::abs(b)) {
      EXPECT_TRUE(ToQuad(dd::FastTwoSum(a, b)) == Quad(a) + Quad(b));
    }
  }
}

// Every operation within its published (or file-comment) bound, which is
// far inside the uniform kDoubleDoubleUnitRoundoff = 32 u^2; results stay
// normalized. Includes near-cancellation for the additions.
TEST(DoubleDouble, OperationsMeetTheirErrorBounds) {
  std::mt19937_64 rng(2);
  double worst_add = 0, worst_mul = 0, worst_div = 0, worst_sqrt = 0,
         worst_reciprocal = 0;
  for (int k = 0; k < 200000; ++k) {
    const DoubleDouble x = RandomDoubleDouble(&rng, 25);
    DoubleDouble y = RandomDoubleDouble(&rng, 25);
    if (k % 4 == 0) {  // Near-cancellation: y ~ -x.
      y = -x + DoubleDouble(x.hi * std::ldexp(1.0, -(k % 100)));
    }
    // The exact sum with one rounding: the high and the low parts each add
    // exactly in binary128 (exponent gaps < 60 bits).
    const Quad exact_sum =
        (Quad(x.hi) + Quad(y.hi)) + (Quad(x.lo) + Quad(y.lo));
    if (exact_sum == 0) continue;
    const DoubleDouble sum = x + y;
    worst_add = std::max(worst_add, RelativeError(sum, exact_sum));
    EXPECT_TRUE(Normalized(sum));
    const DoubleDouble product = x * y;
    worst_mul =
        std::max(worst_mul, RelativeError(product, ToQuad(x) * ToQuad(y)));
    EXPECT_TRUE(Normalized(product));
    const DoubleDouble quotient = x / y;
    worst_div =
        std::max(worst_div, RelativeError(quotient, ToQuad(x) / ToQuad(y)));
    worst_reciprocal = std::max(
        worst_reciprocal, RelativeError(Reciprocal(y), Quad(1) / ToQuad(y)));
    const DoubleDouble ax = x.hi < 0 ? -x : x;
    const DoubleDouble root = Sqrt(ax);
    // sqrt via Newton in binary128 from the double root: exact to ~2^-113.
    Quad q = std::sqrt(ax.ToDouble());
    const Quad a = ToQuad(ax);
    for (int it = 0; it < 3; ++it) q = (q + a / q) / 2;
    worst_sqrt = std::max(worst_sqrt, RelativeError(root, q));
  }
  std::printf("worst/u^2: add %.3f mul %.3f recip %.3f div %.3f sqrt %.3f\n",
              worst_add / (u * u), worst_mul / (u * u),
              worst_reciprocal / (u * u), worst_div / (u * u),
              worst_sqrt / (u * u));
  EXPECT_LE(worst_add, (3 + 13 * u) * u * u);
  EXPECT_LE(worst_mul, 5 * u * u);
  EXPECT_LE(worst_reciprocal, 9.1 * u * u);
  EXPECT_LE(worst_div, 15 * u * u);
  EXPECT_LE(worst_sqrt, 4.2 * u * u);
  EXPECT_LT(15 * u * u, kDoubleDoubleUnitRoundoff);
}

// The Cray-style bound of AccumulateSubtract:
// |fl(x - y) - (x - y)| <= 3.01 u^2 (|x| + |y|).
TEST(DoubleDouble, AccumulateSubtractMeetsItsCrayBound) {
  std::mt19937_64 rng(3);
  double worst = 0;
  for (int k = 0; k < 200000; ++k) {
    const DoubleDouble x = RandomDoubleDouble(&rng, 25);
    DoubleDouble y = RandomDoubleDouble(&rng, 25);
    if (k % 3 == 0) y = x + DoubleDouble(x.hi * std::ldexp(1.0, -(k % 110)));
    const DoubleDouble z = AccumulateSubtract(x, y);
    const Quad exact = (Quad(x.hi) - Quad(y.hi)) + (Quad(x.lo) - Quad(y.lo));
    Quad error = ToQuad(z) - exact;
    if (error < 0) error = -error;
    const Quad scale = (x.hi < 0 ? -ToQuad(x) : ToQuad(x)) +
                       (y.hi < 0 ? -ToQuad(y) : ToQuad(y));
    worst = std::max(worst, static_cast<double>(error / scale));
    EXPECT_TRUE(Normalized(z) || (z.hi == 0 && z.lo == 0));
  }
  std::printf("worst Cray/u^2 %.3f\n", worst / (u * u));
  EXPECT_LE(worst, 3.01 * u * u);
}

// SubtractProducts(s, x, y, K), K = 1..kMaxProducts, within its bound
// |r - (s - sum_j x_j y_j)| <= (K^2 + 2K) u^2 |s| + sum_j (n_j^2 + 6 n_j + 6)
// u^2 |x_j y_j| (n_j = K - j + 1), tested without the factors (1 + 40u),
// and within the single-step Cray bound 3.01 u^2 |s| + 13.01 u^2 |x y| for
// K = 1. The binary128 reference errs by ~(K + 1) 2^-113 (~0.07 u^2) of the
// terms, far below the bounds. Includes near-cancellation of s against the
// products. The result is normalized, and zero products are exact no-ops.
TEST(DoubleDouble, SubtractProductsMeetsItsBound) {
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<int> count(1, kMaxProducts);
  double worst = 0, worst_single = 0;
  for (int trial = 0; trial < 100000; ++trial) {
    const int K = count(rng);
    DoubleDouble x[kMaxProducts], y[kMaxProducts];
    Quad products[kMaxProducts], sum = 0;
    for (int j = 0; j < K; ++j) {
      x[j] = RandomDoubleDouble(&rng, 10);
      y[j] = RandomDoubleDouble(&rng, 10);
      products[j] = ToQuad(x[j]) * ToQuad(y[j]);
      sum += products[j];
    }
    DoubleDouble s = RandomDoubleDouble(&rng, 20);
    if (trial % 3 == 0) {  // s ~ sum_j x_j y_j: cancellation.
      const double shift = s.hi * std::ldexp(1.0, -(trial % 120));
      s = dd::TwoSum(static_cast<double>(sum), shift);
    }
    const DoubleDouble r = SubtractProducts(s, x, y, K);
    EXPECT_TRUE(Normalized(r) || (r.hi == 0 && r.lo == 0));
    const Quad error = Abs(ToQuad(r) - (ToQuad(s) - sum));
    Quad bound = (K * K + 2 * K) * Quad(u) * u * Abs(ToQuad(s));
    for (int j = 0; j < K; ++j) {
      const int n_j = K - j;  // j counts from 0 here.
      bound += (n_j * n_j + 6 * n_j + 6) * Quad(u) * u * Abs(products[j]);
    }
    worst = std::max(worst, static_cast<double>(error / bound));
    if (K == 1) {
      const Quad single =
          3.01 * u * u * Abs(ToQuad(s)) + 13.01 * u * u * Abs(products[0]);
      worst_single =
          std::max(worst_single, static_cast<double>(error / single));
    }
    // Zero products change nothing (bitwise, up to the sign of zeros).
    if (K < kMaxProducts) {
      DoubleDouble xz[kMaxProducts], yz[kMaxProducts];
      for (int j = 0; j < K; ++j) {
        xz[j] = x[j];
        yz[j] = y[j];
      }
      xz[K] = DoubleDouble(0.0);
      yz[K] = y[0];
      const DoubleDouble rz = SubtractProducts(s, xz, yz, K + 1);
      EXPECT_TRUE(rz.hi == r.hi && rz.lo == r.lo);
    }
  }
  std::printf(
      "SubtractProducts: worst error / bound %.3f (K = 1: / Cray "
      "bound %.3f)\n",
      worst, worst_single);
  EXPECT_LE(worst, 1.0);
  EXPECT_LE(worst_single, 1.0);
}

// A random sparse symmetric positive definite matrix (a weighted graph
// Laplacian plus a diagonal), upper triangle in compressed columns, and the
// same as a dense binary128 matrix.
struct TestMatrix {
  int n = 0;
  std::vector<int> start, row;
  std::vector<DoubleDouble> value;
  std::vector<Quad> dense;  // n x n, column-major.
};

TestMatrix RandomSpdMatrix(int n, int edges, double shift, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::uniform_real_distribution<double> weight(0.1, 10);
  TestMatrix m;
  m.n = n;
  std::vector<double> a(static_cast<size_t>(n) * n, 0.0);
  for (int e = 0; e < edges; ++e) {
    const int i = node(rng), j = node(rng);
    if (i == j) continue;
    const double w = weight(rng);
    a[i + n * i] += w;
    a[j + n * j] += w;
    a[i + n * j] -= w;
    a[j + n * i] -= w;
  }
  for (int i = 0; i < n; ++i) a[i + n * i] += shift * weight(rng);
  m.start.push_back(0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= j; ++i) {
      if (a[i + n * j] != 0 || i == j) {
        m.row.push_back(i);
        m.value.emplace_back(a[i + n * j]);
      }
    }
    m.start.push_back(static_cast<int>(m.row.size()));
  }
  m.dense.assign(a.begin(), a.end());
  return m;
}

// The factorization's true residual L L^T - A (binary128) stays within the
// returned row bounds, and L matches a dense binary128 Cholesky.
TEST(DoubleDoubleCholesky, BackwardErrorBoundCoversTheTrueResidual) {
  for (uint64_t seed : {1, 2, 3}) {
    const int n = 60;
    const TestMatrix m = RandomSpdMatrix(n, 150, 1e-3, seed);
    DoubleDoubleCholesky chol;
    chol.Analyze(n, m.start, m.row);
    ASSERT_TRUE(chol.Factorize(m.value));
    std::vector<double> rho;
    chol.RowBackwardErrorBounds(&rho);
    // Dense L from the factor: L = chol(A) in binary128 for reference.
    std::vector<Quad> L(static_cast<size_t>(n) * n, 0);
    for (int j = 0; j < n; ++j) {
      Quad d = m.dense[j + n * j];
      for (int k = 0; k < j; ++k) d -= L[j + n * k] * L[j + n * k];
      L[j + n * j] = std::sqrt(static_cast<double>(d));
      for (int it = 0; it < 3; ++it) {
        L[j + n * j] = (L[j + n * j] + d / L[j + n * j]) / 2;
      }
      for (int i = j + 1; i < n; ++i) {
        Quad s = m.dense[i + n * j];
        for (int k = 0; k < j; ++k) s -= L[i + n * k] * L[j + n * k];
        L[i + n * j] = s / L[j + n * j];
      }
    }
    std::vector<Quad> Lc(static_cast<size_t>(n) * n, 0);  // The computed L.
    for (int j = 0; j < n; ++j) {
      for (int p = chol.factor_start()[j]; p < chol.factor_start()[j + 1];
           ++p) {
        Lc[chol.factor_row()[p] + n * j] = ToQuad(chol.factor_value()[p]);
      }
    }
    double worst_ratio = 0, max_rho = 0;
    for (int i = 0; i < n; ++i) {
      Quad row_sum = 0;
      for (int j = 0; j < n; ++j) {
        Quad llt = 0;
        for (int k = 0; k < n; ++k) llt += Lc[i + n * k] * Lc[j + n * k];
        Quad e = llt - m.dense[i + n * j];
        row_sum += e < 0 ? -e : e;
        const Quad diff = Lc[i + n * j] - L[i + n * j];
        EXPECT_LT(std::abs(static_cast<double>(diff)),
                  1e-26 * (1 + std::abs(static_cast<double>(L[i + n * j]))));
      }
      worst_ratio =
          std::max(worst_ratio, static_cast<double>(row_sum) / rho[i]);
      max_rho = std::max(max_rho, rho[i]);
    }
    std::printf("residual / bound %.3g, max bound %.3g\n", worst_ratio,
                max_rho);
    EXPECT_LE(worst_ratio, 1.0) << "seed " << seed;
    EXPECT_GT(worst_ratio, 0.0);  // The residual is not trivially zero ...
    EXPECT_LT(max_rho, 1e-25);    // ... and the bound is double-double sized.
  }
}

TEST(DoubleDoubleCholesky, RejectsIndefiniteMatrices) {
  // A Laplacian (singular) shifted down by a little: indefinite by 1e-20,
  // far below double precision's resolution of its entries (~10).
  TestMatrix m = RandomSpdMatrix(40, 120, 0, 7);
  for (int j = 0; j < m.n; ++j) {
    const int diagonal = m.start[j + 1] - 1;
    m.value[diagonal] = m.value[diagonal] - DoubleDouble(1e-20);
  }
  DoubleDoubleCholesky chol;
  chol.Analyze(m.n, m.start, m.row);
  EXPECT_FALSE(chol.Factorize(m.value));
  // ... and shifted up by as little it is positive definite (lambda_min =
  // 1e-20, condition number ~1e22: within double-double's reach).
  for (int j = 0; j < m.n; ++j) {
    const int diagonal = m.start[j + 1] - 1;
    m.value[diagonal] = m.value[diagonal] + DoubleDouble(2e-20);
  }
  EXPECT_TRUE(chol.Factorize(m.value));
}

}  // namespace
}  // namespace ceres_sesync::internal
