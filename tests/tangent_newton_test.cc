// Tests of the Newton preconditioner of rank-d levels (tangent_newton.h):
// its operator against the dense inverse of the Riemannian Hessian (eq. 44,
// SESyncCost::HessianVector) in tangent coordinates, on pose graphs with
// and without landmarks and priors; and a descent that switches to it
// against one that does not.

#include "ceres_sesync/internal/tangent_newton.h"

#include <cmath>
#include <random>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync::internal {
namespace {

using Eigen::MatrixXd;

// Basis tangent vectors at Y (d x dn, blocks in O(d)): Y_i E_k in block i,
// E_k the orthonormal skew basis, zero elsewhere.
std::vector<MatrixXd> TangentBasis(const MatrixXd& Y, int d) {
  const int n = static_cast<int>(Y.cols()) / d;
  std::vector<MatrixXd> basis;
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < d; ++a) {
      for (int b = a + 1; b < d; ++b) {
        MatrixXd E = MatrixXd::Zero(d, d);
        E(b, a) = 1 / std::sqrt(2.0);
        E(a, b) = -1 / std::sqrt(2.0);
        MatrixXd V = MatrixXd::Zero(d, Y.cols());
        V.middleCols(d * i, d) = Y.middleCols(d * i, d) * E;
        basis.push_back(V);
      }
    }
  }
  return basis;
}

// Apply(V) = sum_i z_i B_i with z = (M + eps I)^{-1} (<B_i, V>)_i and M_ij =
// <B_i, Hess F(Y)[B_j]>: the regularized inverse of the Riemannian Hessian on
// the tangent space. eps above M's spectrum makes the dense reference well
// conditioned at any point (H itself is indefinite away from minima).
void ExpectInverseOfTheHessian(const PoseGraph& graph, uint64_t seed) {
  const int d = graph.dimension;
  const SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  const int n = problem.num_rotations();
  std::mt19937_64 rng(seed);
  MatrixXd Y(d, d * n);
  for (int i = 0; i < n; ++i) {
    Y.middleCols(d * i, d) = test_util::RandomRotation(d, &rng);
  }
  SESyncPreconditioner none(problem, PreconditionerType::kNone, 1e6);
  SESyncCost cost(&problem, &none);
  cost.Evaluate(Y);
  const std::vector<MatrixXd> basis = TangentBasis(Y, d);
  const int m = static_cast<int>(basis.size());
  MatrixXd M(m, m);
  for (int j = 0; j < m; ++j) {
    MatrixXd hv;
    cost.HessianVector(basis[j], &hv);
    for (int i = 0; i < m; ++i) M(i, j) = basis[i].cwiseProduct(hv).sum();
  }
  const double eps = 2 * M.norm();
  TangentNewton newton(problem);
  ASSERT_TRUE(newton.Factorize(Y, cost.Lambda(), eps));
  EXPECT_EQ(newton.point(), Y);
  const MatrixXd reference_inverse =
      (M + eps * MatrixXd::Identity(m, m)).inverse();
  for (int trial = 0; trial < 3; ++trial) {
    MatrixXd V = MatrixXd::Zero(d, d * n);
    Eigen::VectorXd g(m);
    std::normal_distribution<double> normal;
    for (int i = 0; i < m; ++i) {
      g(i) = normal(rng);
      V += g(i) * basis[i];
    }
    const Eigen::VectorXd z = reference_inverse * g;
    MatrixXd expected = MatrixXd::Zero(d, d * n);
    for (int i = 0; i < m; ++i) expected += z(i) * basis[i];
    MatrixXd PV;
    newton.Apply(V, &PV);
    EXPECT_LT((PV - expected).norm(), 1e-10 * expected.norm())
        << "d = " << d << ", trial " << trial;
  }
  // Rebase() carries the factor of Y to another point Y1: Apply(V) = sum_i
  // z_i B_i(Y1) with z = (M + eps I)^{-1} (<B_i(Y1), V>)_i, M still Y's.
  MatrixXd Y1(d, d * n);
  for (int i = 0; i < n; ++i) {
    Y1.middleCols(d * i, d) = test_util::RandomRotation(d, &rng);
  }
  newton.Rebase(Y1);
  EXPECT_EQ(newton.point(), Y1);
  const std::vector<MatrixXd> basis1 = TangentBasis(Y1, d);
  MatrixXd V = MatrixXd::Zero(d, d * n);
  Eigen::VectorXd g(m);
  std::normal_distribution<double> normal;
  for (int i = 0; i < m; ++i) {
    g(i) = normal(rng);
    V += g(i) * basis1[i];
  }
  const Eigen::VectorXd z = reference_inverse * g;
  MatrixXd expected = MatrixXd::Zero(d, d * n);
  for (int i = 0; i < m; ++i) expected += z(i) * basis1[i];
  MatrixXd PV;
  newton.Apply(V, &PV);
  EXPECT_LT((PV - expected).norm(), 1e-10 * expected.norm()) << "d = " << d;
}

TEST(TangentNewton, ApplyIsTheInverseOfTheRiemannianHessian) {
  for (int d : {2, 3}) {
    test_util::RandomGraphOptions o;
    o.dimension = d;
    o.num_poses = 12;
    o.num_loop_closures = 8;
    o.kappa = 20;
    o.tau = 10;
    o.seed = 40 + d;
    ExpectInverseOfTheHessian(test_util::RandomPoseGraph(o, nullptr), d);
  }
}

TEST(TangentNewton, ApplyIsTheInverseWithLandmarksAndPriors) {
  for (int d : {2, 3}) {
    test_util::RandomLandmarkGraphOptions o;
    o.poses.dimension = d;
    o.poses.num_poses = 8;
    o.poses.num_loop_closures = 4;
    o.poses.seed = 50 + d;
    o.num_landmarks = 5;
    o.num_position_priors = 1;
    o.num_rotation_priors = 1;
    o.num_pose_priors = 1;
    ExpectInverseOfTheHessian(test_util::RandomLandmarkGraph(o, nullptr),
                              7 + d);
  }
}

// A rank-d descent from the chordal start with the switch forced at the
// first truncated-CG solve (EnableNewton(0)) against the same descent
// without it: the same minimum (the gradient at both end points below the
// tolerance), in fewer products, the Newton system refactorized at each
// iterate; the switch does not carry into a solve begun without it. (The
// minimum is nondegenerate up to the gauge, so both end points are within
// about |grad| / lambda_min(Hess) of it.)
TEST(TangentNewton, SwitchedDescentReachesTheSameMinimum) {
  for (int d : {2, 3}) {
    test_util::RandomGraphOptions o;
    o.dimension = d;
    o.num_poses = 300;
    o.num_loop_closures = 30;
    o.chain = true;
    o.kappa = 30;
    o.tau = 5;
    o.seed = 11 + d;
    const PoseGraph graph = test_util::RandomPoseGraph(o, nullptr);
    const SESyncProblem problem(graph);
    ASSERT_TRUE(problem.ok());
    MatrixXd start;
    ASSERT_TRUE(ChordalRotations(problem, &start));
    SESyncPreconditioner exact(problem, PreconditionerType::kRegularizedQ, 1e6);
    RiemannianTrustRegionOptions rtr;
    // Absolute, with F ~ 100: reachable above the round-off of F's
    // differences, where the trust region stops accepting steps.
    rtr.gradient_tolerance = 1e-6;
    rtr.relative_decrease_tolerance = 0;
    rtr.preconditioned_gradient_tolerance = 0;
    rtr.step_tolerance = 0;
    std::vector<MatrixXd> minima;
    std::vector<int> products;
    for (const bool newton : {false, true}) {
      SESyncCost cost(&problem, &exact);
      cost.EnableNewton(newton ? 0 : -1);
      cost.BeginSolve(/*allow_newton=*/true);
      MatrixXd Y = start;
      RiemannianTrustRegionSummary summary;

      MinimizeRiemannianTrustRegion(rtr, &cost, &Y, &summary);
      EXPECT_EQ(summary.termination,
                RiemannianTrustRegionSummary::Termination::kGradientTolerance)
          << "d = " << d << (newton ? " with" : " without") << " Newton";
      EXPECT_EQ(cost.newton_active(), newton);
      minima.push_back(Y);
      products.push_back(summary.hessian_vector_products);
      if (newton) {
        EXPECT_GT(cost.newton_factorizations(), 1);
        cost.BeginSolve(/*allow_newton=*/false);
        EXPECT_FALSE(cost.newton_active());
      }
    }
    EXPECT_LT(products[1], products[0]) << "d = " << d;
    // The same minimum up to the gauge (R_0 is not fixed): compare
    // R_0^T R_i.
    auto relative = [d](const MatrixXd& Y) {
      return MatrixXd(Y.leftCols(d).transpose() * Y);
    };
    EXPECT_LT((relative(minima[1]) - relative(minima[0])).cwiseAbs().maxCoeff(),
              1e-6)
        << "d = " << d;
  }
}

// Newton from the start of a rank-d descent (EnableNewton(-1, true), the
// staircase's 2D default) against the exact preconditioner: the same
// minimum in fewer products, the SESyncPreconditioner never applied, and
// the factor kept across iterates while the solves stay short (fewer
// factorizations than iterations).
TEST(TangentNewton, DescentFromTheStartKeepsItsFactor) {
  test_util::RandomGraphOptions o;
  o.dimension = 2;
  o.num_poses = 300;
  o.num_loop_closures = 30;
  o.chain = true;
  o.kappa = 30;
  o.tau = 5;
  o.seed = 21;
  const PoseGraph graph = test_util::RandomPoseGraph(o, nullptr);
  const SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  MatrixXd start;
  ASSERT_TRUE(ChordalRotations(problem, &start));
  SESyncPreconditioner exact(problem, PreconditionerType::kRegularizedQ, 1e6);
  RiemannianTrustRegionOptions rtr;
  rtr.gradient_tolerance = 1e-6;  // As above.
  rtr.relative_decrease_tolerance = 0;
  rtr.preconditioned_gradient_tolerance = 0;
  rtr.step_tolerance = 0;
  std::vector<MatrixXd> minima;
  std::vector<int> products;
  for (const bool newton : {false, true}) {
    SESyncCost cost(&problem, &exact);
    cost.EnableNewton(-1, /*from_start=*/newton);
    cost.BeginSolve(/*allow_newton=*/true);
    EXPECT_EQ(cost.newton_active(), newton);
    MatrixXd Y = start;
    RiemannianTrustRegionSummary summary;
    MinimizeRiemannianTrustRegion(rtr, &cost, &Y, &summary);
    EXPECT_EQ(summary.termination,
              RiemannianTrustRegionSummary::Termination::kGradientTolerance)
        << (newton ? "with" : "without") << " Newton";
    minima.push_back(Y);
    products.push_back(summary.hessian_vector_products);
    if (newton) {
      EXPECT_EQ(cost.preconditioner_applications(), 0);
      EXPECT_GE(cost.newton_factorizations(), 1);
      EXPECT_LT(cost.newton_factorizations(), summary.iterations);
    }
  }
  EXPECT_LT(products[1], products[0]);
  auto relative = [](const MatrixXd& Y) {
    return MatrixXd(Y.leftCols(2).transpose() * Y);
  };
  EXPECT_LT((relative(minima[1]) - relative(minima[0])).cwiseAbs().maxCoeff(),
            1e-6);
}

}  // namespace
}  // namespace ceres_sesync::internal
