// Tests of the landmark benchmark generator (landmark_generator.h): the walk
// and the sensor model against their definitions, determinism, priors, the
// noise level against the closed-form expectation, option validation, the
// Ceres baselines on its graphs, and `ceres_sesync generate landmarks`.

#include "ceres_sesync/landmark_generator.h"

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "Eigen/LU"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/file_util.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

LandmarkGraphOptions Small(int d) {
  LandmarkGraphOptions o;
  o.dimension = d;
  o.num_poses = 300;
  o.world_size = 20;
  o.num_landmarks = d == 2 ? 120 : 600;
  o.sensor_range = 4;
  o.seed = 3;
  return o;
}

PoseGraph Generate(const LandmarkGraphOptions& o, Solution* truth) {
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateLandmarkGraph(o, &graph, truth, &error)) << error;
  return graph;
}

TEST(LandmarkGenerator, WalkFollowsTheManhattanRules) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    LandmarkGraphOptions o = Small(d);
    o.step_length = 0.5;
    o.block_length = 4;
    Solution truth;
    const PoseGraph g = Generate(o, &truth);
    ASSERT_EQ(g.num_poses, o.num_poses);
    EXPECT_LT((truth.poses[0].R - Eigen::MatrixXd::Identity(d, d)).norm(),
              1e-15);
    EXPECT_LT(truth.poses[0].t.norm(), 1e-15);
    std::set<std::vector<int>> directions;
    for (int i = 0; i < g.num_poses; ++i) {
      const Pose& x = truth.poses[i];
      EXPECT_LT(
          (x.R.transpose() * x.R - Eigen::MatrixXd::Identity(d, d)).norm(),
          1e-12);
      EXPECT_NEAR(x.R.determinant(), 1, 1e-12);
      // Inside the box.
      EXPECT_LE(x.t.cwiseAbs().maxCoeff(), o.world_size / 2 + 1e-12);
      if (i + 1 == g.num_poses) break;
      // One step along an axis, in the direction the pose faces.
      const Eigen::VectorXd step = truth.poses[i + 1].t - x.t;
      EXPECT_NEAR(step.norm(), o.step_length, 1e-12);
      EXPECT_LT((step / o.step_length - x.R.col(0)).norm(), 1e-12);
      std::vector<int> direction(d);
      for (int k = 0; k < d; ++k) direction[k] = std::lround(step[k] / 0.5);
      directions.insert(direction);
      // Headings change only at intersections and never reverse.
      if (i > 0) {
        const Eigen::VectorXd before = x.t - truth.poses[i - 1].t;
        if ((before - step).norm() > 1e-12) {
          EXPECT_GT(before.dot(step), -1e-12) << "reversal at " << i;
          const Eigen::VectorXd lattice =
              x.t / (o.step_length * o.block_length);
          EXPECT_LT((lattice - lattice.array().round().matrix()).norm(), 1e-9)
              << "turn off an intersection at pose " << i;
        }
      }
    }
    // The walk does turn: several axis directions are used.
    EXPECT_GE(directions.size(), static_cast<size_t>(2 * d - 1));
  }
}

TEST(LandmarkGenerator, ObservationsFollowTheSensorModel) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    LandmarkGraphOptions o = Small(d);
    o.noiseless = true;
    Solution truth;
    const PoseGraph g = Generate(o, &truth);
    std::string error;
    ASSERT_TRUE(ValidatePoseGraph(g, ValidationOptions(), &error)) << error;
    ASSERT_GT(g.num_landmarks, 10);
    EXPECT_LE(g.num_landmarks, o.num_landmarks);
    ASSERT_EQ(static_cast<int>(truth.landmarks.size()), g.num_landmarks);
    EXPECT_EQ(static_cast<int>(g.measurements.size()), g.num_poses - 1);
    for (int i = 1; i < g.num_poses; ++i) {
      EXPECT_EQ(g.measurements[i - 1].i, i - 1);
      EXPECT_EQ(g.measurements[i - 1].j, i);
    }
    // Every observation is within range; with detection probability 1 and
    // no limit every truth landmark in range of a pose is observed by it.
    std::vector<std::set<int>> seen(g.num_poses);
    for (const LandmarkMeasurement& m : g.landmark_measurements) {
      EXPECT_LE((truth.landmarks[m.l] - truth.poses[m.i].t).norm(),
                o.sensor_range + 1e-12);
      EXPECT_EQ(m.nu, o.landmark_nu);
      EXPECT_TRUE(seen[m.i].insert(m.l).second) << "observed twice";
    }
    for (int i = 0; i < g.num_poses; ++i) {
      for (int l = 0; l < g.num_landmarks; ++l) {
        const bool in_range =
            (truth.landmarks[l] - truth.poses[i].t).norm() <= o.sensor_range;
        EXPECT_EQ(seen[i].count(l) == 1, in_range) << i << " " << l;
      }
    }
    // Ids: poses 0..n-1, landmarks n.. in order of first observation.
    for (int l = 0; l < g.num_landmarks; ++l) {
      EXPECT_EQ(g.landmark_ids[l], g.num_poses + l);
    }
    int next = 0;
    for (const LandmarkMeasurement& m : g.landmark_measurements) {
      EXPECT_LE(m.l, next);
      next = std::max(next, m.l + 1);
    }
    // Noiseless: the ground truth has F = 0.
    EXPECT_LT(EvaluateObjective(g, truth), 1e-18);
  }
}

TEST(LandmarkGenerator, DetectionProbabilityAndObservationLimit) {
  LandmarkGraphOptions o = Small(2);
  Solution truth;
  const PoseGraph all = Generate(o, &truth);
  o.detection_probability = 0.5;
  const PoseGraph half = Generate(o, nullptr);
  const double ratio = static_cast<double>(half.landmark_measurements.size()) /
                       all.landmark_measurements.size();
  // ~3000 Bernoulli(0.5) draws: 0.5 +- 0.01 (1 sigma).
  EXPECT_NEAR(ratio, 0.5, 0.05);
  o.detection_probability = 1;
  o.max_observations_per_pose = 3;
  Solution capped_truth;
  const PoseGraph capped = Generate(o, &capped_truth);
  std::vector<int> count(capped.num_poses, 0);
  for (const LandmarkMeasurement& m : capped.landmark_measurements) {
    ++count[m.i];
  }
  EXPECT_EQ(*std::max_element(count.begin(), count.end()), 3);
}

TEST(LandmarkGenerator, PriorsAndDeterminism) {
  LandmarkGraphOptions o = Small(3);
  o.gps_interval = 25;
  o.start_prior = true;
  Solution truth;
  const PoseGraph g = Generate(o, &truth);
  ASSERT_EQ(g.priors.size(), 1u + 12u);  // Poses 0, 25, ..., 275.
  EXPECT_EQ(g.priors[0].i, 0);
  EXPECT_TRUE(g.priors[0].has_rotation() && g.priors[0].has_position());
  for (size_t k = 1; k < g.priors.size(); ++k) {
    EXPECT_EQ(g.priors[k].i, static_cast<int>(25 * (k - 1)));
    EXPECT_FALSE(g.priors[k].has_rotation());
    EXPECT_EQ(g.priors[k].tau, o.gps_tau);
  }
  std::string error;
  EXPECT_TRUE(ValidatePoseGraph(g, ValidationOptions(), &error)) << error;
  // Same options, same graph; another seed, another graph.
  Solution again_truth;
  const PoseGraph again = Generate(o, &again_truth);
  ASSERT_EQ(again.landmark_measurements.size(), g.landmark_measurements.size());
  for (size_t k = 0; k < g.landmark_measurements.size(); ++k) {
    EXPECT_EQ(again.landmark_measurements[k].z, g.landmark_measurements[k].z);
  }
  EXPECT_EQ(again.priors[3].t, g.priors[3].t);
  o.seed = 4;
  const PoseGraph other = Generate(o, nullptr);
  EXPECT_NE(other.priors[3].t, g.priors[3].t);
}

TEST(LandmarkGenerator, NoiseMatchesTheExpectedObjective) {
  // F(truth) is a sum of ~10^4 independent terms; its expectation has a
  // closed form (ExpectedGroundTruthObjective). Relative standard deviation
  // ~sqrt(2 / (d m)) ~ 1%; 5% is > 4 sigma.
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    LandmarkGraphOptions o = Small(d);
    o.kappa = 20;  // Rotation noise large enough to matter.
    o.gps_interval = 5;
    o.start_prior = true;
    o.start_prior_kappa = 30;
    Solution truth;
    const PoseGraph g = Generate(o, &truth);
    const double f = EvaluateObjective(g, truth);
    const double expected = ExpectedGroundTruthObjective(g);
    EXPECT_NEAR(f / expected, 1, 0.05) << f << " vs " << expected;
    // The landmark part alone: d per measurement.
    PoseGraph landmarks_only = g;
    landmarks_only.measurements.clear();
    landmarks_only.priors.clear();
    const double fl = EvaluateObjective(landmarks_only, truth);
    EXPECT_NEAR(fl / (d * g.landmark_measurements.size()), 1, 0.05);
  }
}

TEST(LandmarkGenerator, VictoriaParkLikePresetSeesManyLandmarksPerPose) {
  LandmarkGraphOptions o = VictoriaParkLikeOptions();
  o.num_poses = 300;  // Keep the test short.
  Solution truth;
  const PoseGraph g = Generate(o, &truth);
  const double per_pose =
      static_cast<double>(g.landmark_measurements.size()) / g.num_poses;
  EXPECT_GT(per_pose, 15) << per_pose;
  std::string error;
  EXPECT_TRUE(ValidatePoseGraph(g, ValidationOptions(), &error)) << error;
}

TEST(LandmarkGenerator, RejectsInvalidOptions) {
  auto expect_error = [](const LandmarkGraphOptions& o, const char* what) {
    PoseGraph g;
    std::string error;
    EXPECT_FALSE(GenerateLandmarkGraph(o, &g, nullptr, &error)) << what;
    EXPECT_NE(error.find(what), std::string::npos) << error;
  };
  LandmarkGraphOptions o;
  o.dimension = 4;
  expect_error(o, "dimension");
  o = {};
  o.num_poses = 1;
  expect_error(o, "num_poses");
  o = {};
  o.num_landmarks = 0;
  expect_error(o, "num_landmarks");
  o = {};
  o.step_length = NAN;
  expect_error(o, "step_length");
  o = {};
  o.block_length = 0;
  expect_error(o, "block_length");
  o = {};
  o.turn_probability = 1.5;
  expect_error(o, "turn_probability");
  o = {};
  o.world_size = 9;  // < 2 * 5 * 1.
  expect_error(o, "world_size");
  o = {};
  o.sensor_range = 0;
  expect_error(o, "sensor_range");
  o = {};
  o.detection_probability = 0;
  expect_error(o, "detection_probability");
  o = {};
  o.max_observations_per_pose = -1;
  expect_error(o, "max_observations_per_pose");
  o = {};
  o.kappa = -1;
  expect_error(o, "kappa");
  o = {};
  o.tau = INFINITY;
  expect_error(o, "tau");
  o = {};
  o.landmark_nu = 0;
  expect_error(o, "landmark_nu");
  o = {};
  o.gps_interval = -2;
  expect_error(o, "gps_interval");
  o = {};
  o.gps_tau = 0;
  expect_error(o, "gps_tau");
  o = {};
  o.start_prior = true;
  o.start_prior_kappa = 0;
  expect_error(o, "start_prior_kappa");
}

// The baselines on generated graphs, from odometry: a noiseless map is
// recovered exactly (in the world frame with a start prior and GPS priors).
TEST(LandmarkGenerator, CeresFromOdometryRecoversANoiselessMap) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    LandmarkGraphOptions o = Small(d);
    o.num_poses = 120;
    o.noiseless = true;
    o.gps_interval = 10;
    o.start_prior = true;
    Solution truth;
    const PoseGraph g = Generate(o, &truth);
    // Odometry from the start prior is exact here; perturb it to make the
    // solver work: every pose and landmark moved by ~0.1.
    Solution start{OdometryInitialization(g), {}};
    start.landmarks = InitialLandmarkPositions(g, start.poses);
    double start_error = 0;
    for (int i = 0; i < g.num_poses; ++i) {
      start.poses[i].t.array() += 0.1 * std::sin(i);
      start_error =
          std::max(start_error, (start.poses[i].t - truth.poses[i].t).norm());
    }
    for (auto& p : start.landmarks) p.array() -= 0.1;
    ASSERT_GT(start_error, 0.05);
    CeresBaselineOptions options;
    options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
    options.function_tolerance = 1e-16;
    options.gradient_tolerance = 1e-16;
    options.parameter_tolerance = 1e-14;
    Solution result;
    CeresBaselineSummary summary;
    std::string error;
    ASSERT_TRUE(SolveWithCeres(g, start, options, &result, &summary, &error))
        << error;
    EXPECT_LT(summary.final_objective, 1e-16) << summary.BriefReport();
    double worst = 0;
    for (int i = 0; i < g.num_poses; ++i) {
      worst = std::max({worst, (result.poses[i].t - truth.poses[i].t).norm(),
                        (result.poses[i].R - truth.poses[i].R).norm()});
    }
    for (int l = 0; l < g.num_landmarks; ++l) {
      worst =
          std::max(worst, (result.landmarks[l] - truth.landmarks[l]).norm());
    }
    EXPECT_LT(worst, 1e-7);
  }
}

// Runs the tool with `arguments`, its stderr to `stderr_path` (or
// discarded); returns its exit code.
int RunTool(const std::string& arguments,
            const std::string& stderr_path = "/dev/null") {
  const std::string command = std::string(CERES_SESYNC_TOOL) + " " + arguments +
                              " >/dev/null 2>" + stderr_path;
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool Exists(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "r");
  if (f) std::fclose(f);
  return f != nullptr;
}

TEST(GenerateLandmarksCommand, WritesTheGraphAndTheGroundTruth) {
  if (std::string(CERES_SESYNC_TOOL).empty()) {
    GTEST_SKIP() << "the ceres_sesync tool is not built";
  }
  const std::string dir = std::string(CERES_SESYNC_BINARY_DIR);
  const std::string output = dir + "/landmark_generator_test_graph.g2o";
  const std::string truth_path = dir + "/landmark_generator_test_truth.g2o";
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    std::remove(output.c_str());
    std::remove(truth_path.c_str());
    ASSERT_EQ(RunTool("generate landmarks --dimension " + std::to_string(d) +
                      " --num_poses 150 --world_size 20 --num_landmarks 200 "
                      "--sensor_range 4 --gps_interval 30 --start_prior "
                      "--seed 5 --output " +
                      output + " --ground_truth " + truth_path),
              0);
    LandmarkGraphOptions o;
    o.dimension = d;
    o.num_poses = 150;
    o.world_size = 20;
    o.num_landmarks = 200;
    o.sensor_range = 4;
    o.gps_interval = 30;
    o.start_prior = true;
    o.seed = 5;
    Solution truth;
    const PoseGraph expected = Generate(o, &truth);
    PoseGraph graph;
    std::string error;
    ASSERT_TRUE(ReadG2oFile(output, {}, &graph, &error)) << error;
    EXPECT_EQ(graph.num_poses, expected.num_poses);
    EXPECT_EQ(graph.num_landmarks, expected.num_landmarks);
    EXPECT_EQ(graph.landmark_measurements.size(),
              expected.landmark_measurements.size());
    EXPECT_EQ(graph.priors.size(), expected.priors.size());
    // Default vertices: odometry, landmarks from their first observation.
    ASSERT_EQ(static_cast<int>(graph.initial_landmarks.size()),
              graph.num_landmarks);
    // The ground-truth file reproduces F(truth) of the generated graph.
    Solution file_truth;
    ASSERT_TRUE(ReadG2oSolution(truth_path, graph, &file_truth, &error))
        << error;
    const double f = EvaluateObjective(expected, truth);
    EXPECT_NEAR(EvaluateObjective(graph, file_truth), f, 1e-9 * f);
  }
  // The generated graph (the last one, 3D) solves and certifies with the
  // program; its solution file reads back with every landmark.
  const std::string solved = dir + "/landmark_generator_test_solved.g2o";
  std::remove(solved.c_str());
  EXPECT_EQ(RunTool("solve " + output + " --output " + solved), 0);
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(ReadG2oFile(output, {}, &graph, &error)) << error;
  Solution solution;
  ASSERT_TRUE(ReadG2oSolution(solved, graph, &solution, &error)) << error;
  EXPECT_EQ(static_cast<int>(solution.landmarks.size()), graph.num_landmarks);
  EXPECT_EQ(RunTool("certify " + output + " " + solved), 0);
  std::remove(solved.c_str());

  std::remove(output.c_str());
  EXPECT_EQ(RunTool("generate landmarks"), 2);  // No --output.
  EXPECT_EQ(RunTool("generate landmarks extra --output " + output), 2);
  EXPECT_EQ(RunTool("generate landmarks --preset city --output " + output), 2);
  EXPECT_EQ(RunTool("generate landmarks --num_poses 1 --output " + output), 2);
  EXPECT_EQ(RunTool("generate landmarks --dimension 4 --output " + output), 2);
  EXPECT_EQ(RunTool("generate landmarks --sensor_range -1 --output " + output),
            2);
  // Flags of the other models (cube, city, outliers).
  EXPECT_EQ(RunTool("generate landmarks --side 4 --output " + output), 2);
  EXPECT_EQ(RunTool("generate landmarks --fraction 0.1 --output " + output), 2);
  EXPECT_EQ(
      RunTool("generate landmarks --landmark_fraction 0.1 --output " + output),
      2);
  EXPECT_EQ(RunTool("generate landmarks --vertices bogus --output " + output),
            2);
  EXPECT_FALSE(Exists(output)) << "a failed run left " << output;
  std::remove(truth_path.c_str());
}

}  // namespace
}  // namespace ceres_sesync
