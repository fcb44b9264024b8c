// SparseCholeskyFactor's row-wise solves X = B A^{-1} against a dense LLT,
// for factors CHOLMOD produced as simplicial and as supernodal, every rank r
// the fixed-size kernels cover (and one beyond, the dynamic fallback), and
// the zero-padded "tail" solve the preconditioner uses.

#include "ceres_sesync/internal/sparse_cholesky_factor.h"

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/internal/extended_cholesky.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "gtest/gtest.h"

namespace ceres_sesync::internal {
namespace {

// The lower triangle of a weighted graph Laplacian plus shift * I: SPD and
// diagonally dominant. Calls add_edges(edge) with edge(i, j, w) adding the
// edge {i, j} of weight w > 0 (loops i == j are ignored; duplicates sum).
template <typename AddEdges>
SparseMatrix ShiftedLaplacian(int n, double shift, AddEdges&& add_edges) {
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(n, shift);
  add_edges([&](int i, int j, double w) {
    if (i == j) return;
    t.emplace_back(std::max(i, j), std::min(i, j), -w);
    diagonal(i) += w;
    diagonal(j) += w;
  });
  for (int i = 0; i < n; ++i) t.emplace_back(i, i, diagonal(i));
  SparseMatrix A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

// A random sparse SPD matrix: a ring plus random chords (fill after
// reordering), diagonally dominant so it is well conditioned.
SparseMatrix RandomSpd(int n, int extra_edges, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> weight(0.1, 2.0);
  std::uniform_int_distribution<int> vertex(0, n - 1);
  return ShiftedLaplacian(n, 0.5, [&](auto&& edge) {
    auto random_edge = [&](int i, int j) {
      if (i != j) edge(i, j, weight(rng));  // No weight drawn for loops.
    };
    for (int i = 0; i < n; ++i) random_edge(i, (i + 1) % n);
    for (int k = 0; k < extra_edges; ++k) {
      const int i = vertex(rng);
      random_edge(i, vertex(rng));
    }
  });
}

// X = B A^{-1} and the tail solve (A's leading `offset` = 120 unknowns with
// a zero right-hand side, dropped from the result) for random B with r
// rows, against a dense LLT of A. cond(A) is small (diagonal dominance), so
// both agree to a modest multiple of machine epsilon.
void ExpectSolvesMatchDense(const SparseCholeskyFactor& solver,
                            const Eigen::MatrixXd& dense, int r) {
  const int n = static_cast<int>(dense.rows());
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(r, n);
  Eigen::MatrixXd X;
  solver.SolveRows(B, &X);
  const Eigen::MatrixXd expected = dense.llt().solve(B.transpose()).transpose();
  EXPECT_LT((X - expected).norm() / expected.norm(), 1e-12) << r;
  const int offset = 120;
  const Eigen::MatrixXd tail_B = Eigen::MatrixXd::Random(r, n - offset);
  Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(r, n);
  padded.rightCols(n - offset) = tail_B;
  Eigen::MatrixXd tail_X;
  solver.SolveRowsTail(tail_B, offset, &tail_X);
  const Eigen::MatrixXd full =
      dense.llt().solve(padded.transpose()).transpose();
  ASSERT_EQ(tail_X.cols(), n - offset);
  EXPECT_LT((tail_X - full.rightCols(n - offset)).norm() / full.norm(), 1e-12)
      << r;
}

class SparseCholeskyFactorTest
    : public ::testing::TestWithParam<std::tuple<bool, int>> {};

TEST_P(SparseCholeskyFactorTest, SolveRowsMatchesDenseSolve) {
  const auto [supernodal, r] = GetParam();
  const int n = 300;
  const SparseMatrix A = RandomSpd(n, 900, 7);
  CholmodFactor factor;
  ConfigureCholmod(
      supernodal ? CholmodLayout::kSupernodal : CholmodLayout::kSimplicial,
      &factor);
  factor.compute(A);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const SparseCholeskyFactor solver = factor.ExtractFactor();
  ASSERT_EQ(solver.size(), n);

  ExpectSolvesMatchDense(solver,
                         Eigen::MatrixXd(A).selfadjointView<Eigen::Lower>(), r);
}

// The supernodal constructor, from extended_cholesky.h's double factor of
// P A P^T (a random ordering P): the same solves as a dense LLT of A, for
// every rank r the fixed-size kernels cover, and the tail solve.
TEST(SparseCholeskyFactor, FromSupernodesMatchesDenseSolve) {
  const int n = 300;
  const SparseMatrix A = RandomSpd(n, 900, 11);
  std::vector<int> ordering(n), position(n);
  for (int k = 0; k < n; ++k) ordering[k] = k;
  std::shuffle(ordering.begin(), ordering.end(), std::mt19937(3));
  for (int k = 0; k < n; ++k) position[ordering[k]] = k;
  // The upper triangle of P A P^T in compressed columns.
  std::vector<std::vector<std::pair<int, double>>> columns(n);
  for (int c = 0; c < n; ++c) {
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      const int pr = position[it.row()], pc = position[c];
      columns[std::max(pr, pc)].emplace_back(std::min(pr, pc), it.value());
    }
  }
  std::vector<int> start(1, 0), row;
  std::vector<double> value;
  for (auto& column : columns) {
    std::sort(column.begin(), column.end());
    for (const auto& [r, v] : column) {
      row.push_back(r);
      value.push_back(v);
    }
    start.push_back(static_cast<int>(row.size()));
  }
  DoubleDoubleCholesky chol;
  chol.Analyze(n, start, row);
  ASSERT_TRUE(chol.Factorize(value));
  ASSERT_GT(chol.num_supernodes(), 1);
  const SparseCholeskyFactor solver(
      ordering, [&](const SparseCholeskyFactor::SupernodeVisitor& visit) {
        chol.ForEachSupernode(visit);
      });
  ASSERT_EQ(solver.size(), n);
  EXPECT_EQ(solver.num_supernodes(), chol.num_supernodes());
  const Eigen::MatrixXd dense =
      Eigen::MatrixXd(A).selfadjointView<Eigen::Lower>();
  for (int r = 1; r <= 7; ++r) ExpectSolvesMatchDense(solver, dense, r);

  // RefreshValues: the factor of A + 3 I (same analysis) copied into this
  // solver solves with A + 3 I, bitwise as a solver built from it.
  std::vector<double> shifted = value;
  for (int c = 0; c < n; ++c) {
    for (int q = start[c]; q < start[c + 1]; ++q) {
      if (row[q] == c) shifted[q] += 3;
    }
  }
  ASSERT_TRUE(chol.Factorize(shifted));
  auto supernodes = [&](const SparseCholeskyFactor::SupernodeVisitor& visit) {
    chol.ForEachSupernode(visit);
  };
  SparseCholeskyFactor refreshed = solver;
  refreshed.RefreshValues(supernodes);
  const SparseCholeskyFactor fresh(ordering, supernodes);
  const Eigen::MatrixXd dense_shifted =
      dense + 3 * Eigen::MatrixXd::Identity(n, n);
  for (int r = 1; r <= 3; ++r)
    ExpectSolvesMatchDense(refreshed, dense_shifted, r);
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(2, n);
  Eigen::MatrixXd x_refreshed, x_fresh;
  refreshed.SolveRows(B, &x_refreshed);
  fresh.SolveRows(B, &x_fresh);
  EXPECT_EQ(x_refreshed, x_fresh);
}

// The certificate relies on the factorization failing for matrices that are
// not positive definite, in every layout (a simplicial LDL^T would succeed).
TEST(ConfigureCholmod, EveryLayoutRejectsIndefiniteMatrices) {
  const int n = 200;
  SparseMatrix A = RandomSpd(n, 600, 11);
  const Eigen::MatrixXd dense =
      Eigen::MatrixXd(A).selfadjointView<Eigen::Lower>();
  const double lambda_min =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense).eigenvalues()(0);
  for (CholmodLayout layout :
       {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal,
        CholmodLayout::kAutomatic}) {
    for (double shift : {-1.001 * lambda_min, -0.999 * lambda_min}) {
      SparseMatrix shifted = A;
      for (int k = 0; k < n; ++k) shifted.coeffRef(k, k) += shift;
      CholmodFactor factor;
      ConfigureCholmod(layout, &factor);
      factor.compute(shifted);
      // shift > -lambda_min: PD; shift < -lambda_min: one negative eigenvalue.
      EXPECT_EQ(factor.info() == Eigen::Success, shift > -lambda_min)
          << "layout " << static_cast<int>(layout) << " shift " << shift;
    }
  }
}

// Access to the CHOLMOD factor, to compute the true residual in the test.
class InspectableFactor : public CholmodFactor {
 public:
  const cholmod_factor& raw() const { return *m_cholmodFactor; }
};

// RowBackwardErrorBounds (in place, simplicial or supernodal) bounds the
// true backward error row by row: for every row, sum_j |(L L^T - P A
// P^T)_ij| (computed in long double from the factor converted by CHOLMOD
// itself) <= rho of its original index. Both layouts bound the same matrix
// alike (compared on the largest bound of two blocks of original indices).
TEST(CholmodFactor, RowBackwardErrorBoundsCoverTheTrueResidual) {
  const int n = 300, split = 120;
  const SparseMatrix A = RandomSpd(n, 2500, 17);
  const Eigen::MatrixXd dense =
      Eigen::MatrixXd(A).selfadjointView<Eigen::Lower>();
  double bounds[2][2];  // [layout][head, tail]
  int layout_index = 0;
  for (CholmodLayout layout :
       {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal}) {
    InspectableFactor factor;
    ConfigureCholmod(layout, &factor);
    factor.compute(A);
    ASSERT_EQ(factor.info(), Eigen::Success);
    EXPECT_EQ(factor.IsSupernodal(), layout == CholmodLayout::kSupernodal);
    std::vector<double> rho;
    factor.RowBackwardErrorBounds(&rho);
    ASSERT_EQ(static_cast<int>(rho.size()), n);
    double head = 0, tail = 0;
    for (int i = 0; i < n; ++i) {
      double& side = i < split ? head : tail;
      side = std::max(side, rho[i]);
    }
    bounds[layout_index][0] = head;
    bounds[layout_index][1] = tail;
    ++layout_index;

    // Dense L from a simplicial packed copy (CHOLMOD's own conversion).
    cholmod_common* common = &factor.cholmod();
    cholmod_factor* copy =
        cholmod_copy_factor(const_cast<cholmod_factor*>(&factor.raw()), common);
    ASSERT_TRUE(cholmod_change_factor(CHOLMOD_REAL, 1, 0, 1, 1, copy, common));
    Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> L =
        Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>::Zero(n, n);
    const int* p = static_cast<const int*>(copy->p);
    const int* row = static_cast<const int*>(copy->i);
    const double* x = static_cast<const double*>(copy->x);
    for (int j = 0; j < n; ++j) {
      for (int k = p[j]; k < p[j + 1]; ++k) L(row[k], j) = x[k];
    }
    const int* perm = static_cast<const int*>(copy->Perm);
    Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic> PAP(n, n);
    for (int a = 0; a < n; ++a) {
      for (int b = 0; b < n; ++b) PAP(a, b) = dense(perm[a], perm[b]);
    }
    const auto E = (L * L.transpose() - PAP).eval();
    double worst_ratio = 0;
    for (int a = 0; a < n; ++a) {
      const double row_error = static_cast<double>(E.row(a).cwiseAbs().sum());
      const double bound = rho[perm[a]];
      EXPECT_LE(row_error, bound)
          << "row " << a << " layout " << static_cast<int>(layout);
      worst_ratio = std::max(worst_ratio, row_error / bound);
    }
    EXPECT_GT(worst_ratio, 0.0);  // The residual is really measured.
    cholmod_free_factor(&copy, common);
  }
  // Same matrix, same bound formula, different stored patterns (supernodes
  // store some zeros): the same order of magnitude.
  for (int side = 0; side < 2; ++side) {
    EXPECT_GT(bounds[1][side], 0.5 * bounds[0][side]);
    EXPECT_LT(bounds[1][side], 4 * bounds[0][side]);
  }
}

// Rows are split over threads with unchanged arithmetic: bitwise identical
// results (the matrix is large enough to pass the parallel work threshold).
TEST(SparseCholeskyFactor, ThreadsGiveIdenticalResults) {
  const int n = 4000;
  const SparseMatrix A = RandomSpd(n, 8000, 3);
  CholmodFactor factor;
  ConfigureCholmod(CholmodLayout::kAutomatic, &factor);
  factor.compute(A);
  ASSERT_EQ(factor.info(), Eigen::Success);
  const SparseCholeskyFactor solver = factor.ExtractFactor();
  // Threads engage (ThreadsFor: 4 r entries >= 1e7) for every r below.
  EXPECT_GE(4.0 * 3 * solver.stored_entries(), 1e7);
  for (int r : {3, 5, 7}) {
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(r, n - 10);
    Eigen::MatrixXd serial, parallel;
    solver.SolveRowsTail(B, 10, &serial, 1);
    for (int threads : {2, 3, 16}) {
      solver.SolveRowsTail(B, 10, &parallel, threads);
      EXPECT_TRUE(parallel == serial) << "r " << r << " threads " << threads;
    }
  }
}

// The Laplacian of a side x side grid plus a diagonal: its nested-dissection
// factor has two large independent subtrees below a small top separator, so
// the solves run split (bins and top).
SparseMatrix GridSpd(int side) {
  return ShiftedLaplacian(side * side, 0.25, [&](auto&& edge) {
    for (int y = 0; y < side; ++y) {
      for (int x = 0; x < side; ++x) {
        const int i = y * side + x;
        if (x + 1 < side) edge(i, i + 1, 1.0 + 0.01 * (i % 7));
        if (y + 1 < side) edge(i, i + side, 1.0 + 0.01 * (i % 5));
      }
    }
  });
}

// The split schedule (bins solved concurrently, their updates of the top
// accumulated separately): residuals of X A = B at the level of a backward
// stable solve, in every layout and precision of the stored factor, for full
// and tail solves, and bitwise the same results for every thread count.
TEST(SparseCholeskyFactor, SplitSolvesAreAccurateAndThreadIndependent) {
  const int side = 200, n = side * side;
  const SparseMatrix lower = GridSpd(side);
  const SparseMatrix A = lower.selfadjointView<Eigen::Lower>();
  for (CholmodLayout layout :
       {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal}) {
    CholmodFactor factor;
    ConfigureCholmod(layout, &factor);
    factor.compute(lower);
    ASSERT_EQ(factor.info(), Eigen::Success);
    SparseCholeskyFactor solver = factor.ExtractFactor();
    ASSERT_EQ(solver.num_bins(), 2) << "layout " << static_cast<int>(layout);
    // Large enough for threads at r >= 3 (ThreadsFor: 4 r entries >= 1e7).
    EXPECT_GE(4.0 * 3 * solver.stored_entries(), 1e7);
    EXPECT_GT(solver.top_entries(), 0);
    EXPECT_LT(solver.top_entries(), solver.stored_entries() / 4);
    for (const bool single : {false, true}) {
      if (single) solver.ConvertToSinglePrecision();
      for (int r : {1, 3, 7}) {
        const Eigen::MatrixXd B = Eigen::MatrixXd::Random(r, n);
        Eigen::MatrixXd X, parallel;
        solver.SolveRows(B, &X, 1);
        // cond(A) <= 8.3 / 0.25 (Gershgorin): a backward stable solve leaves
        // a residual of a modest multiple of eps cond(A); the single factor
        // is a preconditioner within ~2^-24 cond(A) relative of the inverse.
        const double tolerance = single ? 1e-5 : 1e-12;
        EXPECT_LT((X * A - B).norm() / B.norm(), tolerance)
            << "r " << r << " single " << single;
        for (int threads : {2, 3, 16}) {
          solver.SolveRows(B, &parallel, threads);
          EXPECT_TRUE(parallel == X) << "r " << r << " threads " << threads;
        }
        // Tail: the leading `offset` unknowns have zero right-hand side.
        const int offset = n / 3;
        const Eigen::MatrixXd tail_B = B.rightCols(n - offset);
        Eigen::MatrixXd padded = B;
        padded.leftCols(offset).setZero();
        solver.SolveRows(padded, &X, 1);
        for (int threads : {1, 2, 5}) {
          solver.SolveRowsTail(tail_B, offset, &parallel, threads);
          EXPECT_TRUE(parallel == X.rightCols(n - offset))
              << "tail r " << r << " threads " << threads;
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllKernels, SparseCholeskyFactorTest,
                         ::testing::Combine(::testing::Bool(),
                                            ::testing::Range(1, 9)));

}  // namespace
}  // namespace ceres_sesync::internal
