// The Ceres baselines with landmarks and priors (ceres_baseline.h): cost =
// F / 2 against EvaluateObjective, the residual Jacobians against numeric
// differentiation (ceres::GradientChecker, on the problem's manifolds), the
// gradient against central differences of EvaluateObjective, recovery of a
// noiseless map (in the world frame with priors, up to gauge without), the
// gauge handling, and the odometry / landmark initializations.

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "ceres/gradient_checker.h"
#include "ceres_sesync/ceres_baseline.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Method = CeresBaselineOptions::Method;

PoseGraph LandmarkGraph(int d, uint64_t seed, int position_priors,
                        int rotation_priors, int pose_priors, bool noiseless,
                        Solution* truth) {
  test_util::RandomLandmarkGraphOptions options;
  options.poses.dimension = d;
  options.poses.num_poses = 8;
  options.poses.num_loop_closures = 3;
  options.poses.noiseless = noiseless;
  options.poses.seed = seed;
  options.num_landmarks = 10;
  options.observations_per_landmark = 3;
  options.num_position_priors = position_priors;
  options.num_rotation_priors = rotation_priors;
  options.num_pose_priors = pose_priors;
  return test_util::RandomLandmarkGraph(options, truth);
}

// Small rotation of a d x d rotation by `angle` about `axis` (2D: angle).
Eigen::MatrixXd Turn(const Eigen::MatrixXd& R, const Eigen::Vector3d& axis,
                     double angle) {
  if (R.rows() == 2) return R * Eigen::Rotation2Dd(angle).toRotationMatrix();
  return R * Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Every pose and landmark moved by N(0, sigma) (rotations by ~sigma rad).
Solution Perturb(Solution x, double sigma, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0, sigma);
  for (Pose& p : x.poses) {
    for (int c = 0; c < p.t.size(); ++c) p.t[c] += normal(rng);
    p.R = Turn(p.R, Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
               normal(rng));
  }
  for (Eigen::VectorXd& p : x.landmarks) {
    for (int c = 0; c < p.size(); ++c) p[c] += normal(rng);
  }
  return x;
}

// Largest difference of poses and landmarks, directly (world frame).
double WorldFrameDistance(const Solution& a, const Solution& b) {
  double worst = 0;
  for (size_t i = 0; i < a.poses.size(); ++i) {
    worst = std::max({worst, (a.poses[i].R - b.poses[i].R).norm(),
                      (a.poses[i].t - b.poses[i].t).norm()});
  }
  for (size_t l = 0; l < a.landmarks.size(); ++l) {
    worst = std::max(worst, (a.landmarks[l] - b.landmarks[l]).norm());
  }
  return worst;
}

// The same after expressing both in the frame of their pose 0 (the gauge).
double GaugeFreeDistance(const Solution& a, const Solution& b) {
  auto in_frame_of_0 = [](const Solution& x) {
    const Pose& o = x.poses[0];
    Solution y = x;
    for (Pose& p : y.poses) {
      p.t = o.R.transpose() * (p.t - o.t);
      p.R = o.R.transpose() * p.R;
    }
    for (Eigen::VectorXd& p : y.landmarks) p = o.R.transpose() * (p - o.t);
    return y;
  };
  return WorldFrameDistance(in_frame_of_0(a), in_frame_of_0(b));
}

CeresBaselineOptions Tight(Method method) {
  CeresBaselineOptions options;
  options.method = method;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  options.max_num_iterations = 200;
  return options;
}

TEST(CeresLandmarkProblem, CostIsHalfTheObjective) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph g = LandmarkGraph(d, 1, 2, 2, 2, false, &truth);
    const Solution x = Perturb(truth, 0.3, 2);
    CeresPoseBlocks blocks;
    std::string error;
    ASSERT_TRUE(blocks.FromSolution(d, x, &error)) << error;
    ceres::Problem problem;
    ASSERT_TRUE(BuildCeresProblem(g, &blocks, &problem, &error)) << error;
    // One block per edge and landmark measurement, one per prior part.
    int prior_blocks = 0;
    for (const PosePrior& p : g.priors) {
      prior_blocks += p.has_rotation() + p.has_position();
    }
    EXPECT_EQ(problem.NumResidualBlocks(),
              static_cast<int>(g.measurements.size() +
                               g.landmark_measurements.size()) +
                  prior_blocks);
    double cost = 0;
    ASSERT_TRUE(problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost,
                                 nullptr, nullptr, nullptr));
    const double f = EvaluateObjective(g, x);
    EXPECT_NEAR(2 * cost, f, 1e-12 * f);
    // The blocks round-trip (3D rotations through quaternions).
    EXPECT_LT(
        WorldFrameDistance(Solution{blocks.ToPoses(), blocks.ToLandmarks()}, x),
        1e-12);
  }
}

// Each residual block's Jacobian (autodiff) against central differences in
// the tangent space of its manifolds.
TEST(CeresLandmarkProblem, ResidualJacobiansMatchNumericDifferentiation) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph g = LandmarkGraph(d, 3, 2, 2, 2, false, &truth);
    CeresPoseBlocks blocks;
    std::string error;
    ASSERT_TRUE(blocks.FromSolution(d, Perturb(truth, 0.5, 4), &error))
        << error;
    ceres::Problem problem;
    ASSERT_TRUE(BuildCeresProblem(g, &blocks, &problem, &error)) << error;
    std::vector<ceres::ResidualBlockId> residual_blocks;
    problem.GetResidualBlocks(&residual_blocks);
    ceres::NumericDiffOptions numeric;
    int checked_landmark = 0, checked_prior = 0;
    for (ceres::ResidualBlockId id : residual_blocks) {
      std::vector<double*> parameters;
      problem.GetParameterBlocksForResidualBlock(id, &parameters);
      std::vector<const ceres::Manifold*> manifolds;
      for (double* p : parameters) manifolds.push_back(problem.GetManifold(p));
      const ceres::CostFunction* cost =
          problem.GetCostFunctionForResidualBlock(id);
      ceres::GradientChecker checker(cost, &manifolds, numeric);
      ceres::GradientChecker::ProbeResults results;
      // Probe's own entrywise relative test fails on structural zeros (1e-13
      // vs 0); compare each tangent-space Jacobian relative to its largest
      // entry instead. Central differences with Ceres's default step are
      // accurate to ~1e-10 here; a wrong derivative is off by O(1).
      checker.Probe(parameters.data(), 1e-7, &results);
      ASSERT_TRUE(results.return_value);
      ASSERT_EQ(results.local_jacobians.size(), parameters.size());
      for (size_t b = 0; b < parameters.size(); ++b) {
        const auto& user = results.local_jacobians[b];
        const auto& numeric_jacobian = results.local_numeric_jacobians[b];
        const double scale = std::max(1.0, user.cwiseAbs().maxCoeff());
        EXPECT_LT((user - numeric_jacobian).cwiseAbs().maxCoeff(), 1e-7 * scale)
            << "block " << b << "\n"
            << user << "\nvs\n"
            << numeric_jacobian;
      }
      if (parameters.size() == 3) ++checked_landmark;
      if (parameters.size() == 1) ++checked_prior;
    }
    EXPECT_EQ(checked_landmark,
              static_cast<int>(g.landmark_measurements.size()));
    EXPECT_EQ(checked_prior, 8);  // 2 + 2 + 2 x 2 prior parts.
  }
}

// The gradient that Ceres sees, against central differences of
// EvaluateObjective (an independent evaluation) along the landmark and
// translation coordinates.
TEST(CeresLandmarkProblem, GradientMatchesTheObjective) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph g = LandmarkGraph(d, 5, 3, 0, 1, false, &truth);
    const Solution x = Perturb(truth, 0.4, 6);
    CeresPoseBlocks blocks;
    std::string error;
    ASSERT_TRUE(blocks.FromSolution(d, x, &error)) << error;
    ceres::Problem problem;
    ASSERT_TRUE(BuildCeresProblem(g, &blocks, &problem, &error)) << error;
    ceres::Problem::EvaluateOptions evaluate;
    for (int l = 0; l < g.num_landmarks; ++l) {
      evaluate.parameter_blocks.push_back(blocks.landmark(l));
    }
    for (int i = 0; i < g.num_poses; ++i) {
      evaluate.parameter_blocks.push_back(blocks.translation(i));
    }
    std::vector<double> gradient;
    ASSERT_TRUE(
        problem.Evaluate(evaluate, nullptr, nullptr, &gradient, nullptr));
    const double h = 1e-6;
    double worst = 0, scale = 0;
    size_t k = 0;
    for (int l = 0; l < g.num_landmarks; ++l) {
      for (int c = 0; c < d; ++c, ++k) {
        Solution plus = x, minus = x;
        plus.landmarks[l][c] += h;
        minus.landmarks[l][c] -= h;
        // F = 2 cost, so dcost = dF / 2.
        const double numeric =
            (EvaluateObjective(g, plus) - EvaluateObjective(g, minus)) /
            (4 * h);
        worst = std::max(worst, std::abs(numeric - gradient[k]));
        scale = std::max(scale, std::abs(numeric));
      }
    }
    for (int i = 0; i < g.num_poses; ++i) {
      for (int c = 0; c < d; ++c, ++k) {
        Solution plus = x, minus = x;
        plus.poses[i].t[c] += h;
        minus.poses[i].t[c] -= h;
        const double numeric =
            (EvaluateObjective(g, plus) - EvaluateObjective(g, minus)) /
            (4 * h);
        worst = std::max(worst, std::abs(numeric - gradient[k]));
        scale = std::max(scale, std::abs(numeric));
      }
    }
    ASSERT_EQ(k, gradient.size());
    ASSERT_GT(scale, 1);
    // F is quadratic in these coordinates: central differences are exact up
    // to round-off, ~1e-16 F / h.
    EXPECT_LT(worst, 1e-6 * scale);
  }
}

TEST(SolveWithCeresLandmarks,
     NoiselessMapWithPriorsIsRecoveredInTheWorldFrame) {
  for (int d : {2, 3}) {
    for (Method method : {Method::kLevenbergMarquardt, Method::kPowellDogleg}) {
      SCOPED_TRACE(testing::Message()
                   << "d=" << d << " method=" << static_cast<int>(method));
      Solution truth;
      // Two position priors and one pose prior: the gauge is fixed.
      const PoseGraph g = LandmarkGraph(d, 7, 2, 0, 1, true, &truth);
      ASSERT_EQ(g.fixed_pose, -1);
      const Solution start = Perturb(truth, 0.15, 8);
      ASSERT_GT(WorldFrameDistance(start, truth), 0.1);
      Solution result;
      CeresBaselineSummary summary;
      std::string error;
      ASSERT_TRUE(
          SolveWithCeres(g, start, Tight(method), &result, &summary, &error))
          << error;
      EXPECT_LT(summary.final_objective, 1e-18) << summary.BriefReport();
      EXPECT_NEAR(summary.final_objective, EvaluateObjective(g, result), 1e-12);
      // Every pose moved, pose 0 included: nothing was held constant.
      EXPECT_LT(WorldFrameDistance(result, truth), 1e-7);
    }
  }
}

TEST(SolveWithCeresLandmarks, NoiselessMapWithoutPriorsIsRecoveredUpToGauge) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph g = LandmarkGraph(d, 9, 0, 0, 0, true, &truth);
    Solution start = Perturb(truth, 0.15, 10);
    Solution result;
    std::string error;
    ASSERT_TRUE(SolveWithCeres(g, start, Tight(Method::kLevenbergMarquardt),
                               &result, nullptr, &error))
        << error;
    EXPECT_LT(GaugeFreeDistance(result, truth), 1e-7);
    // Pose 0 is the gauge: held at its initial value.
    EXPECT_EQ(result.poses[0].t, start.poses[0].t);
    EXPECT_LT((result.poses[0].R - start.poses[0].R).norm(), 1e-15);
  }
}

TEST(SolveWithCeresLandmarks, RotationPriorsOnlyHoldTheTranslationOfPoseZero) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph g = LandmarkGraph(d, 11, 0, 2, 0, true, &truth);
    const Solution start = Perturb(truth, 0.15, 12);
    Solution result;
    std::string error;
    ASSERT_TRUE(SolveWithCeres(g, start, Tight(Method::kLevenbergMarquardt),
                               &result, nullptr, &error))
        << error;
    EXPECT_LT(EvaluateObjective(g, result), 1e-18);
    EXPECT_EQ(result.poses[0].t, start.poses[0].t);
    // Rotations are in the world frame; translations up to the shift that
    // pose 0's held translation implies.
    const Eigen::VectorXd shift = start.poses[0].t - truth.poses[0].t;
    Solution shifted = truth;
    for (Pose& p : shifted.poses) p.t += shift;
    for (Eigen::VectorXd& p : shifted.landmarks) p += shift;
    EXPECT_LT(WorldFrameDistance(result, shifted), 1e-7);
  }
}

TEST(SolveWithCeresLandmarks, NoisyResultIsStationary) {
  Solution truth;
  const PoseGraph g = LandmarkGraph(3, 13, 2, 1, 1, false, &truth);
  Solution result;
  CeresBaselineSummary summary;
  std::string error;
  ASSERT_TRUE(SolveWithCeres(g, truth, Tight(Method::kLevenbergMarquardt),
                             &result, &summary, &error))
      << error;
  const double f = EvaluateObjective(g, result);
  EXPECT_NEAR(summary.final_objective, f, 1e-10 * f);
  EXPECT_LE(f, EvaluateObjective(g, truth));
  // Central differences of F along every landmark coordinate vanish.
  const double h = 1e-5;
  for (int l = 0; l < g.num_landmarks; ++l) {
    for (int c = 0; c < 3; ++c) {
      Solution plus = result, minus = result;
      plus.landmarks[l][c] += h;
      minus.landmarks[l][c] -= h;
      EXPECT_LT(
          std::abs(EvaluateObjective(g, plus) - EvaluateObjective(g, minus)) /
              (2 * h),
          1e-6 * f);
    }
  }
}

TEST(SolveWithCeresLandmarks, PoseOnlyOverloadAndBadInputs) {
  Solution truth;
  const PoseGraph g = LandmarkGraph(2, 15, 1, 0, 0, false, &truth);
  Poses poses;
  std::string error;
  EXPECT_FALSE(SolveWithCeres(g, truth.poses, CeresBaselineOptions(), &poses,
                              nullptr, &error));
  EXPECT_NE(error.find("overload that takes and returns a Solution"),
            std::string::npos)
      << error;
  // Priors without landmarks work with the pose-only form.
  PoseGraph priors_only = LandmarkGraph(2, 15, 1, 1, 0, true, &truth);
  priors_only.landmark_measurements.clear();
  priors_only.landmark_ids.clear();
  priors_only.index_of_landmark_id.clear();
  priors_only.num_landmarks = 0;
  ASSERT_TRUE(SolveWithCeres(priors_only, Perturb(truth, 0.1, 1).poses,
                             Tight(Method::kLevenbergMarquardt), &poses,
                             nullptr, &error))
      << error;
  EXPECT_LT(EvaluateObjective(priors_only, poses), 1e-18);
  // Wrong number of landmark positions, non-finite ones, invalid graphs.
  Solution result;
  Solution wrong = truth;
  wrong.landmarks.pop_back();
  EXPECT_FALSE(SolveWithCeres(g, wrong, {}, &result, nullptr, &error));
  EXPECT_NE(error.find("one position per landmark"), std::string::npos);
  wrong = truth;
  wrong.landmarks[0][1] = NAN;
  EXPECT_FALSE(SolveWithCeres(g, wrong, {}, &result, nullptr, &error));
  EXPECT_NE(error.find("landmark 0 is not a finite position"),
            std::string::npos)
      << error;
  PoseGraph unseen = g;
  unseen.AddLandmark(999);
  wrong = truth;
  wrong.landmarks.push_back(Eigen::Vector2d::Zero());
  EXPECT_FALSE(SolveWithCeres(unseen, wrong, {}, &result, nullptr, &error));
  EXPECT_NE(error.find("not observed"), std::string::npos) << error;
}

TEST(LandmarkInitialization, OdometryPlacesTheMapInThePriorsWorldFrame) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    PoseGraph g = LandmarkGraph(d, 17, 2, 0, 1, true, &truth);
    // The root is the pose with the full prior, placed at it: exact odometry
    // then reproduces the truth in the world frame, and the landmarks follow.
    const Poses poses = OdometryInitialization(g);
    const Solution start{poses, InitialLandmarkPositions(g, poses)};
    EXPECT_LT(WorldFrameDistance(start, truth), 1e-9);
    EXPECT_LT(EvaluateObjective(g, start), 1e-18);
  }
}

TEST(LandmarkInitialization, IslandsTiedByPriorsAreEachPlaced) {
  // Poses 0-1 and 2-3, no edge between them; a full pose prior on 1 and 2.
  Solution truth;
  PoseGraph g;
  g.dimension = 2;
  std::mt19937_64 rng(3);
  truth.poses = test_util::RandomPoses(2, 4, 3, &rng);
  for (int v = 0; v < 4; ++v) g.AddVertex(v);
  for (auto [i, j] : {std::pair{0, 1}, std::pair{2, 3}}) {
    RelativePoseMeasurement e;
    e.i = i;
    e.j = j;
    e.R = truth.poses[i].R.transpose() * truth.poses[j].R;
    e.t = truth.poses[i].R.transpose() * (truth.poses[j].t - truth.poses[i].t);
    e.kappa = e.tau = 1;
    g.measurements.push_back(e);
  }
  for (int i : {1, 2}) {
    g.priors.push_back({i, truth.poses[i].R, truth.poses[i].t, 5.0, 5.0});
  }
  std::string error;
  ASSERT_TRUE(ValidatePoseGraph(g, &error)) << error;
  const Poses poses = OdometryInitialization(g);
  EXPECT_LT(WorldFrameDistance(Solution{poses, {}}, truth), 1e-12);
}

}  // namespace
}  // namespace ceres_sesync
