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
  // Apply(V) for a random V = sum_i g_i B_i against sum_i z_i B_i, z =
  // reference_inverse g, B_i the basis at newton.point().
  std::normal_distribution<double> normal;
  auto expect_inverse = [&](const std::vector<MatrixXd>& B, int trial) {
    MatrixXd V = MatrixXd::Zero(d, d * n);
    Eigen::VectorXd g(m);
    for (int i = 0; i < m; ++i) {
      g(i) = normal(rng);
      V += g(i) * B[i];
    }
    const Eigen::VectorXd z = reference_inverse * g;
    MatrixXd expected = MatrixXd::Zero(d, d * n);
    for (int i = 0; i < m; ++i) expected += z(i) * B[i];
    MatrixXd PV;
    newton.Apply(V, &PV);
    EXPECT_LT((PV - expected).norm(), 1e-10 * expected.norm())
        << "d = " << d << ", trial " << trial;
  };
  for (int trial = 0; trial < 3; ++trial) expect_inverse(basis, trial);
  // Rebase() carries the factor of Y to another point Y1: Apply(V) = sum_i
  // z_i B_i(Y1) with z = (M + eps I)^{-1} (<B_i(Y1), V>)_i, M still Y's.
  MatrixXd Y1(d, d * n);
  for (int i = 0; i < n; ++i) {
    Y1.middleCols(d * i, d) = test_util::RandomRotation(d, &rng);
  }
  newton.Rebase(Y1);
  EXPECT_EQ(newton.point(), Y1);
  expect_inverse(TangentBasis(Y1, d), /*trial=*/3);
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

// A rank-d descent from the chordal start of a 300-pose chain (30 loop
// closures, kappa 30, tau 5) preconditioned by (Q + eps I)^-1 with the
// Newton system as EnableNewton(switch_products, from_start) sets it, to an
// absolute gradient tolerance of 1e-6 (with F ~ 100: reachable above the
// round-off of F's differences, where the trust region stops accepting
// steps).
struct Descent {
  MatrixXd minimum;
  RiemannianTrustRegionSummary summary;
  bool newton_active = false;
  bool newton_active_in_a_plain_solve = false;  // After BeginSolve(false).
  int newton_factorizations = 0, preconditioner_applications = 0;
};

Descent Descend(int d, uint64_t seed, int switch_products, bool from_start) {
  test_util::RandomGraphOptions o;
  o.dimension = d;
  o.num_poses = 300;
  o.num_loop_closures = 30;
  o.chain = true;
  o.kappa = 30;
  o.tau = 5;
  o.seed = seed;
  const PoseGraph graph = test_util::RandomPoseGraph(o, nullptr);
  const SESyncProblem problem(graph);
  EXPECT_TRUE(problem.ok());
  Descent descent;
  EXPECT_TRUE(ChordalRotations(problem, &descent.minimum));
  SESyncPreconditioner exact(problem, PreconditionerType::kRegularizedQ, 1e6);
  RiemannianTrustRegionOptions rtr;
  rtr.gradient_tolerance = 1e-6;
  rtr.relative_decrease_tolerance = 0;
  rtr.preconditioned_gradient_tolerance = 0;
  rtr.step_tolerance = 0;
  SESyncCost cost(&problem, &exact);
  cost.EnableNewton(switch_products, from_start);
  cost.BeginSolve(/*allow_newton=*/true);
  MinimizeRiemannianTrustRegion(rtr, &cost, &descent.minimum, &descent.summary);
  EXPECT_EQ(descent.summary.termination,
            RiemannianTrustRegionSummary::Termination::kGradientTolerance)
      << "d = " << d << ", switch at " << switch_products
      << (from_start ? ", from the start" : "");
  descent.newton_active = cost.newton_active();
  descent.newton_factorizations = cost.newton_factorizations();
  descent.preconditioner_applications = cost.preconditioner_applications();
  cost.BeginSolve(/*allow_newton=*/false);
  descent.newton_active_in_a_plain_solve = cost.newton_active();
  return descent;
}

// The same minimum up to the gauge (R_0 is not fixed): R_0^T R_i within
// 1e-6. (The minimum is nondegenerate up to the gauge, so both end points
// are within about |grad| / lambda_min(Hess) of it.)
void ExpectTheSameMinimum(const MatrixXd& A, const MatrixXd& B, int d) {
  auto relative = [d](const MatrixXd& Y) {
    return MatrixXd(Y.leftCols(d).transpose() * Y);
  };
  EXPECT_LT((relative(A) - relative(B)).cwiseAbs().maxCoeff(), 1e-6)
      << "d = " << d;
}

// A descent with the switch forced at the first truncated-CG solve
// (EnableNewton(0)) against the same descent without it: the same minimum
// in fewer products, the Newton system refactorized at each iterate; the
// switch does not carry into a solve begun without it.
TEST(TangentNewton, SwitchedDescentReachesTheSameMinimum) {
  for (int d : {2, 3}) {
    const Descent plain = Descend(d, 11 + d, -1, false);
    const Descent newton = Descend(d, 11 + d, 0, false);
    EXPECT_FALSE(plain.newton_active);
    EXPECT_TRUE(newton.newton_active);
    EXPECT_GT(newton.newton_factorizations, 1);
    EXPECT_FALSE(newton.newton_active_in_a_plain_solve);
    EXPECT_LT(newton.summary.hessian_vector_products,
              plain.summary.hessian_vector_products)
        << "d = " << d;
    ExpectTheSameMinimum(newton.minimum, plain.minimum, d);
  }
}

// Newton from the start of a rank-d descent (EnableNewton(-1, true), the
// staircase's 2D default) against the exact preconditioner: the same
// minimum in fewer products, the SESyncPreconditioner never applied, and
// the factor kept across iterates while the solves stay short (fewer
// factorizations than iterations).
TEST(TangentNewton, DescentFromTheStartKeepsItsFactor) {
  const Descent plain = Descend(2, 21, -1, false);
  const Descent newton = Descend(2, 21, -1, true);
  EXPECT_TRUE(newton.newton_active);
  EXPECT_EQ(newton.preconditioner_applications, 0);
  EXPECT_GE(newton.newton_factorizations, 1);
  EXPECT_LT(newton.newton_factorizations, newton.summary.iterations);
  EXPECT_LT(newton.summary.hessian_vector_products,
            plain.summary.hessian_vector_products);
  ExpectTheSameMinimum(newton.minimum, plain.minimum, 2);
}

}  // namespace
}  // namespace ceres_sesync::internal
