// Tests of the chordal initialization (chordal_initialization.h): exact
// recovery on noiseless graphs (gauge R_0 = I), outputs in SO(d), optimal
// translations, agreement with a dense least-squares reference on noisy
// graphs, and input validation.

#include "ceres_sesync/chordal_initialization.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/pose_graph.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Eigen::MatrixXd;
using test_util::RandomGraphOptions;

double RotationError(const MatrixXd& R, int d) {
  double worst = 0;
  for (int i = 0; i < R.cols() / d; ++i) {
    const MatrixXd Ri = R.middleCols(d * i, d);
    worst = std::max(worst,
                     (Ri.transpose() * Ri - MatrixXd::Identity(d, d)).norm());
    worst = std::max(worst, std::abs(Ri.determinant() - 1));
  }
  return worst;
}

TEST(ChordalInitialization, NoiselessGraphsAreRecoveredExactly) {
  for (int d : {2, 3}) {
    for (int loops : {0, 5, 60}) {
      RandomGraphOptions o;
      o.dimension = d;
      o.num_poses = 40;
      o.num_loop_closures = loops;
      o.noiseless = true;
      o.kappa = 3;
      o.tau = 0.2;
      o.seed = 10 * d + loops;
      Poses truth;
      const PoseGraph graph = test_util::RandomPoseGraph(o, &truth);
      MatrixXd R;
      std::string error;
      ASSERT_TRUE(ChordalRotations(graph, &R, &error)) << error;
      ASSERT_EQ(R.rows(), d);
      ASSERT_EQ(R.cols(), d * o.num_poses);
      EXPECT_LT(RotationError(R, d), 1e-12);
      // Gauge R_0 = I: R_i = R0_true^T R_i_true.
      EXPECT_LT((R.leftCols(d) - MatrixXd::Identity(d, d)).norm(), 1e-14);
      for (int i = 0; i < o.num_poses; ++i) {
        EXPECT_LT((R.middleCols(d * i, d) - truth[0].R.transpose() * truth[i].R)
                      .norm(),
                  1e-10)
            << "pose " << i;
      }
      Poses poses;
      ASSERT_TRUE(ChordalInitialization(graph, &poses, &error)) << error;
      ASSERT_EQ(poses.size(), truth.size());
      EXPECT_EQ(poses[0].t.norm(), 0.0);
      EXPECT_LT(test_util::GaugeInvariantPoseDistance(poses, truth), 1e-9);
      // Exact data: F = 0 up to round-off of O(1) quantities.
      EXPECT_LT(EvaluateObjective(graph, poses),
                1e-18 * graph.measurements.size() + 1e-16);
    }
  }
}

// On noisy data: the output rotations are in SO(d), and they are the blockwise
// projections of the dense least-squares solution of
// min sum kappa ||R_j - R_i R~||^2 with R_0 = I (computed densely here).
// In 2D the chordal system is solved in complex form when every rotation
// block is exactly [[c, -s], [s, c]] (the graphs read or generated), and in
// real form otherwise (variant 20: rotations one ulp away from that form).
TEST(ChordalInitialization, NoisyGraphsMatchDenseLeastSquares) {
  for (int variant : {2, 3, 20}) {
    const int d = variant == 3 ? 3 : 2;
    RandomGraphOptions o;
    o.dimension = d;
    o.num_poses = 30;
    o.num_loop_closures = 25;
    o.kappa = 2;  // Strong noise.
    o.seed = 99 + d;
    PoseGraph graph = test_util::RandomPoseGraph(o, nullptr);
    if (d == 2) {
      // The test graphs' rotations are products: make them exactly of the
      // form read from files, then (variant 20) move one entry by an ulp.
      for (auto& e : graph.measurements) {
        const double theta = std::atan2(e.R(1, 0), e.R(0, 0));
        e.R << std::cos(theta), -std::sin(theta), std::sin(theta),
            std::cos(theta);
        if (variant == 20) e.R(1, 1) = std::nextafter(e.R(1, 1), 2.0);
      }
    }
    MatrixXd R;
    std::string error;
    ASSERT_TRUE(ChordalRotations(graph, &R, &error)) << error;
    EXPECT_LT(RotationError(R, d), 1e-12);
    // Dense reference: L = Q of the graph with t~ = 0 (rotation Laplacian).
    PoseGraph rotation_only = graph;
    for (auto& e : rotation_only.measurements) e.t.setZero();
    const MatrixXd L = test_util::DenseQ(rotation_only);
    const int dn = d * o.num_poses;
    const MatrixXd L11 = L.bottomRightCorner(dn - d, dn - d);
    const MatrixXd L10 = L.bottomLeftCorner(dn - d, d);
    const MatrixXd X = L11.ldlt().solve(-L10).transpose();  // d x (dn - d)
    for (int i = 1; i < o.num_poses; ++i) {
      const MatrixXd B = X.middleCols(d * (i - 1), d);
      Eigen::JacobiSVD<MatrixXd> svd(B,
                                     Eigen::ComputeFullU | Eigen::ComputeFullV);
      MatrixXd U = svd.matrixU();
      if ((U * svd.matrixV().transpose()).determinant() < 0) U.col(d - 1) *= -1;
      const MatrixXd expected = U * svd.matrixV().transpose();
      EXPECT_LT((R.middleCols(d * i, d) - expected).norm(), 1e-8)
          << "pose " << i;
    }
    // Translations are optimal for these rotations: stationarity in t.
    Poses poses;
    ASSERT_TRUE(ChordalInitialization(graph, &poses, &error)) << error;
    const double f = EvaluateObjective(graph, poses);
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal;
    for (int trial = 0; trial < 3; ++trial) {
      Poses plus = poses, minus = poses;
      for (int i = 0; i < o.num_poses; ++i) {
        for (int a = 0; a < d; ++a) {
          const double step = 0.1 * normal(rng);
          plus[i].t(a) += step;
          minus[i].t(a) -= step;
        }
      }
      const double fp = EvaluateObjective(graph, plus);
      const double fm = EvaluateObjective(graph, minus);
      EXPECT_GE(fp, f);
      EXPECT_LE(std::abs(fp - fm), 1e-9 * (fp + fm - 2 * f) + 1e-12 * f);
    }
  }
}

TEST(ChordalInitialization, NoiselessCubeAndSinglePose) {
  CubeOptions cube;
  cube.dimension = 3;
  cube.side = 4;
  cube.loop_closure_probability = 0.5;
  PoseGraph graph;
  Poses truth;
  ASSERT_TRUE(GenerateCube(cube, &graph, &truth, nullptr));
  test_util::MakeMeasurementsExact(truth, &graph);
  Poses poses;
  std::string error;
  ASSERT_TRUE(ChordalInitialization(graph, &poses, &error)) << error;
  EXPECT_LT(test_util::GaugeInvariantPoseDistance(poses, truth), 1e-9);

  PoseGraph single;
  single.dimension = 2;
  single.AddVertex(5);
  ASSERT_TRUE(ChordalInitialization(single, &poses, &error)) << error;
  ASSERT_EQ(poses.size(), 1u);
  EXPECT_EQ(poses[0].R, MatrixXd::Identity(2, 2));
  EXPECT_EQ(poses[0].t.norm(), 0.0);
}

TEST(ChordalInitialization, InvalidInputIsRejectedWithMessage) {
  RandomGraphOptions o;
  o.num_poses = 6;
  PoseGraph graph = test_util::RandomPoseGraph(o, nullptr);
  graph.AddVertex(1000);  // Disconnected.
  MatrixXd R;
  Poses poses;
  std::string error;
  EXPECT_FALSE(ChordalRotations(graph, &R, &error));
  EXPECT_FALSE(error.empty());
  error.clear();
  EXPECT_FALSE(ChordalInitialization(graph, &poses, &error));
  EXPECT_FALSE(error.empty());
}

// The elimination order of the reduced Laplacian changes only round-off:
// CHOLMOD's own analysis, the problem's vertex ordering, a random order of
// the blocks, and an order missing a block (ignored: CHOLMOD's own) give
// the same rotations to 1e-10, on a noisy 3D cube (the solution's
// conditioning is O(1) there).
TEST(ChordalInitialization, BlockOrderingChangesOnlyRoundOff) {
  CubeOptions cube;
  cube.side = 5;
  cube.seed = 3;
  PoseGraph graph;
  ASSERT_TRUE(GenerateCube(cube, &graph, nullptr, nullptr));
  const internal::SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  const int d = 3, n = graph.num_poses;
  MatrixXd reference;
  ASSERT_TRUE(internal::ChordalRotationsFromLaplacian(
      problem.RotationLaplacian(), d, &reference));
  std::vector<int> random(n);
  std::iota(random.begin(), random.end(), 0);
  std::shuffle(random.begin(), random.end(), std::mt19937(7));
  const std::vector<int> incomplete(random.begin() + 1, random.end());
  const std::vector<int>& vertex = problem.vertex_ordering();
  ASSERT_EQ(static_cast<int>(vertex.size()), n);
  for (const std::vector<int>* ordering :
       {&vertex, static_cast<const std::vector<int>*>(&random), &incomplete}) {
    MatrixXd R;
    std::vector<int> component;
    ASSERT_TRUE(internal::ChordalRotationsFromLaplacian(
        problem.RotationLaplacian(), d, &R, &component, ordering));
    EXPECT_LT((R - reference).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_EQ(component, std::vector<int>(n, 0));
  }
  MatrixXd R;
  ASSERT_TRUE(internal::ChordalRotations(problem, &R));
  EXPECT_LT((R - reference).cwiseAbs().maxCoeff(), 1e-10);
  // The factorization and solves split over threads: bitwise the same.
  for (int threads : {2, 3}) {
    MatrixXd R_threads;
    ASSERT_TRUE(internal::ChordalRotationsFromLaplacian(
        problem.RotationLaplacian(), d, &R_threads, nullptr, &vertex, threads));
    MatrixXd R_one;
    ASSERT_TRUE(internal::ChordalRotationsFromLaplacian(
        problem.RotationLaplacian(), d, &R_one, nullptr, &vertex, 1));
    EXPECT_EQ(R_threads, R_one) << threads << " threads";
  }
}

// Precisions far from 1 (the factorization accepts pivots within 2^+-900):
// rotation precisions scaled by 2^-950 scale L(G^rho) exactly, which the
// chordal solve undoes, so the estimate is bitwise that of the unscaled
// graph (3D: the real system; 2D cubes take the complex one).
TEST(ChordalInitialization, TinyPrecisionsGiveTheSameEstimate) {
  CubeOptions cube;
  cube.side = 4;
  cube.seed = 2;
  PoseGraph graph;
  ASSERT_TRUE(GenerateCube(cube, &graph, nullptr, nullptr));
  PoseGraph tiny = graph;
  for (auto& e : tiny.measurements) e.kappa = std::ldexp(e.kappa, -950);
  MatrixXd R, R_tiny;
  std::string error;
  ASSERT_TRUE(ChordalRotations(graph, &R, &error)) << error;
  ASSERT_TRUE(ChordalRotations(tiny, &R_tiny, &error)) << error;
  EXPECT_EQ(R, R_tiny);
}

}  // namespace
}  // namespace ceres_sesync
