// Independent tests of the SE-Sync data matrices (internal/sesync_problem.h)
// and of the Burer-Monteiro cost (internal/sesync_cost.h).
//
// The reference for Q is built DENSELY in the test from first principles
// (tests/util/test_graphs.h: the data matrix M assembled residual by residual,
// then the Schur complement of its translation block), and cross-checked
// against the paper's own formula Q = L(G^rho) + T^T Omega^1/2 Pi Omega^1/2 T
// (Rosen et al. 2019, eq. 24) with Pi computed by an SVD. Derivatives of the
// cost are checked by finite differences along retraction curves.

#include "ceres_sesync/internal/sesync_problem.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using internal::PreconditionerType;
using internal::SESyncCost;
using internal::SESyncPreconditioner;
using internal::SESyncProblem;
using test_util::DenseQ;
using test_util::DenseQFromPaper;
using test_util::RandomGraphOptions;
using test_util::RandomPoseGraph;

double RelativeError(const MatrixXd& a, const MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

MatrixXd Gaussian(int rows, int cols, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  MatrixXd m(rows, cols);
  for (Eigen::Index k = 0; k < m.size(); ++k) m.data()[k] = normal(*rng);
  return m;
}

double Inner(const MatrixXd& a, const MatrixXd& b) {
  return a.cwiseProduct(b).sum();
}

// A family of small graphs: 2D and 3D, trees, sparse and dense loop closures,
// varied precisions (including strongly anisotropic kappa vs tau).
std::vector<RandomGraphOptions> SmallGraphFamily() {
  std::vector<RandomGraphOptions> family;
  uint64_t seed = 1;
  for (int d : {2, 3}) {
    for (int n : {2, 3, 12, 40}) {
      for (int loops : {0, n / 2, 3 * n}) {
        for (double kappa : {1.0, 500.0}) {
          RandomGraphOptions o;
          o.dimension = d;
          o.num_poses = n;
          o.num_loop_closures = loops;
          o.kappa = kappa;
          o.tau = kappa == 1.0 ? 300.0 : 0.5;
          o.seed = seed++;
          family.push_back(o);
        }
      }
    }
  }
  return family;
}

// The test's own two dense references agree (guards the reference itself).
TEST(DenseReference, DataMatrixSchurComplementMatchesPaperFormula) {
  for (const RandomGraphOptions& o : SmallGraphFamily()) {
    const PoseGraph graph = RandomPoseGraph(o, nullptr);
    EXPECT_LT(RelativeError(DenseQ(graph), DenseQFromPaper(graph)), 1e-11)
        << "d " << o.dimension << " n " << o.num_poses;
  }
}

// The dense data matrix reproduces the objective (12): tr(X M X^T) = F(x).
TEST(DenseReference, DataMatrixReproducesObjective) {
  std::mt19937_64 rng(7);
  for (const RandomGraphOptions& o : SmallGraphFamily()) {
    const PoseGraph graph = RandomPoseGraph(o, nullptr);
    const Poses x = test_util::RandomPoses(o.dimension, o.num_poses, 2, &rng);
    MatrixXd X(o.dimension, o.num_poses * (1 + o.dimension));
    X << test_util::StackTranslations(x), test_util::StackRotations(x);
    const double f = EvaluateObjective(graph, x);
    EXPECT_NEAR((X * test_util::DenseDataMatrix(graph) * X.transpose()).trace(),
                f, 1e-11 * f);
  }
}

// MultiplyQ(Y) = Y Q for random Y of several ranks; Q dense from M.
TEST(SESyncProblem, MultiplyQMatchesDenseQ) {
  std::mt19937_64 rng(11);
  for (const RandomGraphOptions& o : SmallGraphFamily()) {
    const PoseGraph graph = RandomPoseGraph(o, nullptr);
    ASSERT_TRUE(ValidatePoseGraph(graph, nullptr));
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    EXPECT_EQ(problem.dimension(), o.dimension);
    EXPECT_EQ(problem.num_rotations(), o.num_poses);
    EXPECT_EQ(problem.num_translations(), o.num_poses);
    const MatrixXd Q = DenseQ(graph);
    for (int r : {1, o.dimension, o.dimension + 2}) {
      const MatrixXd Y = Gaussian(r, o.dimension * o.num_poses, &rng);
      MatrixXd YQ;
      problem.MultiplyQ(Y, &YQ);
      ASSERT_EQ(YQ.rows(), r);
      ASSERT_EQ(YQ.cols(), Y.cols());
      // Round-off: a few sparse products and one Cholesky solve with the
      // translational Laplacian (condition number <= ~1e4 here): 1e-10.
      EXPECT_LT(RelativeError(YQ, Y * Q), 1e-10)
          << "d " << o.dimension << " n " << o.num_poses << " loops "
          << o.num_loop_closures << " r " << r;
    }
  }
}

// MultiplyQ where Lbar's fill is heavy enough for CHOLMOD's supernodal layout
// (a 3D lattice with loop closures to half of the poses within 4 lattice
// units: Lbar nearly dense), whose factor its solves then read. Reference:
// Y Q = Y D - Y Vbar^T Lbar^{-1} Vbar from the problem's own sparse matrices
// with a dense Cholesky of Lbar (the matrices themselves are checked against
// the paper's Q above; this checks the solves).
TEST(SESyncProblem, MultiplyQMatchesDenseReferenceWithSupernodalLbar) {
  CubeOptions options;
  options.side = 10;
  options.loop_closure_probability = 0.5;
  options.loop_closure_radius = 4;
  options.kappa = 100;
  options.tau = 400;
  PoseGraph graph;
  ASSERT_TRUE(GenerateCube(options, &graph, nullptr, nullptr));
  SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  ASSERT_TRUE(problem.LbarIsSupernodal());
  const MatrixXd Vbar(problem.Vbar());
  const MatrixXd Lbar(problem.Lbar());
  std::mt19937_64 rng(12);
  const MatrixXd Y = Gaussian(5, 3 * graph.num_poses, &rng);
  // Y Q without forming Q (Lbar is symmetric).
  const MatrixXd YVt_Linv = Lbar.llt().solve(Vbar * Y.transpose()).transpose();
  const MatrixXd reference = Y * MatrixXd(problem.D()) - YVt_Linv * Vbar;
  MatrixXd YQ;
  problem.MultiplyQ(Y, &YQ);
  // Round-off of the sparse products and of two Cholesky solves with Lbar
  // (the lattice is compact and densely connected: well conditioned).
  EXPECT_LT(RelativeError(YQ, reference), 1e-10);
}

// The documented sparse pieces: M = [L(W^tau) -V; -V^T D], Lbar and Vbar drop
// pose 0, and L(G^rho) = D - Sigma is Q of the same graph with t~ = 0.
TEST(SESyncProblem, SparseBlocksMatchDenseDataMatrix) {
  for (const RandomGraphOptions& o : SmallGraphFamily()) {
    const PoseGraph graph = RandomPoseGraph(o, nullptr);
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    const int d = o.dimension, n = o.num_poses;
    const MatrixXd M = test_util::DenseDataMatrix(graph);
    const double scale = M.norm();
    EXPECT_LT(
        (MatrixXd(problem.D()) - M.bottomRightCorner(d * n, d * n)).norm(),
        1e-13 * scale);
    EXPECT_LT((MatrixXd(problem.Vbar()) + M.block(1, n, n - 1, d * n)).norm(),
              1e-13 * scale);
    const MatrixXd Lbar =
        MatrixXd(problem.Lbar()).selfadjointView<Eigen::Lower>();
    EXPECT_LT((Lbar - M.block(1, 1, n - 1, n - 1)).norm(), 1e-13 * scale);
    PoseGraph rotation_only = graph;
    for (auto& e : rotation_only.measurements) e.t.setZero();
    EXPECT_LT(RelativeError(MatrixXd(problem.RotationLaplacian()),
                            DenseQ(rotation_only)),
              1e-12);
  }
}

// Rotations -> F(Y) with Y = R equals F(x) at the optimal translations, which
// are pose 0 at the origin and are a stationary point (and minimum) in t.
TEST(SESyncProblem, RecoverTranslationsIsOptimalAndReproducesObjective) {
  std::mt19937_64 rng(13);
  for (const RandomGraphOptions& o : SmallGraphFamily()) {
    Poses truth;
    const PoseGraph graph = RandomPoseGraph(o, &truth);
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    const int d = o.dimension, n = o.num_poses;
    std::vector<MatrixXd> rotation_sets = {
        test_util::StackRotations(truth),
        test_util::StackRotations(test_util::RandomPoses(d, n, 1, &rng))};
    for (const MatrixXd& R : rotation_sets) {
      const MatrixXd T = problem.RecoverTranslations(R);
      ASSERT_EQ(T.rows(), d);
      ASSERT_EQ(T.cols(), n);
      EXPECT_EQ(T.col(0).norm(), 0.0) << "documented gauge t_0 = 0";
      const Poses x = test_util::PosesFromMatrices(R, T);
      const double f = EvaluateObjective(graph, x);
      MatrixXd RQ;
      problem.MultiplyQ(R, &RQ);
      const double f_rotations = Inner(R, RQ);
      // Both are sums of m nonnegative terms of size ~f: 1e-10 relative.
      EXPECT_NEAR(f_rotations, f, 1e-10 * std::max(f, 1e-12))
          << "d " << d << " n " << n;
      // Stationarity in t: F(T + s P) - F(T - s P) = 4 s <grad_T F, P> = 0,
      // and minimality: F(T + s P) >= F(T).
      for (int trial = 0; trial < 5; ++trial) {
        const MatrixXd P = Gaussian(d, n, &rng);
        const double s = 0.3;
        const double f_plus = EvaluateObjective(
            graph, test_util::PosesFromMatrices(R, T + s * P));
        const double f_minus = EvaluateObjective(
            graph, test_util::PosesFromMatrices(R, T - s * P));
        const double curvature = f_plus + f_minus - 2 * f;
        EXPECT_GE(f_plus, f - 1e-12 * f);
        EXPECT_GE(f_minus, f - 1e-12 * f);
        // The odd part must vanish relative to the even (curvature) part and
        // the round-off of the sums (~1e-14 (f_plus + f_minus)).
        EXPECT_LE(std::abs(f_plus - f_minus),
                  1e-9 * curvature + 1e-12 * (f_plus + f_minus));
      }
    }
  }
}

TEST(SESyncProblem, BlockDiagonalMultiplyMatchesDense) {
  std::mt19937_64 rng(17);
  for (int d : {2, 3}) {
    // r = d .. d + 3 take the fixed-size kernels, d + 4 the dynamic one.
    for (int r = d; r <= d + 4; ++r) {
      const int n = 7;
      const MatrixXd V = Gaussian(r, d * n, &rng);
      const MatrixXd Lambda = Gaussian(d, d * n, &rng);
      MatrixXd out;
      internal::BlockDiagonalMultiply(V, Lambda, d, &out);
      EXPECT_LT(
          RelativeError(out, V * test_util::BlockDiagonalToDense(Lambda, d)),
          1e-15)
          << "d " << d << " r " << r;
    }
  }
}

// ---------------------------------------------------------------------------
// Landmarks and priors: the index sets of ProblemLayout (sesync_problem.h),
// checked against DenseLandmarkDataMatrix (built residual by residual in the
// test, independent of ForEachDataTerm).

struct LandmarkCase {
  std::string name;
  test_util::RandomLandmarkGraphOptions options;
};

// Landmarks only, each kind of prior alone, all together; trees (no loop
// closures) and landmarks seen by a single pose; 2D and 3D.
std::vector<LandmarkCase> LandmarkGraphFamily() {
  std::vector<LandmarkCase> family;
  uint64_t seed = 500;
  for (int d : {2, 3}) {
    for (int n : {1, 3, 15}) {
      for (int kind = 0; kind < 5; ++kind) {
        LandmarkCase c;
        auto& o = c.options;
        o.poses.dimension = d;
        o.poses.num_poses = n;
        o.poses.num_loop_closures = n / 3;
        o.poses.kappa = kind == 4 ? 500 : 20;
        o.poses.tau = kind == 4 ? 0.5 : 10;
        o.poses.seed = seed++;
        o.num_landmarks = n == 1 ? 3 : 2 * n;
        o.observations_per_landmark = kind == 0 ? 1 : 3;
        o.nu = 7;
        const char* names[] = {"landmarks seen once", "position priors",
                               "rotation priors", "pose priors",
                               "all priors, anisotropic"};
        c.name = std::string(names[kind]) + " d " + std::to_string(d) + " n " +
                 std::to_string(n);
        if (kind == 1) o.num_position_priors = 2;
        if (kind == 2) o.num_rotation_priors = 2;
        if (kind == 3) o.num_pose_priors = 1;
        if (kind == 4) {
          o.num_position_priors = 2;
          o.num_rotation_priors = 1;
          o.num_pose_priors = 1;
          o.prior_kappa = 1e4;
          o.prior_tau = 0.1;
        }
        // A single pose with rotation priors only has nothing to place its
        // translation but itself; keep it (the gauge is pose 0 then).
        family.push_back(c);
      }
    }
  }
  return family;
}

// The two dense routes to Q agree (pseudo-inverse of the whole translation
// block vs Cholesky of the reduced one): guards the references.
TEST(DenseReference, LandmarkSchurComplementsAgree) {
  for (const LandmarkCase& c : LandmarkGraphFamily()) {
    const PoseGraph graph = test_util::RandomLandmarkGraph(c.options, nullptr);
    ASSERT_TRUE(ValidatePoseGraph(graph, nullptr)) << c.name;
    const test_util::DenseLandmarkProblem dense =
        test_util::BuildDenseLandmarkProblem(graph);
    // Relative to Q, or to D where Q is zero (a single pose whose landmarks
    // are each seen once: any rotation fits them exactly).
    EXPECT_LT((dense.Q - test_util::DenseLandmarkQ(graph)).norm(),
              1e-10 * std::max(dense.Q.norm(), dense.D.norm()))
        << c.name;
  }
}

// The layout's sizes and the sparse D, Vbar, Lbar equal the dense blocks in
// the documented index sets (landmarks after the poses, t_w last and the
// gauge when some prior has a position term, R_w after the poses).
TEST(SESyncProblem, LandmarkBlocksMatchDenseDataMatrix) {
  for (const LandmarkCase& c : LandmarkGraphFamily()) {
    const PoseGraph graph = test_util::RandomLandmarkGraph(c.options, nullptr);
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok()) << c.name;
    const int n = graph.num_poses, L = graph.num_landmarks;
    bool position = false;
    for (const PosePrior& p : graph.priors) position |= p.has_position();
    EXPECT_EQ(problem.num_rotations(), n + (graph.priors.empty() ? 0 : 1));
    EXPECT_EQ(problem.num_translations(), n + L + (position ? 1 : 0));
    EXPECT_EQ(problem.layout().gauge(), position ? n + L : 0);
    const test_util::DenseLandmarkProblem dense =
        test_util::BuildDenseLandmarkProblem(graph);
    const double scale = dense.D.norm() + dense.Lbar.norm();
    EXPECT_LT((MatrixXd(problem.D()) - dense.D).norm(), 1e-13 * scale)
        << c.name;
    EXPECT_LT((MatrixXd(problem.Vbar()) - dense.Vbar).norm(), 1e-13 * scale)
        << c.name;
    EXPECT_LT((MatrixXd(problem.Lbar()) - dense.Lbar).norm(), 1e-13 * scale)
        << c.name;
    // One vertex per pose, landmark and (with priors) the world.
    std::vector<int> ordering = problem.vertex_ordering();
    std::sort(ordering.begin(), ordering.end());
    std::vector<int> expected(n + L + (graph.priors.empty() ? 0 : 1));
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(ordering, expected) << c.name;
  }
}

TEST(SESyncProblem, LandmarkMultiplyQMatchesDenseQ) {
  std::mt19937_64 rng(41);
  for (const LandmarkCase& c : LandmarkGraphFamily()) {
    const PoseGraph graph = test_util::RandomLandmarkGraph(c.options, nullptr);
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    const MatrixXd Q = test_util::DenseLandmarkQ(graph);
    const double D_norm = MatrixXd(problem.D()).norm();
    const int d = graph.dimension;
    ASSERT_EQ(Q.rows(), d * problem.num_rotations());
    for (int r : {1, d + 2}) {
      const MatrixXd Y = Gaussian(r, static_cast<int>(Q.rows()), &rng);
      MatrixXd YQ;
      problem.MultiplyQ(Y, &YQ);
      // As for pose graphs: sparse products and one solve, 1e-10 (relative
      // to D where Q vanishes).
      EXPECT_LT((YQ - Y * Q).norm(),
                1e-10 * std::max(Q.norm(), D_norm) * Y.norm())
          << c.name << " r " << r;
    }
  }
}

// The recovered translations and landmark positions are the minimizers of F
// for the rotations: F(x) equals <R, R Q> there, and perturbing any of them
// does not decrease F (stationary, convex). R_w = I and (when present)
// t_w = 0, so the solver's frame is the world frame.
TEST(SESyncProblem, LandmarkRecoverTranslationsIsOptimal) {
  std::mt19937_64 rng(43);
  for (const LandmarkCase& c : LandmarkGraphFamily()) {
    Solution truth;
    const PoseGraph graph = test_util::RandomLandmarkGraph(c.options, &truth);
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    const int d = graph.dimension, n = graph.num_poses, L = graph.num_landmarks;
    const MatrixXd R = test_util::StackSolverRotations(graph, truth.poses);
    const MatrixXd T = problem.RecoverTranslations(R);
    ASSERT_EQ(T.rows(), d);
    ASSERT_EQ(T.cols(), problem.num_translations());
    EXPECT_EQ(T.col(problem.layout().gauge()).norm(), 0.0);
    auto solution = [&](const MatrixXd& translations) {
      Solution x;
      for (int i = 0; i < n; ++i) {
        x.poses.push_back(Pose{truth.poses[i].R, translations.col(i)});
      }
      for (int l = 0; l < L; ++l)
        x.landmarks.push_back(translations.col(n + l));
      return x;
    };
    const double f = EvaluateObjective(graph, solution(T));
    MatrixXd RQ;
    problem.MultiplyQ(R, &RQ);
    // F is a sum of nonnegative terms: 1e-10 relative, plus the round-off
    // of the implicit Q's cancellation where F vanishes (1e-12 of the
    // data's scale tr(D)).
    const double floor = 1e-12 * MatrixXd(problem.D()).trace();
    EXPECT_NEAR(Inner(R, RQ), f, 1e-10 * f + floor) << c.name;
    for (int trial = 0; trial < 4; ++trial) {
      MatrixXd P = Gaussian(d, static_cast<int>(T.cols()), &rng);
      P.col(problem.layout().gauge()).setZero();  // t_w stays at 0.
      const double s = 0.3;
      const double f_plus = EvaluateObjective(graph, solution(T + s * P));
      const double f_minus = EvaluateObjective(graph, solution(T - s * P));
      const double curvature = f_plus + f_minus - 2 * f;
      EXPECT_GE(f_plus, f - 1e-12 * f) << c.name;
      EXPECT_GE(f_minus, f - 1e-12 * f) << c.name;
      EXPECT_LE(std::abs(f_plus - f_minus),
                1e-9 * curvature + 1e-12 * (f_plus + f_minus))
          << c.name;
    }
  }
}

// Rounding bounds: every stored entry of M (in the documented index sets)
// is within its row's bound of the exact value recomputed here in long
// double (a sum of the same terms; long double's extra digits make its own
// error negligible against the bound).
TEST(SESyncProblem, LandmarkRowRoundingBoundsCoverTheStoredMatrices) {
  for (const LandmarkCase& c : LandmarkGraphFamily()) {
    const PoseGraph graph = test_util::RandomLandmarkGraph(c.options, nullptr);
    SESyncProblem problem(graph);
    const int d = graph.dimension;
    const int N = problem.num_translations(), dn = d * problem.num_rotations();
    using LongMatrix =
        Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
    LongMatrix lw = LongMatrix::Zero(N, N), v = LongMatrix::Zero(N, dn),
               dd = LongMatrix::Zero(dn, dn);
    internal::ForEachDataTerm<long double>(
        graph, [&](internal::DataBlock block, int row, int col, long double x) {
          switch (block) {
            case internal::DataBlock::kTranslation:
              lw(row, col) += x;
              return;
            case internal::DataBlock::kCoupling:
              v(row, col) += x;
              return;
            default:
              dd(row, col) += x;
          }
        });
    const MatrixXd D(problem.D()), V(problem.Vbar()), Lbar(problem.Lbar());
    for (int q = 0; q < dn; ++q) {
      long double row = 0;
      for (int b = 0; b < dn; ++b) row += std::abs(D(q, b) - dd(q, b));
      for (int k = 0; k < N; ++k) {
        const int j = problem.layout().reduced(k);
        if (j >= 0) row += std::abs(-V(j, q) - -v(k, q));
      }
      EXPECT_LE(static_cast<double>(row), problem.rotation_row_rounding()[q])
          << c.name;
    }
    for (int k = 0; k < N; ++k) {
      const int j = problem.layout().reduced(k);
      if (j < 0) continue;
      long double row = 0;
      for (int l = 0; l < N; ++l) {
        const int i = problem.layout().reduced(l);
        if (i >= 0) row += std::abs(Lbar(j, i) - lw(k, l));
      }
      for (int q = 0; q < dn; ++q) row += std::abs(V(j, q) - v(k, q));
      EXPECT_LE(static_cast<double>(row), problem.translation_row_rounding()[k])
          << c.name;
    }
  }
}

// ---------------------------------------------------------------------------
// SESyncCost: F(Y) = tr(Q Y^T Y) on St(d, r)^n.

// The reference Q of any graph: DenseQ for pose graphs, DenseLandmarkQ
// (rotation blocks of the solver) with landmarks and priors.
MatrixXd ReferenceQ(const PoseGraph& graph) {
  return graph.has_landmarks_or_priors() ? test_util::DenseLandmarkQ(graph)
                                         : DenseQ(graph);
}

struct CostFixture {
  explicit CostFixture(PoseGraph g,
                       PreconditionerType type = PreconditionerType::kNone)
      : graph(std::move(g)),
        problem(graph),
        preconditioner(problem, type, 1e6),
        cost(&problem, &preconditioner),
        Q(ReferenceQ(graph)),
        d(graph.dimension),
        n(problem.num_rotations()) {}
  PoseGraph graph;
  SESyncProblem problem;
  SESyncPreconditioner preconditioner;
  SESyncCost cost;
  MatrixXd Q;
  int d, n;  // Dimension, rotation blocks.
};

MatrixXd RandomTangent(const MatrixXd& Y, int d, std::mt19937_64* rng) {
  MatrixXd V;
  ProjectToStiefelProductTangent(Y, Gaussian(Y.rows(), Y.cols(), rng), d, &V);
  return V;
}

// Pose graphs and graphs with landmarks and priors (landmarks change Q
// through the eliminated translations; priors add the world block R_w).
std::vector<PoseGraph> CostGraphs() {
  std::vector<PoseGraph> graphs;
  for (int d : {2, 3}) {
    RandomGraphOptions o;
    o.dimension = d;
    o.num_poses = 25;
    o.num_loop_closures = 30;
    o.kappa = 20;
    o.tau = 10;
    o.seed = 100 + d;
    graphs.push_back(RandomPoseGraph(o, nullptr));
    test_util::RandomLandmarkGraphOptions l;
    l.poses = o;
    l.poses.num_loop_closures = 3;
    l.poses.seed = 200 + d;
    l.num_landmarks = 20;
    l.observations_per_landmark = 3;
    l.nu = 15;
    graphs.push_back(test_util::RandomLandmarkGraph(l, nullptr));
    l.poses.seed = 300 + d;
    l.num_position_priors = 3;
    l.num_rotation_priors = 1;
    l.num_pose_priors = 1;
    graphs.push_back(test_util::RandomLandmarkGraph(l, nullptr));
  }
  return graphs;
}

TEST(SESyncCost, ValueAndLambdaMatchDense) {
  std::mt19937_64 rng(19);
  for (const PoseGraph& graph : CostGraphs()) {
    CostFixture fx(graph);
    const int d = fx.d, n = fx.n;
    SCOPED_TRACE(testing::Message()
                 << "d " << d << " landmarks " << graph.num_landmarks
                 << " priors " << graph.priors.size());
    for (int r : {d, d + 1, d + 3}) {
      const MatrixXd Y = RandomStiefelProductPoint(d, r, n, &rng);
      const double f = fx.cost.Evaluate(Y);
      const double f_dense = (Y * fx.Q * Y.transpose()).trace();
      EXPECT_NEAR(f, f_dense, 1e-10 * std::abs(f_dense));
      // Lambda = SymBlockDiag_d(Q Y^T Y), blockwise sym((Q Y^T Y)_ii).
      const MatrixXd QYY = fx.Q * Y.transpose() * Y;
      const MatrixXd& Lambda = fx.cost.Lambda();
      ASSERT_EQ(Lambda.rows(), d);
      ASSERT_EQ(Lambda.cols(), d * n);
      for (int i = 0; i < n; ++i) {
        const MatrixXd B = QYY.block(d * i, d * i, d, d);
        EXPECT_LT(
            (Lambda.middleCols(d * i, d) - 0.5 * (B + B.transpose())).norm(),
            1e-10 * fx.Q.norm());
      }
    }
  }
}

// d/dt F(R_Y(t V)) at t = 0 equals <grad F(Y), V> (central differences).
TEST(SESyncCost, GradientMatchesFiniteDifferencesAlongRetraction) {
  std::mt19937_64 rng(23);
  for (const PoseGraph& graph : CostGraphs()) {
    CostFixture fx(graph);
    const int d = fx.d, n = fx.n;
    SCOPED_TRACE(testing::Message()
                 << "d " << d << " landmarks " << graph.num_landmarks
                 << " priors " << graph.priors.size());
    for (int r : {d, d + 2}) {
      for (int trial = 0; trial < 3; ++trial) {
        const MatrixXd Y = RandomStiefelProductPoint(d, r, n, &rng);
        fx.cost.Evaluate(Y);
        MatrixXd g;
        fx.cost.Gradient(&g);
        // The gradient is tangent: Y_i^T g_i is skew.
        MatrixXd pg;
        ProjectToStiefelProductTangent(Y, g, d, &pg);
        EXPECT_LT((pg - g).norm(), 1e-12 * g.norm());
        // ... and is the projection of the Euclidean gradient 2 Y Q.
        MatrixXd projected;
        ProjectToStiefelProductTangent(Y, 2 * Y * fx.Q, d, &projected);
        EXPECT_LT(RelativeError(g, projected), 1e-10);
        const MatrixXd V = RandomTangent(Y, d, &rng);
        const double h = 1e-5;
        MatrixXd Yp, Ym;
        fx.cost.Retract(Y, h * V, &Yp);
        fx.cost.Retract(Y, -h * V, &Ym);
        const double fd =
            (fx.cost.Evaluate(Yp) - fx.cost.Evaluate(Ym)) / (2 * h);
        // Truncation O(h^2 |phi'''|) plus round-off ~1e-16 F / h: relative
        // to ||g|| ||V|| this is < 1e-8; a wrong factor would be O(1).
        EXPECT_NEAR(fd, Inner(g, V), 1e-7 * g.norm() * V.norm());
      }
    }
  }
}

// Hess[V] = lim Proj_Y(grad(R_Y(hV)) - grad(R_Y(-hV))) / (2h), and the
// Hessian is symmetric on the tangent space; at random (non-critical) points
// and at a point near a critical point.
TEST(SESyncCost, HessianMatchesFiniteDifferencesAndIsSymmetric) {
  std::mt19937_64 rng(29);
  for (const PoseGraph& graph : CostGraphs()) {
    CostFixture fx(graph);
    const int d = fx.d, n = fx.n;
    SCOPED_TRACE(testing::Message()
                 << "d " << d << " landmarks " << graph.num_landmarks
                 << " priors " << graph.priors.size());
    for (int r : {d, d + 2}) {
      for (int trial = 0; trial < 3; ++trial) {
        const MatrixXd Y = RandomStiefelProductPoint(d, r, n, &rng);
        const MatrixXd V = RandomTangent(Y, d, &rng);
        const MatrixXd U = RandomTangent(Y, d, &rng);
        const double h = 1e-5;
        MatrixXd Yp, Ym, gp, gm;
        fx.cost.Retract(Y, h * V, &Yp);
        fx.cost.Retract(Y, -h * V, &Ym);
        fx.cost.Evaluate(Yp);
        fx.cost.Gradient(&gp);
        fx.cost.Evaluate(Ym);
        fx.cost.Gradient(&gm);
        MatrixXd fd;
        ProjectToStiefelProductTangent(Y, (gp - gm) / (2 * h), d, &fd);
        fx.cost.Evaluate(Y);
        MatrixXd HV, HU;
        fx.cost.HessianVector(V, &HV);
        fx.cost.HessianVector(U, &HU);
        EXPECT_LT(RelativeError(HV, fd), 1e-6) << "d " << d << " r " << r;
        // Tangent output.
        MatrixXd p;
        ProjectToStiefelProductTangent(Y, HV, d, &p);
        EXPECT_LT((p - HV).norm(), 1e-12 * HV.norm());
        // Symmetry.
        const double uhv = Inner(U, HV), vhu = Inner(V, HU);
        EXPECT_NEAR(uhv, vhu, 1e-11 * HV.norm() * U.norm());
      }
    }
  }
}

// The staircase optimizes a level on the rows of Y that are not exactly zero
// (Staircase::Optimize): the padding of a chordal start at rank d + 2, and
// the zero rows an escape from such a level keeps. That rests on the trust
// region keeping exactly zero rows exactly zero with every preconditioner,
// and on the compact run being the same run: the same iterations and
// products, the same F and rows up to round-off.
TEST(SESyncCost, TrustRegionKeepsZeroRowsZeroAndMatchesTheCompactRun) {
  CityOptions city_options;
  city_options.num_poses = 2000;
  city_options.seed = 2;
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(GenerateCity(city_options, &graph, nullptr, &error)) << error;
  SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  const int d = graph.dimension, n = problem.num_rotations();
  MatrixXd R;
  ASSERT_TRUE(internal::ChordalRotations(problem, &R));
  std::mt19937_64 rng(5);
  // A chordal start padded to rank d + 2, and a rank-(d + 2) point with a
  // zero row between nonzero ones (as after an escape from a padded level).
  MatrixXd padded = MatrixXd::Zero(d + 2, d * n);
  padded.topRows(d) = R;
  MatrixXd escaped = MatrixXd::Zero(d + 2, d * n);
  escaped.topRows(d) = R;
  escaped.row(d + 1) = 0.3 * Gaussian(1, d * n, &rng);
  ProjectToStiefelProduct(escaped, d, &escaped);
  ASSERT_TRUE(escaped.row(d).isZero(0));
  for (const PreconditionerType type :
       {PreconditionerType::kNone, PreconditionerType::kBlockJacobi,
        PreconditionerType::kSparseCholesky,
        PreconditionerType::kRegularizedQ}) {
    for (const MatrixXd& start : {padded, escaped}) {
      const int zero_row = d;  // Zero in both starts.
      std::vector<int> rows;
      for (int i = 0; i < start.rows(); ++i) {
        if (!start.row(i).isZero(0)) rows.push_back(i);
      }
      MatrixXd compact(rows.size(), d * n);
      for (size_t k = 0; k < rows.size(); ++k) {
        compact.row(k) = start.row(rows[k]);
      }
      RiemannianTrustRegionOptions options;
      options.preconditioned_gradient_tolerance = 1e-6;
      options.max_iterations = 30;
      SESyncPreconditioner p_full(problem, type, 1e6);
      SESyncPreconditioner p_compact(problem, type, 1e6);
      SESyncCost cost_full(&problem, &p_full);
      SESyncCost cost_compact(&problem, &p_compact);
      MatrixXd Y = start, Yc = compact;
      RiemannianTrustRegionSummary full_summary, compact_summary;
      MinimizeRiemannianTrustRegion(options, &cost_full, &Y, &full_summary);
      MinimizeRiemannianTrustRegion(options, &cost_compact, &Yc,
                                    &compact_summary);
      SCOPED_TRACE("preconditioner " + std::to_string(static_cast<int>(type)) +
                   ", nonzero rows " + std::to_string(rows.size()));
      EXPECT_GT(full_summary.iterations, 1);
      EXPECT_LT(full_summary.final_cost, 0.999 * cost_full.Evaluate(start));
      EXPECT_TRUE(Y.row(zero_row).isZero(0));
      if (rows.size() == static_cast<size_t>(d)) {
        EXPECT_TRUE(Y.row(d + 1).isZero(0));
      }
      EXPECT_NEAR(full_summary.final_cost, compact_summary.final_cost,
                  1e-12 * full_summary.final_cost);
      // Without a preconditioner truncated CG runs for hundreds of products
      // and amplifies the round-off of reductions summed in another order
      // (measured: 382 against 380 products, rows 1.6e-7 apart): there the
      // invariant and F are what is compared.
      if (type == PreconditionerType::kNone) continue;
      EXPECT_EQ(full_summary.iterations, compact_summary.iterations);
      EXPECT_EQ(full_summary.hessian_vector_products,
                compact_summary.hessian_vector_products);
      for (size_t k = 0; k < rows.size(); ++k) {
        EXPECT_LT((Y.row(rows[k]) - Yc.row(k)).norm(),
                  1e-9 * std::sqrt(static_cast<double>(n)));
      }
    }
  }
}

// With two threads the vertex ordering is computed beside the assembly (at
// 5000 vertices and more): the same permutation, and so bitwise the same
// products, as with one thread; for a pose graph and for one with landmarks
// and position priors (whose couplings the pattern must include).
TEST(SESyncProblem, OrderingAndProductsDoNotDependOnThreadCount) {
  CityOptions city;
  city.num_poses = 6000;
  city.seed = 3;
  LandmarkGraphOptions landmarks;
  landmarks.num_poses = 4000;
  landmarks.num_landmarks = 3000;
  landmarks.world_size = 200;
  landmarks.sensor_range = 8;
  landmarks.gps_interval = 50;
  landmarks.seed = 4;
  std::vector<PoseGraph> graphs(2);
  ASSERT_TRUE(GenerateCity(city, &graphs[0], nullptr, nullptr));
  ASSERT_TRUE(GenerateLandmarkGraph(landmarks, &graphs[1], nullptr, nullptr));
  std::mt19937_64 rng(5);
  for (const PoseGraph& graph : graphs) {
    SESyncProblem serial(graph, 1), parallel(graph, 2);
    ASSERT_TRUE(serial.ok() && parallel.ok());
    const internal::ProblemLayout layout(graph);
    ASSERT_GE(layout.num_vertices(), 5000);
    std::vector<int> sorted = serial.vertex_ordering();
    std::sort(sorted.begin(), sorted.end());
    std::vector<int> identity(layout.num_vertices());
    std::iota(identity.begin(), identity.end(), 0);
    EXPECT_EQ(sorted, identity);
    EXPECT_EQ(serial.vertex_ordering(), parallel.vertex_ordering());
    const MatrixXd Y = Gaussian(4, static_cast<int>(serial.D().cols()), &rng);
    MatrixXd a, b;
    serial.MultiplyQ(Y, &a);
    parallel.MultiplyQ(Y, &b);
    EXPECT_TRUE((a.array() == b.array()).all());
  }
}

// ReleaseNumericFactor() frees the values and keeps the symbolic analysis:
// a copy taken before stays valid, and refactorizing (simplicial or
// supernodal) gives the same factor to the last bit.
TEST(CholmodFactor, ReleaseKeepsAnalysisAndCopies) {
  std::mt19937_64 rng(41);
  for (const PoseGraph& graph : CostGraphs()) {
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    internal::SparseMatrix identity(problem.D().rows(), problem.D().cols());
    identity.setIdentity();
    const internal::SparseMatrix A = problem.D() + identity;
    const MatrixXd B = Gaussian(static_cast<int>(A.rows()), 2, &rng);
    for (auto layout : {internal::CholmodLayout::kSimplicial,
                        internal::CholmodLayout::kSupernodal}) {
      internal::CholmodFactor factor;
      internal::ConfigureCholmod(layout, &factor);
      factor.analyzePattern(A);
      EXPECT_FALSE(factor.HasNumericFactor());
      factor.factorize(A);
      ASSERT_TRUE(factor.HasNumericFactor());
      const MatrixXd X = factor.solve(B);
      const internal::SparseCholeskyFactor copy = factor.ExtractFactor();
      factor.ReleaseNumericFactor();
      EXPECT_FALSE(factor.HasNumericFactor());
      MatrixXd X_copy;
      copy.SolveRows(B.transpose(), &X_copy);
      EXPECT_LT(RelativeError(X_copy.transpose(), X), 1e-12);
      factor.factorize(A);
      ASSERT_EQ(factor.info(), Eigen::Success);
      ASSERT_TRUE(factor.HasNumericFactor());
      const MatrixXd X_again = factor.solve(B);
      EXPECT_TRUE((X_again.array() == X.array()).all());
      EXPECT_LT(RelativeError(
                    MatrixXd(A.selfadjointView<Eigen::Lower>() * X_again), B),
                1e-10);
    }
  }
}

// The preconditioners: the documented dense operators, and symmetric positive
// definite on the tangent space (the operator Proj o P o Proj).
TEST(SESyncPreconditioner, AllTypesAreDocumentedOperatorsAndSpdOnTangent) {
  std::mt19937_64 rng(31);
  for (const PoseGraph& graph : CostGraphs()) {
    SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    const int d = graph.dimension, n = problem.num_rotations(), dn = d * n;
    const MatrixXd Q = ReferenceQ(graph);
    const MatrixXd D = MatrixXd(problem.D());
    // eps = Gershgorin bound on lambda_max(D) / max_condition (documented).
    const double max_condition = 1e6;
    const double eps = D.cwiseAbs().rowwise().sum().maxCoeff() / max_condition;
    const MatrixXd I = MatrixXd::Identity(dn, dn);
    MatrixXd block_jacobi = MatrixXd::Zero(dn, dn);
    for (int i = 0; i < n; ++i) {
      block_jacobi.block(d * i, d * i, d, d) =
          (D.block(d * i, d * i, d, d) + eps * MatrixXd::Identity(d, d))
              .inverse();
    }
    struct Case {
      PreconditionerType type;
      MatrixXd dense_inverse;
    };
    const std::vector<Case> cases = {
        {PreconditionerType::kBlockJacobi, block_jacobi},
        {PreconditionerType::kSparseCholesky, (D + eps * I).inverse()},
        {PreconditionerType::kRegularizedQ, (Q + eps * I).inverse()}};
    for (const Case& c : cases) {
      SESyncPreconditioner preconditioner(problem, c.type, max_condition);
      EXPECT_EQ(preconditioner.type(), c.type);
      const MatrixXd V = Gaussian(4, dn, &rng);
      MatrixXd X;
      preconditioner.Apply(V, &X);
      // Condition number <= 1e6 by construction: 1e-8 relative.
      EXPECT_LT(RelativeError(X, V * c.dense_inverse), 1e-8)
          << "type " << static_cast<int>(c.type) << " d " << d;

      // Proj o P o Proj as a dense operator on R^{r x dn} (column-major vec).
      SESyncCost cost(&problem, &preconditioner);
      const int r = d + 1;
      const MatrixXd Y = RandomStiefelProductPoint(d, r, n, &rng);
      cost.Evaluate(Y);
      const int N = r * dn;
      MatrixXd P(N, N), Pi(N, N);
      for (int k = 0; k < N; ++k) {
        MatrixXd e = MatrixXd::Zero(r, dn);
        e.data()[k] = 1;
        MatrixXd t, pt;
        cost.ProjectToTangent(e, &t);
        cost.Precondition(t, &pt);
        P.col(k) = Eigen::Map<const VectorXd>(pt.data(), N);
        Pi.col(k) = Eigen::Map<const VectorXd>(t.data(), N);
      }
      EXPECT_LT((P - P.transpose()).norm(), 1e-10 * P.norm())
          << "preconditioner not symmetric on the tangent space";
      // Orthonormal basis B of the tangent space (eigenvectors of Pi with
      // eigenvalue 1); B^T P B must be positive definite.
      Eigen::SelfAdjointEigenSolver<MatrixXd> proj_eig(Pi);
      const int tangent_dim = StiefelTangentDimension(d, r) * n;
      const MatrixXd B = proj_eig.eigenvectors().rightCols(tangent_dim);
      EXPECT_NEAR(proj_eig.eigenvalues()(N - tangent_dim), 1.0, 1e-10);
      const MatrixXd Pt = B.transpose() * P * B;
      Eigen::SelfAdjointEigenSolver<MatrixXd> p_eig(0.5 *
                                                    (Pt + Pt.transpose()));
      EXPECT_GT(p_eig.eigenvalues()(0), 0.0)
          << "type " << static_cast<int>(c.type) << " d " << d;
    }
  }
}

// kAdaptive: block-Jacobi until a rule of PreconditionerSettings fires, then
// the exact (Q + eps I)^{-1}, with the documented operators before and after.
// Block-Jacobi's inverses (computed when first applied) follow the data
// matrices: after UpdateWeights() and Refresh(), Apply() is the block
// inverse of the new D + eps I, for kBlockJacobi and kAdaptive alike.
TEST(SESyncPreconditioner, BlockJacobiFollowsTheWeights) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> uniform(0.3, 1.0);
  for (int d : {2, 3}) {
    RandomGraphOptions o;
    o.dimension = d;
    o.num_poses = 20;
    o.num_loop_closures = 15;
    o.seed = 400 + d;
    const PoseGraph graph = RandomPoseGraph(o, nullptr);
    internal::MeasurementWeights weights(graph.measurements.size(), 1.0);
    SESyncProblem problem(graph, 1, weights);
    ASSERT_TRUE(problem.ok());
    const int n = problem.num_rotations(), dn = d * n;
    for (PreconditionerType type :
         {PreconditionerType::kBlockJacobi, PreconditionerType::kAdaptive}) {
      SESyncPreconditioner preconditioner(problem, type, 1e6);
      for (int round = 0; round < 2; ++round) {
        const MatrixXd D = MatrixXd(problem.D());
        const double eps = D.cwiseAbs().rowwise().sum().maxCoeff() / 1e6;
        MatrixXd block_jacobi = MatrixXd::Zero(dn, dn);
        for (int i = 0; i < n; ++i) {
          block_jacobi.block(d * i, d * i, d, d) =
              (D.block(d * i, d * i, d, d) + eps * MatrixXd::Identity(d, d))
                  .inverse();
        }
        const MatrixXd V = Gaussian(3, dn, &rng);
        MatrixXd X;
        preconditioner.Apply(V, &X);
        EXPECT_LT(RelativeError(X, V * block_jacobi), 1e-8)
            << "d " << d << " round " << round;
        for (double& w : weights) w = uniform(rng);
        ASSERT_TRUE(problem.UpdateWeights(weights));
        preconditioner.Refresh();
      }
    }
  }
}

TEST(SESyncPreconditioner, AdaptiveSwitchesByItsRules) {
  std::mt19937_64 rng(37);
  RandomGraphOptions o;
  o.dimension = 2;
  o.num_poses = 25;
  o.num_loop_closures = 30;
  o.seed = 41;
  const PoseGraph graph = RandomPoseGraph(o, nullptr);
  SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  const int d = 2, n = problem.num_rotations(), dn = d * n;
  const double max_condition = 1e6;
  const MatrixXd D = MatrixXd(problem.D());
  const double eps = D.cwiseAbs().rowwise().sum().maxCoeff() / max_condition;
  MatrixXd block_jacobi = MatrixXd::Zero(dn, dn);
  for (int i = 0; i < n; ++i) {
    block_jacobi.block(d * i, d * i, d, d) =
        (D.block(d * i, d * i, d, d) + eps * MatrixXd::Identity(d, d))
            .inverse();
  }
  const MatrixXd exact =
      (ReferenceQ(graph) + eps * MatrixXd::Identity(dn, dn)).inverse();
  const MatrixXd V = Gaussian(4, dn, &rng);
  auto applies = [&](const SESyncPreconditioner& p, const MatrixXd& inverse) {
    MatrixXd X;
    p.Apply(V, &X);
    return RelativeError(X, V * inverse) < 1e-8;
  };

  // The rule of kAutomatic's block-Jacobi: only the total counts.
  internal::PreconditionerSettings total;
  total.switch_iterations = 0;
  total.switch_at_convergence = false;
  total.switch_total_iterations = 10;
  SESyncPreconditioner p(problem, PreconditionerType::kAdaptive, max_condition,
                         nullptr, total);
  EXPECT_TRUE(applies(p, block_jacobi));
  EXPECT_FALSE(p.Update(4, false));
  EXPECT_FALSE(p.Update(0, true));   // Convergence does not switch.
  EXPECT_FALSE(p.Update(6, false));  // 10 in all: not more than 10.
  EXPECT_FALSE(p.exact());
  EXPECT_TRUE(applies(p, block_jacobi));
  EXPECT_TRUE(p.Update(1, false));
  EXPECT_TRUE(p.exact());
  EXPECT_EQ(p.switches(), 1);
  EXPECT_EQ(p.block_jacobi_iterations(), 11);
  EXPECT_TRUE(applies(p, exact));
  EXPECT_FALSE(p.Update(100, false));  // Switches once.
  EXPECT_EQ(p.block_jacobi_iterations(), 11);
  p.Refresh();  // Re-weighting keeps the mode.
  EXPECT_TRUE(applies(p, exact));

  // The default rules: one long solve, or convergence.
  SESyncPreconditioner long_solve(problem, PreconditionerType::kAdaptive,
                                  max_condition);
  EXPECT_FALSE(long_solve.Update(20, false));
  EXPECT_FALSE(long_solve.Update(20, false));  // No total limit by default.
  EXPECT_TRUE(long_solve.Update(21, false));
  EXPECT_TRUE(applies(long_solve, exact));
  SESyncPreconditioner converged(problem, PreconditionerType::kAdaptive,
                                 max_condition);
  EXPECT_TRUE(converged.Update(0, true));
  EXPECT_TRUE(applies(converged, exact));
  // On demand (the staircase at a saddle escape), once; kAdaptive only.
  SESyncPreconditioner on_demand(problem, PreconditionerType::kAdaptive,
                                 max_condition, nullptr, total);
  EXPECT_TRUE(on_demand.SwitchToExact());
  EXPECT_FALSE(on_demand.SwitchToExact());
  EXPECT_EQ(on_demand.switches(), 1);
  EXPECT_TRUE(applies(on_demand, exact));
  SESyncPreconditioner block(problem, PreconditionerType::kBlockJacobi,
                             max_condition);
  EXPECT_FALSE(block.SwitchToExact());
  EXPECT_TRUE(applies(block, block_jacobi));
}

}  // namespace
}  // namespace ceres_sesync
