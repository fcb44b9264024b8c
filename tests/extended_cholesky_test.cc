// The supernodal double-double Cholesky (internal/extended_cholesky.h) on
// matrices with dense blocks: grid Laplacians in nested-dissection order
// (large separator supernodes) and random sparse SPD matrices. Checked
// against the simplicial reference scheme, against its own backward-error
// bound with the true residual L L^T - A in binary128 (__float128: 113-bit
// significands, its rounding ~0.008 u^2 far below the bounds), across the
// SIMD and portable kernels (bitwise), and on indefinite matrices.

#include "ceres_sesync/internal/extended_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "ceres_sesync/internal/double_double.h"
#include "gtest/gtest.h"

namespace ceres_sesync::internal {
namespace {

using Quad = __float128;
Quad ToQuad(const DoubleDouble& x) { return Quad(x.hi) + Quad(x.lo); }
Quad Abs(Quad x) { return x < 0 ? -x : x; }

// A symmetric matrix as its upper triangle in compressed columns (the input
// format of DoubleDoubleCholesky), values in double-double.
struct Matrix {
  int n = 0;
  std::vector<int> start, row;
  std::vector<DoubleDouble> value;
};

// Builds the upper triangle of P A P^T from the entries (i, j, a) of the
// lower triangle of A (i >= j, each once), P the ordering order[k] = k-th
// pivot.
Matrix Permuted(int n,
                const std::vector<std::tuple<int, int, DoubleDouble>>& lower,
                const std::vector<int>& order) {
  std::vector<int> position(n);
  for (int k = 0; k < n; ++k) position[order[k]] = k;
  std::vector<std::vector<std::pair<int, DoubleDouble>>> columns(n);
  for (const auto& [i, j, a] : lower) {
    const int pi = position[i], pj = position[j];
    columns[std::max(pi, pj)].emplace_back(std::min(pi, pj), a);
  }
  Matrix m;
  m.n = n;
  m.start.push_back(0);
  for (auto& column : columns) {
    std::sort(column.begin(), column.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [r, a] : column) {
      m.row.push_back(r);
      m.value.push_back(a);
    }
    m.start.push_back(static_cast<int>(m.row.size()));
  }
  return m;
}

// Nested dissection of a grid box [x0, x1) x [y0, y1) x [z0, z1): both
// halves, then the separating plane; small boxes in natural order.
void Dissect(int nx, int ny, int x0, int x1, int y0, int y1, int z0, int z1,
             std::vector<int>* order) {
  const int sx = x1 - x0, sy = y1 - y0, sz = z1 - z0;
  if (sx * sy * sz <= 8) {
    for (int z = z0; z < z1; ++z)
      for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) order->push_back(x + nx * (y + ny * z));
    return;
  }
  if (sx >= sy && sx >= sz) {
    const int m = x0 + sx / 2;
    Dissect(nx, ny, x0, m, y0, y1, z0, z1, order);
    Dissect(nx, ny, m + 1, x1, y0, y1, z0, z1, order);
    Dissect(nx, ny, m, m + 1, y0, y1, z0, z1, order);
  } else if (sy >= sz) {
    const int m = y0 + sy / 2;
    Dissect(nx, ny, x0, x1, y0, m, z0, z1, order);
    Dissect(nx, ny, x0, x1, m + 1, y1, z0, z1, order);
    Dissect(nx, ny, x0, x1, m, m + 1, z0, z1, order);
  } else {
    const int m = z0 + sz / 2;
    Dissect(nx, ny, x0, x1, y0, y1, z0, m, order);
    Dissect(nx, ny, x0, x1, y0, y1, m + 1, z1, order);
    Dissect(nx, ny, x0, x1, y0, y1, m, m + 1, order);
  }
}

// The Laplacian of an nx x ny x nz grid with random edge weights k / 16,
// k in [2, 160] (sums exact in double), plus `shift` times a random
// diagonal in [0.5, 1.5] added in double-double (exactly), in
// nested-dissection order.
Matrix GridLaplacian(int nx, int ny, int nz, double shift, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> weight(2, 160);
  std::uniform_real_distribution<double> scale(0.5, 1.5);
  const int n = nx * ny * nz;
  std::vector<double> diagonal(n, 0.0);
  std::vector<std::tuple<int, int, DoubleDouble>> lower;
  for (int z = 0; z < nz; ++z) {
    for (int y = 0; y < ny; ++y) {
      for (int x = 0; x < nx; ++x) {
        const int i = x + nx * (y + ny * z);
        const int neighbours[3] = {x + 1 < nx ? i + 1 : -1,
                                   y + 1 < ny ? i + nx : -1,
                                   z + 1 < nz ? i + nx * ny : -1};
        for (int j : neighbours) {
          if (j < 0) continue;
          const double w = weight(rng) / 16.0;
          lower.emplace_back(j, i, DoubleDouble(-w));
          diagonal[i] += w;
          diagonal[j] += w;
        }
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    lower.emplace_back(i, i, dd::TwoSum(diagonal[i], shift * scale(rng)));
  }
  std::vector<int> order;
  Dissect(nx, ny, 0, nx, 0, ny, 0, nz, &order);
  return Permuted(n, lower, order);
}

// A random sparse SPD matrix: a weighted graph Laplacian on `edges` random
// edges plus a shifted diagonal (heavy fill: large supernodes).
Matrix RandomSparse(int n, int edges, double shift, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> node(0, n - 1);
  std::uniform_real_distribution<double> weight(0.1, 10);
  std::vector<double> diagonal(n, 0.0);
  std::vector<std::tuple<int, int, DoubleDouble>> lower;
  std::vector<std::vector<int>> seen(n);
  for (int e = 0; e < edges; ++e) {
    int i = node(rng), j = node(rng);
    if (i == j) continue;
    if (i < j) std::swap(i, j);
    if (std::find(seen[i].begin(), seen[i].end(), j) != seen[i].end()) {
      continue;
    }
    seen[i].push_back(j);
    const double w = weight(rng);
    lower.emplace_back(i, j, DoubleDouble(-w));
    diagonal[i] += w;
    diagonal[j] += w;
  }
  for (int i = 0; i < n; ++i) {
    lower.emplace_back(i, i, DoubleDouble(diagonal[i] + shift * weight(rng)));
  }
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  return Permuted(n, lower, order);
}

DoubleDoubleCholesky::Options Supernodal(bool vectorize) {
  DoubleDoubleCholesky::Options options;
  options.vectorize = vectorize;
  return options;
}

// The supernodal scheme on `threads` threads, its tree split however small
// the matrix.
DoubleDoubleCholesky::Options Split(int threads) {
  DoubleDoubleCholesky::Options options;
  options.min_split_flops = 0;
  options.num_threads = threads;
  return options;
}

DoubleDoubleCholesky::Options Simplicial() {
  DoubleDoubleCholesky::Options options;
  options.supernodal = false;
  return options;
}

// Row sums sum_j |(L L^T - A)_ij| in binary128, by rows of L L^T (sparse:
// O(sum of squared column counts)).
std::vector<double> ResidualRowSums(const DoubleDoubleCholesky& chol,
                                    const Matrix& m) {
  const int n = m.n;
  const std::vector<int>& start = chol.factor_start();
  const auto& row = chol.factor_row();
  const std::vector<DoubleDouble>& value = chol.factor_value();
  // Rows of L: (column, value) lists.
  std::vector<std::vector<std::pair<int, Quad>>> rows(n);
  for (int c = 0; c < n; ++c) {
    for (int p = start[c]; p < start[c + 1]; ++p) {
      rows[row[p]].emplace_back(c, ToQuad(value[p]));
    }
  }
  // Full rows of A.
  std::vector<std::vector<std::pair<int, Quad>>> a(n);
  for (int c = 0; c < n; ++c) {
    for (int p = m.start[c]; p < m.start[c + 1]; ++p) {
      a[m.row[p]].emplace_back(c, ToQuad(m.value[p]));
      if (m.row[p] != c) a[c].emplace_back(m.row[p], ToQuad(m.value[p]));
    }
  }
  std::vector<Quad> e(n, 0);
  std::vector<char> touched(n, 0);
  std::vector<int> list;
  std::vector<double> sums(n);
  for (int i = 0; i < n; ++i) {
    list.clear();
    auto touch = [&](int j) {
      if (!touched[j]) {
        touched[j] = 1;
        list.push_back(j);
      }
    };
    // (L L^T)_ij = sum_k L_ik L_jk: k over row i, j over column k.
    for (const auto& [k, l_ik] : rows[i]) {
      for (int p = start[k]; p < start[k + 1]; ++p) {
        touch(row[p]);
        e[row[p]] += l_ik * ToQuad(value[p]);
      }
    }
    for (const auto& [j, a_ij] : a[i]) {
      touch(j);
      e[j] -= a_ij;
    }
    Quad sum = 0;
    for (int j : list) {
      sum += Abs(e[j]);
      e[j] = 0;
      touched[j] = 0;
    }
    sums[i] = static_cast<double>(sum);
  }
  return sums;
}

// Largest |L_ij| of each row.
std::vector<double> RowMax(const DoubleDoubleCholesky& chol) {
  std::vector<double> m(chol.size(), 0.0);
  for (int c = 0; c < chol.size(); ++c) {
    for (int p = chol.factor_start()[c]; p < chol.factor_start()[c + 1]; ++p) {
      double& r = m[chol.factor_row()[p]];
      r = std::max(r, std::abs(chol.factor_value()[p].hi));
    }
  }
  return m;
}

// Entries of two factors of the same pattern that differ in any bit (signed
// zeros included).
int BitwiseDifferences(const DoubleDoubleCholesky& x,
                       const DoubleDoubleCholesky& y) {
  EXPECT_EQ(x.factor_value().size(), y.factor_value().size());
  int differences = 0;
  for (size_t p = 0; p < x.factor_value().size(); ++p) {
    const DoubleDouble& a = x.factor_value()[p];
    const DoubleDouble& b = y.factor_value()[p];
    differences += std::signbit(a.hi) != std::signbit(b.hi) ||
                   std::signbit(a.lo) != std::signbit(b.lo) ||
                   !(a.hi == b.hi) || !(a.lo == b.lo);
  }
  return differences;
}

// The largest |x_ij - reference_ij| over the (common) pattern, relative to
// the largest |L_ij| of its row in `reference`.
double WorstDifference(const DoubleDoubleCholesky& x,
                       const DoubleDoubleCholesky& reference) {
  EXPECT_EQ(x.factor_row(), reference.factor_row());
  const std::vector<double> row_max = RowMax(reference);
  double worst = 0;
  for (size_t p = 0; p < reference.factor_row().size(); ++p) {
    const Quad d =
        ToQuad(x.factor_value()[p]) - ToQuad(reference.factor_value()[p]);
    worst = std::max(worst, static_cast<double>(Abs(d)) /
                                row_max[reference.factor_row()[p]]);
  }
  return worst;
}

// The true residual of a factorization of m against its bound: the largest
// ratio over the rows of sum_j |(L L^T - A)_ij| to rho_i, and max_i rho_i.
struct ResidualCheck {
  double worst_ratio = 0, max_rho = 0;
};
ResidualCheck CheckResidual(const DoubleDoubleCholesky& chol, const Matrix& m) {
  std::vector<double> rho;
  chol.RowBackwardErrorBounds(&rho);
  const std::vector<double> residual = ResidualRowSums(chol, m);
  ResidualCheck check;
  for (int i = 0; i < m.n; ++i) {
    check.worst_ratio = std::max(check.worst_ratio, residual[i] / rho[i]);
    check.max_rho = std::max(check.max_rho, rho[i]);
  }
  return check;
}

struct Case {
  const char* name;
  Matrix matrix;
};

std::vector<Case> Cases() {
  std::vector<Case> cases;
  cases.push_back({"2D grid 40 x 40", GridLaplacian(40, 40, 1, 1.0, 1)});
  cases.push_back({"3D grid 11 x 11 x 11", GridLaplacian(11, 11, 11, 1.0, 2)});
  cases.push_back({"random sparse 300", RandomSparse(300, 900, 1e-3, 3)});
  return cases;
}

// The supernodal factor has the reference's pattern and nearly its values
// (both are backward stable to ~k 4e-31 |A|; the condition numbers here are
// below ~1e5, so the factors agree to ~1e-25 of their rows' scale; the
// tolerance is 1e-23), and its true residual stays within
// RowBackwardErrorBounds.
TEST(ExtendedCholesky, SupernodalMatchesReferenceAndItsBound) {
  for (const Case& c : Cases()) {
    const Matrix& m = c.matrix;
    DoubleDoubleCholesky supernodal, reference(Simplicial());
    supernodal.Analyze(m.n, m.start, m.row);
    reference.Analyze(m.n, m.start, m.row);
    // Dense blocks: a supernode wider than the factorization's panels (32
    // columns), and the share of the work (sum over columns of count^2 / 2)
    // in supernodes of >= 8 columns.
    double in_large = 0;
    int widest = 0;
    const std::vector<int>& super = supernodal.supernode_start();
    for (int s = 0; s < supernodal.num_supernodes(); ++s) {
      widest = std::max(widest, super[s + 1] - super[s]);
      if (super[s + 1] - super[s] < 8) continue;
      for (int j = super[s]; j < super[s + 1]; ++j) {
        const double count =
            supernodal.factor_start()[j + 1] - supernodal.factor_start()[j];
        in_large += 0.5 * count * count;
      }
    }
    const double large_fraction = in_large / supernodal.flops();
    EXPECT_GT(widest, 32) << c.name;
    ASSERT_TRUE(supernodal.Factorize(m.value)) << c.name;
    ASSERT_TRUE(reference.Factorize(m.value)) << c.name;
    ASSERT_EQ(supernodal.factor_start(), reference.factor_start());
    ASSERT_EQ(supernodal.factor_row(), reference.factor_row());
    const double worst_difference = WorstDifference(supernodal, reference);
    const auto [worst_ratio, max_rho] = CheckResidual(supernodal, m);
    double max_a = 0;
    for (const DoubleDouble& a : m.value)
      max_a = std::max(max_a, std::abs(a.hi));
    std::printf(
        "%s: n %d, nnz(L) %lld, %d supernodes (widest %d, %.0f%% of the work "
        "in >= 8 columns), SIMD %d; difference from the reference %.3g; "
        "residual / "
        "bound %.3g, max bound / max |a| %.3g\n",
        c.name, m.n, supernodal.factor_nonzeros(), supernodal.num_supernodes(),
        widest, 100 * large_fraction, supernodal.vectorized(), worst_difference,
        worst_ratio, max_rho / max_a);
    EXPECT_LT(worst_difference, 1e-23) << c.name;
    EXPECT_LE(worst_ratio, 1.0) << c.name;
    EXPECT_GT(worst_ratio, 0.0) << c.name;  // The residual is not zero ...
    EXPECT_LT(max_rho, 1e-25 * max_a) << c.name;  // ... the bound is tiny.
  }
}

// The parallel factorization (the elimination tree split into two bins of
// subtrees and their top, extended_cholesky.h): the same pattern, values
// within the reference's tolerance, the true residual within the bound, and
// bitwise the same factor for every thread count; an indefinite matrix is
// rejected whichever part of the tree holds the failing pivot.
TEST(ExtendedCholesky, SplitFactorizationIsSoundAndThreadIndependent) {
  for (const Case& c : Cases()) {
    const Matrix& m = c.matrix;
    DoubleDoubleCholesky one(Split(1)), two(Split(2)), reference(Simplicial());
    one.Analyze(m.n, m.start, m.row);
    two.Analyze(m.n, m.start, m.row);
    reference.Analyze(m.n, m.start, m.row);
    // A random sparse matrix fills to one dense block: nothing to split.
    const bool random = std::string(c.name).rfind("random", 0) == 0;
    EXPECT_EQ(one.num_bins(), random ? 0 : 2) << c.name;
    ASSERT_TRUE(one.Factorize(m.value)) << c.name;
    ASSERT_TRUE(two.Factorize(m.value)) << c.name;
    ASSERT_TRUE(reference.Factorize(m.value)) << c.name;
    ASSERT_EQ(one.factor_row(), reference.factor_row());
    EXPECT_EQ(BitwiseDifferences(one, two), 0) << c.name;
    EXPECT_LT(WorstDifference(one, reference), 1e-23) << c.name;
    const double worst_ratio = CheckResidual(two, m).worst_ratio;
    EXPECT_LE(worst_ratio, 1.0) << c.name;
    EXPECT_GT(worst_ratio, 0.0) << c.name;
  }
  // Indefinite: the Laplacian's null vector is constant, so every pivot
  // region is affected; rejected with one and with two threads.
  for (int threads : {1, 2}) {
    DoubleDoubleCholesky chol(Split(threads));
    const Matrix negative = GridLaplacian(30, 30, 1, -1e-18, 4);
    chol.Analyze(negative.n, negative.start, negative.row);
    ASSERT_EQ(chol.num_bins(), 2);
    EXPECT_FALSE(chol.Factorize(negative.value)) << threads;
    const Matrix positive = GridLaplacian(30, 30, 1, 1e-18, 4);
    EXPECT_TRUE(chol.Factorize(positive.value)) << threads;
  }
}

// The same matrix with every value rounded to double, as double values.
std::vector<double> RoundedValues(const Matrix& m) {
  std::vector<double> values;
  for (const DoubleDouble& v : m.value) values.push_back(v.hi + v.lo);
  return values;
}

// The same scheme in double (Factorize() with double values): bitwise the
// same factor on one and two threads (a split tree) and with and without
// SIMD; the double-double factor's pattern and, within double's
// resolution, its values (both backward stable; with condition numbers
// below ~1e5 here the factors agree to ~1e5 k u of their rows' scale, the
// tolerance is 1e-8); the true residual L L^T - A, in binary128, within
// RowBackwardErrorBounds() (double's gamma), which is not vacuous; and
// indefinite matrices rejected on every thread count.
TEST(ExtendedCholesky, DoubleFactorizationIsSoundAndThreadIndependent) {
  for (const Case& c : Cases()) {
    Matrix m = c.matrix;
    const std::vector<double> values = RoundedValues(m);
    for (size_t q = 0; q < values.size(); ++q) m.value[q] = values[q];
    DoubleDoubleCholesky::Options portable_options = Split(2);
    portable_options.vectorize = false;
    DoubleDoubleCholesky one(Split(1)), two(Split(2)), extended(Split(1)),
        portable(portable_options);
    for (DoubleDoubleCholesky* chol : {&one, &two, &portable, &extended}) {
      chol->Analyze(m.n, m.start, m.row);
    }
    ASSERT_TRUE(one.Factorize(values)) << c.name;
    ASSERT_TRUE(two.Factorize(values)) << c.name;
    ASSERT_TRUE(portable.Factorize(values)) << c.name;
    ASSERT_TRUE(extended.Factorize(m.value)) << c.name;
    EXPECT_FALSE(one.extended());
    EXPECT_TRUE(extended.extended());
    EXPECT_EQ(BitwiseDifferences(one, two), 0) << c.name;
    EXPECT_EQ(BitwiseDifferences(one, portable), 0) << c.name;
    ASSERT_EQ(one.factor_row(), extended.factor_row());
    for (const DoubleDouble& l : one.factor_value()) EXPECT_EQ(l.lo, 0.0);
    const double worst_difference = WorstDifference(one, extended);
    const auto [worst_ratio, max_rho] = CheckResidual(two, m);
    double max_a = 0;
    for (double a : values) max_a = std::max(max_a, std::abs(a));
    std::printf(
        "%s (double): difference from double-double %.3g; residual / bound "
        "%.3g, max bound / max |a| %.3g\n",
        c.name, worst_difference, worst_ratio, max_rho / max_a);
    EXPECT_LT(worst_difference, 1e-8) << c.name;
    EXPECT_LE(worst_ratio, 1.0) << c.name;
    EXPECT_GT(worst_ratio, 0.0) << c.name;
    EXPECT_LT(max_rho, 1e-10 * max_a) << c.name;
  }
  // The smallest eigenvalue about -/+ 1e-8 (the shift) of entries ~10, far
  // above double's resolution: rejected / factored.
  for (int threads : {1, 2}) {
    DoubleDoubleCholesky chol(Split(threads));
    const Matrix negative = GridLaplacian(30, 30, 1, -1e-8, 4);
    chol.Analyze(negative.n, negative.start, negative.row);
    ASSERT_EQ(chol.num_bins(), 2);
    EXPECT_FALSE(chol.Factorize(RoundedValues(negative))) << threads;
    const Matrix positive = GridLaplacian(30, 30, 1, 1e-8, 4);
    EXPECT_TRUE(chol.Factorize(RoundedValues(positive))) << threads;
  }
}

// ShareAnalysis(): an object factoring with another's analysis computes
// bitwise the factor of an object with its own analysis, in double and in
// double-double; the two objects' numeric factors are independent (one
// factoring different values leaves the other's factor and bounds as they
// were); and the shared analysis outlives its owner's re-analysis of
// another pattern.
TEST(ExtendedCholesky, SharedAnalysisFactorsIndependently) {
  const Matrix a = GridLaplacian(30, 30, 1, 1.0, 5);
  const Matrix b = GridLaplacian(30, 30, 1, 0.5, 6);  // Same pattern.
  ASSERT_EQ(a.row, b.row);
  ASSERT_NE(a.value[0].hi, b.value[0].hi);
  DoubleDoubleCholesky owner(Split(2)), sharer(Split(2)),
      reference_double(Split(2)), reference_extended(Split(2));
  owner.Analyze(a.n, a.start, a.row);
  sharer.ShareAnalysis(owner);
  reference_double.Analyze(a.n, a.start, a.row);
  reference_extended.Analyze(b.n, b.start, b.row);
  EXPECT_EQ(sharer.size(), a.n);
  EXPECT_EQ(sharer.num_bins(), owner.num_bins());
  EXPECT_EQ(sharer.factor_nonzeros(), reference_double.factor_nonzeros());
  EXPECT_EQ(sharer.flops(), reference_double.flops());
  ASSERT_TRUE(owner.Factorize(RoundedValues(a)));
  ASSERT_TRUE(sharer.Factorize(b.value));
  ASSERT_TRUE(reference_double.Factorize(RoundedValues(a)));
  ASSERT_TRUE(reference_extended.Factorize(b.value));
  EXPECT_FALSE(owner.extended());
  EXPECT_TRUE(sharer.extended());
  ASSERT_EQ(sharer.factor_row(), reference_extended.factor_row());
  EXPECT_EQ(BitwiseDifferences(owner, reference_double), 0);
  EXPECT_EQ(BitwiseDifferences(sharer, reference_extended), 0);
  std::vector<double> rho_owner, rho_reference;
  owner.RowBackwardErrorBounds(&rho_owner);
  reference_double.RowBackwardErrorBounds(&rho_reference);
  EXPECT_EQ(rho_owner, rho_reference);
  EXPECT_LE(CheckResidual(sharer, b).worst_ratio, 1.0);
  // The owner analyzes another pattern; the sharer keeps the old one.
  const Matrix other = GridLaplacian(7, 7, 7, 1.0, 7);
  owner.Analyze(other.n, other.start, other.row);
  ASSERT_TRUE(owner.Factorize(other.value));
  EXPECT_EQ(sharer.size(), a.n);
  ASSERT_TRUE(sharer.Factorize(b.value));
  EXPECT_EQ(BitwiseDifferences(sharer, reference_extended), 0);
}

// The SIMD kernels (when the CPU has them) and the portable code compute
// bitwise the same factor.
TEST(ExtendedCholesky, SimdAndPortableKernelsAgreeBitwise) {
  for (const Case& c : Cases()) {
    const Matrix& m = c.matrix;
    DoubleDoubleCholesky simd(Supernodal(true)), portable(Supernodal(false));
    EXPECT_FALSE(portable.vectorized());
    simd.Analyze(m.n, m.start, m.row);
    portable.Analyze(m.n, m.start, m.row);
    ASSERT_TRUE(simd.Factorize(m.value));
    ASSERT_TRUE(portable.Factorize(m.value));
    if (!simd.vectorized()) {
      std::printf("no AVX2+FMA: both portable\n");
    }
    EXPECT_EQ(BitwiseDifferences(simd, portable), 0) << c.name;
  }
}

// A grid Laplacian (singular) shifted down by ~1e-18 is indefinite far
// below double precision's resolution of its entries (~10): rejected; shifted
// up as much, it is positive definite with condition number ~1e20, within
// double-double's reach: factored. Both kernels.
TEST(ExtendedCholesky, RejectsIndefiniteMatrices) {
  for (bool vectorize : {true, false}) {
    for (const auto& [nx, ny, nz] :
         {std::tuple<int, int, int>{30, 30, 1}, {8, 8, 8}}) {
      DoubleDoubleCholesky chol(Supernodal(vectorize));
      const Matrix negative = GridLaplacian(nx, ny, nz, -1e-18, 4);
      chol.Analyze(negative.n, negative.start, negative.row);
      EXPECT_FALSE(chol.Factorize(negative.value)) << nx << " " << nz;
      const Matrix positive = GridLaplacian(nx, ny, nz, 1e-18, 4);
      EXPECT_TRUE(chol.Factorize(positive.value)) << nx << " " << nz;
      std::vector<double> rho;
      chol.RowBackwardErrorBounds(&rho);
      EXPECT_LT(*std::max_element(rho.begin(), rho.end()), 1e-24);
    }
  }
}

// PermuteSymmetricPattern against a dense P A P^T: every entry on or below
// A's diagonal lands once, at (min, max) of its pivots, with its value;
// entries above the diagonal are skipped. Random patterns (both triangles,
// and the lower one alone) and random permutations.
// A dense symmetric matrix in compressed columns (rows ascending): both
// triangles, or the lower one.
struct Compressed {
  std::vector<int> outer{0}, inner;
  std::vector<double> value;
};
Compressed CompressColumns(const std::vector<std::vector<double>>& dense,
                           bool lower_only) {
  const int n = static_cast<int>(dense.size());
  Compressed a;
  for (int c = 0; c < n; ++c) {
    for (int r = lower_only ? c : 0; r < n; ++r) {
      if (dense[r][c] != 0) {
        a.inner.push_back(r);
        a.value.push_back(dense[r][c]);
      }
    }
    a.outer.push_back(static_cast<int>(a.inner.size()));
  }
  return a;
}

// a's values of the lower triangle at their slots of p (zero elsewhere);
// filled[t]: how many values went to slot t. Entries above the diagonal
// must have no slot.
std::vector<double> PlaceValues(const Compressed& a, const PermutedPattern& p,
                                std::vector<int>* filled) {
  std::vector<double> permuted(p.row_index.size(), 0.0);
  filled->assign(p.row_index.size(), 0);
  EXPECT_EQ(p.slot.size(), a.inner.size());
  const int n = static_cast<int>(a.outer.size()) - 1;
  for (int c = 0; c < n; ++c) {
    for (int q = a.outer[c]; q < a.outer[c + 1]; ++q) {
      if (a.inner[q] < c) {
        EXPECT_EQ(p.slot[q], -1);
        continue;
      }
      EXPECT_GE(p.slot[q], 0);
      if (p.slot[q] < 0) continue;
      permuted[p.slot[q]] = a.value[q];
      ++(*filled)[p.slot[q]];
    }
  }
  return permuted;
}

TEST(ExtendedCholesky, PermuteSymmetricPatternMatchesDensePermutation) {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const int n = 1 + trial * 3;
    const bool lower_only = trial % 2 == 1;
    std::uniform_real_distribution<double> uniform(0.5, 1.5);
    std::vector<std::vector<double>> dense(n, std::vector<double>(n, 0.0));
    for (int i = 0; i < n; ++i) {
      dense[i][i] = uniform(rng);
      for (int j = 0; j < i; ++j) {
        if (rng() % 4 == 0) dense[i][j] = dense[j][i] = uniform(rng);
      }
    }
    const Compressed a = CompressColumns(dense, lower_only);
    std::vector<int> ordering(n);
    for (int k = 0; k < n; ++k) ordering[k] = k;
    std::shuffle(ordering.begin(), ordering.end(), rng);
    std::vector<int> position(n);
    for (int k = 0; k < n; ++k) position[ordering[k]] = k;
    const PermutedPattern p =
        PermuteSymmetricPattern(n, a.outer.data(), a.inner.data(), position);
    ASSERT_EQ(static_cast<int>(p.column_start.size()), n + 1);
    std::vector<int> filled;
    const std::vector<double> permuted = PlaceValues(a, p, &filled);
    EXPECT_TRUE(std::all_of(filled.begin(), filled.end(),
                            [](int f) { return f == 1; }));
    // The upper triangle of P A P^T, entry by entry.
    int entries = 0;
    for (int k = 0; k < n; ++k) {
      for (int t = p.column_start[k]; t < p.column_start[k + 1]; ++t) {
        const int row = p.row_index[t];
        ASSERT_LE(row, k);
        EXPECT_EQ(permuted[t], dense[ordering[row]][ordering[k]])
            << "trial " << trial << " (" << row << ", " << k << ")";
      }
      for (int row = 0; row <= k; ++row) {
        entries += dense[ordering[row]][ordering[k]] != 0;
      }
    }
    EXPECT_EQ(entries, p.column_start[n]);
  }
}

// Matrices of blocks (sizes 1-4; some entries inside blocks structurally
// zero, so the pattern is not block-full) in a random block order:
// PermuteSymmetricBlockPattern puts every entry of P A P^T in place and
// completes the pattern to exactly the block pairs that hold an entry
// (rows ascending), and Analyze() by those blocks equals the scalar
// analysis of that pattern: the same counts, flops, supernodes and tree
// split, the factors in double and double-double bitwise the same, with the
// same backward-error bounds. The incomplete pattern is refused.
TEST(ExtendedCholesky, BlockAnalysisEqualsScalarAnalysis) {
  std::mt19937 rng(11);
  int refused = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const int num_blocks = 1 + static_cast<int>(rng() % 60);
    std::vector<int> size(num_blocks), first(num_blocks + 1, 0);
    for (int b = 0; b < num_blocks; ++b) {
      size[b] = 1 + static_cast<int>(rng() % 4);
      first[b + 1] = first[b] + size[b];
    }
    const int n = first[num_blocks];
    std::vector<int> block_of(n);
    for (int b = 0; b < num_blocks; ++b) {
      for (int i = first[b]; i < first[b + 1]; ++i) block_of[i] = b;
    }
    std::uniform_real_distribution<double> uniform(-1, 1);
    std::vector<std::vector<double>> dense(n, std::vector<double>(n, 0.0));
    auto fill_pair = [&](int r, int c, double density) {
      for (int i = first[r]; i < first[r + 1]; ++i) {
        for (int j = first[c]; j < first[c + 1]; ++j) {
          if (i != j && (r != c || i > j) && uniform(rng) < 2 * density - 1) {
            dense[i][j] = dense[j][i] = uniform(rng);
          }
        }
      }
    };
    for (int b = 0; b < num_blocks; ++b) {
      fill_pair(b, b, 0.5);
      if (b > 0) fill_pair(b, b - 1 - static_cast<int>(rng() % b), 0.7);
      if (b > 1 && rng() % 2 == 0) {
        fill_pair(b, static_cast<int>(rng() % b), 0.7);
      }
    }
    for (int i = 0; i < n; ++i) {  // Diagonally dominant: SPD.
      double sum = 1;
      for (int j = 0; j < n; ++j) sum += std::abs(dense[i][j]);
      dense[i][i] = sum;
    }
    const Compressed a = CompressColumns(dense, /*lower_only=*/false);
    // Blocks in a random order, each block's unknowns together.
    std::vector<int> block_order(num_blocks);
    for (int b = 0; b < num_blocks; ++b) block_order[b] = b;
    std::shuffle(block_order.begin(), block_order.end(), rng);
    std::vector<int> ordering, block_start(1, 0);
    for (int b : block_order) {
      for (int i = first[b]; i < first[b + 1]; ++i) ordering.push_back(i);
      block_start.push_back(static_cast<int>(ordering.size()));
    }
    std::vector<int> position(n);
    for (int k = 0; k < n; ++k) position[ordering[k]] = k;
    const PermutedPattern p = PermuteSymmetricBlockPattern(
        n, a.outer.data(), a.inner.data(), position, block_start);
    ASSERT_EQ(static_cast<int>(p.column_start.size()), n + 1);
    std::vector<int> filled;
    const std::vector<double> permuted = PlaceValues(a, p, &filled);
    EXPECT_TRUE(std::all_of(filled.begin(), filled.end(),
                            [](int f) { return f <= 1; }));
    // The pattern: the block pairs holding an entry, whole; the values.
    auto active = [&](int r, int c) {
      for (int i = first[r]; i < first[r + 1]; ++i) {
        for (int j = first[c]; j < first[c + 1]; ++j) {
          if (dense[i][j] != 0) return true;
        }
      }
      return false;
    };
    int expected_entries = 0;
    for (int k = 0; k < n; ++k) {
      for (int row = 0; row <= k; ++row) {
        expected_entries +=
            active(block_of[ordering[row]], block_of[ordering[k]]);
      }
      for (int t = p.column_start[k]; t < p.column_start[k + 1]; ++t) {
        const int row = p.row_index[t];
        ASSERT_LE(row, k);
        if (t > p.column_start[k]) {
          ASSERT_LT(p.row_index[t - 1], row);
        }
        EXPECT_TRUE(active(block_of[ordering[row]], block_of[ordering[k]]));
        EXPECT_EQ(permuted[t], dense[ordering[row]][ordering[k]]);
      }
    }
    EXPECT_EQ(p.column_start[n], expected_entries) << "trial " << trial;
    // Both analyses; the split however small the matrix.
    DoubleDoubleCholesky scalar(Split(1)), blocked(Split(1)),
        scalar_dd(Split(1)), blocked_dd(Split(1));
    scalar.Analyze(n, p.column_start, p.row_index);
    blocked.Analyze(n, p.column_start, p.row_index, block_start);
    scalar_dd.Analyze(n, p.column_start, p.row_index);
    blocked_dd.Analyze(n, p.column_start, p.row_index, block_start);
    EXPECT_EQ(blocked.flops(), scalar.flops());
    EXPECT_EQ(blocked.factor_start(), scalar.factor_start());
    EXPECT_EQ(blocked.supernode_start(), scalar.supernode_start());
    EXPECT_EQ(blocked.supernodal_entries(), scalar.supernodal_entries());
    EXPECT_EQ(blocked.num_bins(), scalar.num_bins());
    EXPECT_EQ(blocked.factor_row(), scalar.factor_row());
    std::vector<DoubleDouble> extended(permuted.size());
    for (size_t t = 0; t < permuted.size(); ++t) {
      extended[t] = DoubleDouble(permuted[t]);
    }
    ASSERT_TRUE(scalar.Factorize(permuted));
    ASSERT_TRUE(blocked.Factorize(permuted));
    ASSERT_TRUE(scalar_dd.Factorize(extended));
    ASSERT_TRUE(blocked_dd.Factorize(extended));
    EXPECT_EQ(BitwiseDifferences(blocked, scalar), 0) << "trial " << trial;
    EXPECT_EQ(BitwiseDifferences(blocked_dd, scalar_dd), 0);
    for (auto [x, y] :
         {std::pair(&blocked, &scalar), std::pair(&blocked_dd, &scalar_dd)}) {
      std::vector<double> rho_x, rho_y;
      x->RowBackwardErrorBounds(&rho_x);
      y->RowBackwardErrorBounds(&rho_y);
      EXPECT_EQ(rho_x, rho_y) << "trial " << trial;
    }
    // The pattern without the completion, where it differs, is refused.
    const PermutedPattern incomplete =
        PermuteSymmetricPattern(n, a.outer.data(), a.inner.data(), position);
    if (incomplete.column_start[n] < p.column_start[n] && refused < 2) {
      ++refused;
      DoubleDoubleCholesky refusing;
      EXPECT_DEATH(refusing.Analyze(n, incomplete.column_start,
                                    incomplete.row_index, block_start),
                   "not block-full");
    }
  }
  EXPECT_EQ(refused, 2);
}

}  // namespace
}  // namespace ceres_sesync::internal
