// Tests of the Ceres local-search baselines: objective scale, recovery of the
// ground truth on noiseless data, agreement of the two methods and
// stationarity (finite differences of EvaluateObjective) on noisy data, the
// gauge, odometry initialization, and input validation.

#include "ceres_sesync/ceres_baseline.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "Eigen/Geometry"
#include "ceres_sesync/cube_generator.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

using Method = CeresBaselineOptions::Method;

PoseGraph MakeCube(int d, int side, uint64_t seed, Poses* truth) {
  CubeOptions options;
  options.dimension = d;
  options.side = side;
  options.loop_closure_probability = 0.3;
  options.seed = seed;
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateCube(options, &graph, truth, &error)) << error;
  return graph;
}

// The same graph with every measurement replaced by the exact relative pose.
PoseGraph ExactGraph(PoseGraph graph, const Poses& truth) {
  for (RelativePoseMeasurement& e : graph.measurements) {
    e.R = truth[e.i].R.transpose() * truth[e.j].R;
    e.t = truth[e.i].R.transpose() * (truth[e.j].t - truth[e.i].t);
  }
  return graph;
}

// x_a^-1 x_b.
Pose Relative(const Pose& a, const Pose& b) {
  return {a.R.transpose() * b.R, a.R.transpose() * (b.t - a.t)};
}

// Largest difference between the two trajectories after expressing both in
// the frame of their pose 0 (the gauge).
double GaugeFreeDistance(const Poses& x, const Poses& y) {
  double worst = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const Pose a = Relative(x[0], x[i]), b = Relative(y[0], y[i]);
    worst = std::max({worst, (a.R - b.R).norm(), (a.t - b.t).norm()});
  }
  return worst;
}

// Rotation of pose `k` by `angle` about local axis `axis` (in 2D: the angle).
Poses RotatePose(Poses poses, int k, int axis, double angle) {
  if (poses[k].R.rows() == 2) {
    Eigen::Matrix2d P = Eigen::Rotation2Dd(angle).toRotationMatrix();
    poses[k].R = poses[k].R * P;
  } else {
    const Eigen::Matrix3d P =
        Eigen::AngleAxisd(angle, Eigen::Vector3d::Unit(axis))
            .toRotationMatrix();
    poses[k].R = poses[k].R * P;
  }
  return poses;
}

// Central finite differences of EvaluateObjective along the translation and
// rotation coordinates of pose k; returns the largest magnitude.
double MaxDirectionalDerivative(const PoseGraph& graph, const Poses& x, int k) {
  const double h = 1e-5;
  const int d = graph.dimension;
  double worst = 0;
  for (int c = 0; c < d; ++c) {
    Poses plus = x, minus = x;
    plus[k].t[c] += h;
    minus[k].t[c] -= h;
    worst = std::max(worst, std::abs(EvaluateObjective(graph, plus) -
                                     EvaluateObjective(graph, minus)) /
                                (2 * h));
  }
  for (int c = 0; c < (d == 2 ? 1 : 3); ++c) {
    worst = std::max(
        worst, std::abs(EvaluateObjective(graph, RotatePose(x, k, c, h)) -
                        EvaluateObjective(graph, RotatePose(x, k, c, -h))) /
                   (2 * h));
  }
  return worst;
}

Poses Perturb(Poses x, double sigma, uint64_t seed, int keep) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0, sigma);
  for (int i = 0; i < static_cast<int>(x.size()); ++i) {
    if (i == keep) continue;
    for (int c = 0; c < x[i].t.size(); ++c) x[i].t[c] += normal(rng);
    for (int c = 0; c < (x[i].t.size() == 2 ? 1 : 3); ++c) {
      x = RotatePose(x, i, c, normal(rng));
    }
  }
  return x;
}

TEST(SolveWithCeres, ReportedObjectivesAreOnTheScaleOfEquation12) {
  // Ceres minimizes 0.5 sum r^2 = F / 2; the summary reports 2 * cost, which
  // must equal EvaluateObjective at the initial and returned poses (1e-10
  // relative: both are sums of the same O(m) terms in double precision).
  for (int d : {2, 3}) {
    for (Method method : {Method::kLevenbergMarquardt, Method::kPowellDogleg}) {
      Poses truth;
      const PoseGraph graph = MakeCube(d, 4, 1, &truth);
      // Loop closures make the odometry guess suboptimal.
      ASSERT_GT(static_cast<int>(graph.measurements.size()),
                graph.num_poses - 1);
      const Poses initial = OdometryInitialization(graph);
      CeresBaselineOptions options;
      options.method = method;
      Poses result;
      CeresBaselineSummary summary;
      std::string error;
      ASSERT_TRUE(
          SolveWithCeres(graph, initial, options, &result, &summary, &error))
          << error;
      const double f0 = EvaluateObjective(graph, initial);
      const double f1 = EvaluateObjective(graph, result);
      EXPECT_NEAR(summary.initial_objective, f0, 1e-10 * f0);
      EXPECT_NEAR(summary.final_objective, f1, 1e-10 * f1);
      EXPECT_NEAR(2 * summary.solver_summary.final_cost, f1, 1e-10 * f1);
      EXPECT_LT(f1, f0);  // the odometry guess of a noisy graph is not optimal
      EXPECT_GT(summary.iterations, 0);
      EXPECT_FALSE(summary.BriefReport().empty());
      std::string why;
      EXPECT_TRUE(ValidatePoseGraph(
          [&] {
            PoseGraph g = graph;
            g.initial_poses = result;  // result poses must be in SE(d)
            return g;
          }(),
          &why))
          << why;
    }
  }
}

TEST(SolveWithCeres, NoiselessCubeRecoversGroundTruth) {
  // Exact measurements: F = 0 exactly at the ground truth (unique up to
  // gauge), so both methods must land there from the odometry initialization
  // and from a heavily perturbed start (0.2 rad, 0.3 m per coordinate).
  // Tolerance 1e-6 on the gauge-free pose difference (the solver stops on a
  // relative decrease, with F ~ 1e-20 by then).
  for (int d : {2, 3}) {
    Poses truth;
    const PoseGraph graph = ExactGraph(MakeCube(d, 3, 2, &truth), truth);
    const Poses odometry = OdometryInitialization(graph);
    EXPECT_LT(GaugeFreeDistance(odometry, truth), 1e-12);
    for (Method method : {Method::kLevenbergMarquardt, Method::kPowellDogleg}) {
      for (const Poses& start : {odometry, Perturb(truth, 0.2, 3, 0)}) {
        CeresBaselineOptions options;
        options.method = method;
        options.function_tolerance = 1e-12;
        Poses result;
        CeresBaselineSummary summary;
        std::string error;
        ASSERT_TRUE(
            SolveWithCeres(graph, start, options, &result, &summary, &error))
            << error;
        EXPECT_LT(GaugeFreeDistance(result, truth), 1e-6)
            << summary.BriefReport();
        EXPECT_LT(summary.final_objective, 1e-10);
      }
    }
  }
}

TEST(SolveWithCeres, MethodsAgreeAndResultIsStationary) {
  // Noisy small cubes started from the ground truth (a good basin): LM and
  // PDL-GN must reach the same local minimum (objective to 1e-6 relative)
  // and the objective's directional derivatives there must vanish (< 1e-4;
  // they are O(1..100) at the start; finite-difference error with h = 1e-5
  // is ~1e-8 at these F values).
  for (int d : {2, 3}) {
    Poses truth;
    const PoseGraph graph = MakeCube(d, 4, 5, &truth);
    const int n = graph.num_poses;
    const std::vector<int> probes = {1, n / 2, n - 1};
    double start_derivative = 0;
    for (int k : probes) {
      start_derivative =
          std::max(start_derivative, MaxDirectionalDerivative(graph, truth, k));
    }
    EXPECT_GT(start_derivative, 0.1);
    double objective[2];
    Poses results[2];
    for (int a = 0; a < 2; ++a) {
      CeresBaselineOptions options;
      options.method =
          a == 0 ? Method::kLevenbergMarquardt : Method::kPowellDogleg;
      options.function_tolerance = 1e-14;
      options.gradient_tolerance = 1e-14;
      options.parameter_tolerance = 1e-14;
      CeresBaselineSummary summary;
      std::string error;
      ASSERT_TRUE(
          SolveWithCeres(graph, truth, options, &results[a], &summary, &error))
          << error;
      objective[a] = summary.final_objective;
      for (int k : probes) {
        EXPECT_LT(MaxDirectionalDerivative(graph, results[a], k), 1e-4)
            << "d=" << d << " pose " << k << " " << summary.BriefReport();
      }
      // Gauge: pose 0 stays exactly at its initial value.
      EXPECT_EQ(results[a][0].t, truth[0].t);
      EXPECT_LT((results[a][0].R - truth[0].R).norm(), 1e-15);
    }
    EXPECT_NEAR(objective[0], objective[1], 1e-6 * objective[0]);
    EXPECT_LT(GaugeFreeDistance(results[0], results[1]), 1e-5);
  }
}

TEST(SolveWithCeres, HoldsTheFixedPose) {
  Poses truth;
  PoseGraph graph = MakeCube(3, 3, 6, &truth);
  graph.fixed_pose = 7;
  const Poses start = Perturb(truth, 0.05, 8, -1);
  Poses result;
  std::string error;
  ASSERT_TRUE(SolveWithCeres(graph, start, CeresBaselineOptions(), &result,
                             nullptr, &error))
      << error;
  EXPECT_EQ(result[7].t, start[7].t);
  // Rotation round-trips through a quaternion: equal to rounding.
  EXPECT_LT((result[7].R - start[7].R).norm(), 1e-14);
  EXPECT_GT((result[0].t - start[0].t).norm(), 1e-6);  // pose 0 moved
}

TEST(BuildCeresProblem, CostIsHalfTheObjective) {
  for (int d : {2, 3}) {
    Poses truth;
    const PoseGraph graph = MakeCube(d, 3, 9, &truth);
    const Poses x = Perturb(truth, 0.1, 10, -1);
    CeresPoseBlocks blocks;
    std::string error;
    ASSERT_TRUE(blocks.FromPoses(d, x, &error)) << error;
    ceres::Problem problem;
    ASSERT_TRUE(BuildCeresProblem(graph, &blocks, &problem, &error)) << error;
    EXPECT_EQ(problem.NumResidualBlocks(),
              static_cast<int>(graph.measurements.size()));
    EXPECT_EQ(problem.NumResiduals(),
              static_cast<int>(graph.measurements.size()) * (d == 2 ? 6 : 12));
    double cost = 0;
    ASSERT_TRUE(problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost,
                                 nullptr, nullptr, nullptr));
    const double f = EvaluateObjective(graph, x);
    EXPECT_NEAR(2 * cost, f, 1e-12 * f);
    // Blocks round-trip the poses.
    EXPECT_LT(GaugeFreeDistance(blocks.ToPoses(), x), 1e-14);
    EXPECT_LT((blocks.ToPoses()[0].t - x[0].t).norm(), 1e-15);
  }
}

TEST(OdometryInitialization, ReproducesNoiselessGroundTruth) {
  // Exact measurements, with some edges reversed (j -> i with the inverse
  // measurement) so that the spanning tree is traversed in both directions.
  for (int d : {2, 3}) {
    Poses truth;
    PoseGraph graph = ExactGraph(MakeCube(d, 4, 11, &truth), truth);
    for (size_t k = 0; k < graph.measurements.size(); k += 3) {
      RelativePoseMeasurement& e = graph.measurements[k];
      e.t = -e.R.transpose() * e.t;
      e.R.transposeInPlace();
      std::swap(e.i, e.j);
    }
    const Poses x = OdometryInitialization(graph);
    ASSERT_EQ(x.size(), truth.size());
    EXPECT_LT(GaugeFreeDistance(x, truth), 1e-12);
    EXPECT_LT((x[0].R - Eigen::MatrixXd::Identity(d, d)).norm(), 1e-15);
    EXPECT_LT(x[0].t.norm(), 1e-15);
    // With a fixed pose and initial poses, the root sits at its initial value
    // and the whole result equals the ground truth (no gauge freedom left).
    graph.fixed_pose = 5;
    graph.initial_poses = truth;
    const Poses y = OdometryInitialization(graph);
    for (size_t i = 0; i < y.size(); ++i) {
      EXPECT_LT((y[i].R - truth[i].R).norm(), 1e-12);
      EXPECT_LT((y[i].t - truth[i].t).norm(), 1e-12);
    }
  }
}

TEST(SolveWithCeres, RejectsInvalidInput) {
  Poses truth;
  const PoseGraph graph = MakeCube(2, 3, 12, &truth);
  Poses result;
  std::string error;
  CeresBaselineOptions options;
  // Wrong number of initial poses.
  EXPECT_FALSE(
      SolveWithCeres(graph, Poses(2), options, &result, nullptr, &error));
  EXPECT_FALSE(error.empty());
  // Initial poses of the wrong dimension / non-finite.
  EXPECT_FALSE(SolveWithCeres(graph, IdentityPoses(3, graph.num_poses), options,
                              &result, nullptr, &error));
  Poses bad = truth;
  bad[2].t[0] = NAN;
  EXPECT_FALSE(SolveWithCeres(graph, bad, options, &result, nullptr, &error));
  // Invalid graph.
  PoseGraph invalid = graph;
  invalid.measurements[0].kappa = 0;
  EXPECT_FALSE(
      SolveWithCeres(invalid, truth, options, &result, nullptr, &error));
  invalid = graph;
  invalid.fixed_pose = graph.num_poses;
  EXPECT_FALSE(
      SolveWithCeres(invalid, truth, options, &result, nullptr, &error));
  // Invalid solver options.
  options.max_num_iterations = -1;
  EXPECT_FALSE(SolveWithCeres(graph, truth, options, &result, nullptr, &error));
  options = CeresBaselineOptions();
  options.num_threads = 0;
  EXPECT_FALSE(SolveWithCeres(graph, truth, options, &result, nullptr, &error));
  // Odometry initialization of a broken graph must not crash.
  invalid = graph;
  invalid.measurements[0].i = -4;
  invalid.measurements[1].j = 1000;
  EXPECT_EQ(OdometryInitialization(invalid).size(), truth.size());
}

}  // namespace
}  // namespace ceres_sesync
