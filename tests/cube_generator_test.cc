// Tests of the synthetic cube generator: structure (lattice path, odometry,
// loop closures), noise statistics against closed forms, determinism, and
// option validation.

#include "ceres_sesync/cube_generator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/LU"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/langevin.h"
#include "gtest/gtest.h"
#include "tests/util/tool_runner.h"

namespace ceres_sesync {
namespace {

bool IsRotation(const Eigen::MatrixXd& R, int d) {
  return R.rows() == d && R.cols() == d &&
         (R.transpose() * R - Eigen::MatrixXd::Identity(d, d)).norm() < 1e-12 &&
         std::abs(R.determinant() - 1) < 1e-12;
}

PoseGraph Generate(const CubeOptions& options, Poses* truth) {
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateCube(options, &graph, truth, &error)) << error;
  return graph;
}

// Unordered pairs {i, j}, |i - j| > 1, whose true positions are exactly one
// lattice spacing apart: the loop-closure candidates, found by brute force.
int CountCandidatePairs(const Poses& truth, double spacing) {
  int count = 0;
  const int n = static_cast<int>(truth.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 2; j < n; ++j) {
      if (std::abs((truth[i].t - truth[j].t).norm() - spacing) < 1e-9) ++count;
    }
  }
  return count;
}

TEST(GenerateCube, StructureOfGraphAndGroundTruth) {
  for (int d : {2, 3}) {
    for (int s : {2, 3, 5}) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " s=" << s);
      CubeOptions options;
      options.dimension = d;
      options.side = s;
      options.spacing = 1.5;
      options.seed = 42;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      const int n = static_cast<int>(std::pow(s, d) + 0.5);
      ASSERT_EQ(graph.num_poses, n);
      ASSERT_EQ(static_cast<int>(truth.size()), n);
      EXPECT_EQ(graph.dimension, d);
      EXPECT_TRUE(graph.initial_poses.empty());
      EXPECT_EQ(graph.fixed_pose, -1);
      std::string error;
      EXPECT_TRUE(ValidatePoseGraph(graph, &error)) << error;  // connected
      for (int i = 0; i < n; ++i) EXPECT_EQ(graph.vertex_ids[i], i);

      // Ground truth: every lattice point visited once; unit steps along one
      // axis; each pose faces its direction of travel.
      std::set<std::vector<long>> visited;
      for (int i = 0; i < n; ++i) {
        ASSERT_TRUE(IsRotation(truth[i].R, d));
        std::vector<long> cell(d);
        for (int k = 0; k < d; ++k) {
          const double c = truth[i].t[k] / options.spacing;
          cell[k] = std::lround(c);
          EXPECT_NEAR(c, cell[k], 1e-12);
          EXPECT_GE(cell[k], 0);
          EXPECT_LT(cell[k], s);
        }
        visited.insert(cell);
        if (i + 1 < n) {
          const Eigen::VectorXd step = truth[i + 1].t - truth[i].t;
          EXPECT_NEAR(step.norm(), options.spacing, 1e-12);
          EXPECT_NEAR(step.cwiseAbs().maxCoeff(), options.spacing, 1e-12);
          EXPECT_LT((truth[i].R.col(0) - step / options.spacing).norm(), 1e-12)
              << "pose " << i << " does not face its direction of travel";
        }
      }
      EXPECT_EQ(static_cast<int>(visited.size()), n);

      // Odometry: exactly one edge (j - 1, j) per j >= 1. Loop closures:
      // lattice neighbours, non-sequential, each pair at most once.
      std::vector<int> odometry(n, 0);
      std::set<std::pair<int, int>> closures;
      for (const RelativePoseMeasurement& e : graph.measurements) {
        EXPECT_EQ(e.kappa, options.kappa);
        EXPECT_EQ(e.tau, options.tau);
        ASSERT_LT(e.i, e.j);
        if (e.j == e.i + 1) {
          ++odometry[e.j];
        } else {
          EXPECT_NEAR((truth[e.i].t - truth[e.j].t).norm(), options.spacing,
                      1e-12);
          EXPECT_TRUE(closures.insert({e.i, e.j}).second);
        }
      }
      for (int j = 1; j < n; ++j) EXPECT_EQ(odometry[j], 1) << j;
    }
  }
}

TEST(GenerateCube, CandidateCountMatchesLatticeFormula) {
  // All lattice-neighbour pairs, d s^(d-1) (s-1), minus the n-1 consecutive
  // ones; pLC = 1 must take all of them and pLC = 0 none.
  for (int d : {2, 3}) {
    const int s = 4;
    CubeOptions options;
    options.dimension = d;
    options.side = s;
    Poses truth;
    options.loop_closure_probability = 1;
    const PoseGraph all = Generate(options, &truth);
    const int n = all.num_poses;
    const int candidates =
        d * static_cast<int>(std::pow(s, d - 1) + 0.5) * (s - 1) - (n - 1);
    EXPECT_EQ(CountCandidatePairs(truth, options.spacing), candidates);
    EXPECT_EQ(static_cast<int>(all.measurements.size()) - (n - 1), candidates);
    options.loop_closure_probability = 0;
    const PoseGraph none = Generate(options, nullptr);
    EXPECT_EQ(static_cast<int>(none.measurements.size()), n - 1);
  }
}

// Unordered pairs {i, j}, |i - j| > 1, whose true positions are at most
// `max_distance` apart (brute force).
int CountPairsWithin(const Poses& truth, double max_distance) {
  int count = 0;
  const int n = static_cast<int>(truth.size());
  for (int i = 0; i < n; ++i) {
    for (int j = i + 2; j < n; ++j) {
      if ((truth[i].t - truth[j].t).norm() <= max_distance + 1e-9) ++count;
    }
  }
  return count;
}

TEST(GenerateCube, LoopClosureRadiusSelectsPairsWithinRadius) {
  // pLC = 1 takes every candidate: exactly the non-consecutive pairs within
  // radius * spacing, each once, oriented from the earlier pose. Radii
  // given to a few digits (1.732) select the same offsets as sqrt(3).
  for (int d : {2, 3}) {
    for (double radius :
         {1.0, 1.2, std::sqrt(2.0), 1.414, std::sqrt(3.0), 1.732, 2.0, 2.5}) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " r=" << radius);
      CubeOptions options;
      options.dimension = d;
      options.side = 5;
      options.spacing = 0.5;
      options.loop_closure_probability = 1;
      options.loop_closure_radius = radius;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      const int n = graph.num_poses;
      // The squared lattice distances are integers: round the radius the
      // way the generator documents (|o|^2 <= r^2 + 1e-3).
      const double lattice_radius = std::sqrt(radius * radius + 1e-3);
      const int expected = CountPairsWithin(truth, lattice_radius * 0.5);
      EXPECT_EQ(static_cast<int>(graph.measurements.size()) - (n - 1),
                expected);
      std::set<std::pair<int, int>> pairs;
      for (const RelativePoseMeasurement& e : graph.measurements) {
        EXPECT_LT(e.i, e.j);
        EXPECT_TRUE(pairs.insert({e.i, e.j}).second) << e.i << " " << e.j;
        EXPECT_LE((truth[e.i].t - truth[e.j].t).norm(),
                  lattice_radius * 0.5 + 1e-9);
      }
    }
  }
  // Known counts on a side-4 cube: lattice neighbours 3 * 16 * 3 = 144, face
  // diagonals 3 * 2 * 4 * 9 = 216, body diagonals 4 * 27 = 108; minus the 63
  // consecutive pairs.
  CubeOptions options;
  options.side = 4;
  options.loop_closure_probability = 1;
  const int n = 64;
  for (const auto& [radius, candidates] :
       std::vector<std::pair<double, int>>{{1.0, 144 - 63},
                                           {std::sqrt(2.0), 144 + 216 - 63},
                                           {1.732, 144 + 216 + 108 - 63}}) {
    options.loop_closure_radius = radius;
    EXPECT_EQ(static_cast<int>(Generate(options, nullptr).measurements.size()),
              n - 1 + candidates)
        << radius;
  }
}

TEST(GenerateCube, DefaultRadiusKeepsTheRandomStream) {
  // Radii below sqrt(2) select the unit offsets only and must reproduce the
  // radius-1 graph bit for bit (the generator's stream before the option
  // existed). At pLC = 1, sqrt(2) must give a strict superset of the pairs.
  for (int d : {2, 3}) {
    CubeOptions options;
    options.dimension = d;
    options.side = 5;
    options.loop_closure_probability = 0.3;
    options.seed = 7;
    const PoseGraph a = Generate(options, nullptr);
    options.loop_closure_radius = 1.41;
    const PoseGraph b = Generate(options, nullptr);
    ASSERT_EQ(a.measurements.size(), b.measurements.size());
    for (size_t k = 0; k < a.measurements.size(); ++k) {
      EXPECT_EQ(a.measurements[k].i, b.measurements[k].i);
      EXPECT_EQ(a.measurements[k].j, b.measurements[k].j);
      EXPECT_EQ(a.measurements[k].R, b.measurements[k].R);  // bitwise
      EXPECT_EQ(a.measurements[k].t, b.measurements[k].t);
    }
    options.loop_closure_probability = 1;
    options.loop_closure_radius = 1;
    const PoseGraph unit = Generate(options, nullptr);
    options.loop_closure_radius = std::sqrt(2.0);
    const PoseGraph diagonal = Generate(options, nullptr);
    std::set<std::pair<int, int>> diagonal_pairs;
    for (const RelativePoseMeasurement& e : diagonal.measurements) {
      diagonal_pairs.insert({e.i, e.j});
    }
    for (const RelativePoseMeasurement& e : unit.measurements) {
      EXPECT_TRUE(diagonal_pairs.count({e.i, e.j})) << e.i << " " << e.j;
    }
    EXPECT_GT(diagonal.measurements.size(), unit.measurements.size());
  }
}

TEST(GenerateCube, LoopClosureCountIsBinomial) {
  // The number of loop closures is Binomial(N, pLC) with N the candidate
  // count; accept within 5 standard deviations (per seed and in total).
  for (int d : {2, 3}) {
    for (double p : {0.1, 0.5}) {
      long total = 0, total_candidates = 0;
      for (uint64_t seed = 0; seed < 5; ++seed) {
        CubeOptions options;
        options.dimension = d;
        options.side = d == 3 ? 8 : 20;
        options.loop_closure_probability = p;
        options.seed = seed;
        Poses truth;
        const PoseGraph graph = Generate(options, &truth);
        const int candidates = CountCandidatePairs(truth, options.spacing);
        const int closures =
            static_cast<int>(graph.measurements.size()) - (graph.num_poses - 1);
        const double sd = std::sqrt(candidates * p * (1 - p));
        EXPECT_LE(std::abs(closures - candidates * p), 5 * sd)
            << "d=" << d << " p=" << p << " seed=" << seed;
        total += closures;
        total_candidates += candidates;
      }
      EXPECT_LE(std::abs(total - total_candidates * p),
                5 * std::sqrt(total_candidates * p * (1 - p)));
    }
  }
}

TEST(GenerateCube, NoiselessLimitReproducesGroundTruth) {
  // kappa = tau = 1e12: rotation noise ~ 1/sqrt(2e12) ~ 7e-7 rad, translation
  // noise ~ 1e-6 m. Measurements must match the true relative poses to that
  // level, and F(truth) must be O(m) (each edge contributes E = 1 + d) while
  // F of the same weights at a 1e-3 perturbation is ~1e6 times larger.
  for (int d : {2, 3}) {
    CubeOptions options;
    options.dimension = d;
    options.side = 4;
    options.kappa = 1e12;
    options.tau = 1e12;
    Poses truth;
    const PoseGraph graph = Generate(options, &truth);
    const int m = static_cast<int>(graph.measurements.size());
    for (const RelativePoseMeasurement& e : graph.measurements) {
      const Eigen::MatrixXd R = truth[e.i].R.transpose() * truth[e.j].R;
      const Eigen::VectorXd t =
          truth[e.i].R.transpose() * (truth[e.j].t - truth[e.i].t);
      EXPECT_LT((e.R - R).norm(), 1e-5);
      EXPECT_LT((e.t - t).norm(), 1e-5);
    }
    const double f = EvaluateObjective(graph, truth);
    EXPECT_LT(f / (options.kappa * m), 1e-10);
    EXPECT_LT(f, 10.0 * (1 + d) * m);
  }
}

TEST(GenerateCube, DeterministicForASeed) {
  CubeOptions options;
  options.side = 4;
  options.loop_closure_probability = 0.3;
  options.seed = 123;
  const PoseGraph a = Generate(options, nullptr);
  const PoseGraph b = Generate(options, nullptr);
  ASSERT_EQ(a.measurements.size(), b.measurements.size());
  for (size_t k = 0; k < a.measurements.size(); ++k) {
    EXPECT_EQ(a.measurements[k].i, b.measurements[k].i);
    EXPECT_EQ(a.measurements[k].j, b.measurements[k].j);
    EXPECT_EQ(a.measurements[k].R, b.measurements[k].R);  // bitwise
    EXPECT_EQ(a.measurements[k].t, b.measurements[k].t);
  }
  options.seed = 124;
  const PoseGraph c = Generate(options, nullptr);
  // Another seed: different noise on the first odometry edge (a collision
  // has probability 0) and, almost surely, different measurements overall.
  EXPECT_NE(a.measurements[0].t, c.measurements[0].t);
  EXPECT_NE(a.measurements[0].R, c.measurements[0].R);
}

TEST(GenerateCube, GroundTruthObjectiveMatchesExpectation) {
  // Per edge, F_e(x_true) = kappa ||P - I||^2 + tau ||eps||^2 with P ~
  // Langevin(I, kappa) and eps ~ N(0, tau^-1 I_d), so E[F_e] = 4 kappa (1 -
  // I1(2 kappa) / I0(2 kappa)) + d. The per-edge contributions are i.i.d.;
  // their mean must be within 5 standard errors of E[F_e].
  struct Case {
    int d, side;
    double kappa, tau;
  };
  for (const Case& c : {Case{3, 10, 16.67, 75}, Case{3, 8, 1.0, 5},
                        Case{2, 40, 16.67, 75}, Case{2, 40, 300, 0.5}}) {
    CubeOptions options;
    options.dimension = c.d;
    options.side = c.side;
    options.kappa = c.kappa;
    options.tau = c.tau;
    options.seed = 99;
    Poses truth;
    const PoseGraph graph = Generate(options, &truth);
    const int m = static_cast<int>(graph.measurements.size());
    double sum = 0, sum2 = 0, total = 0;
    for (const RelativePoseMeasurement& e : graph.measurements) {
      const Pose& a = truth[e.i];
      const Pose& b = truth[e.j];
      const double f = e.kappa * (b.R - a.R * e.R).squaredNorm() +
                       e.tau * (b.t - a.t - a.R * e.t).squaredNorm();
      sum += f;
      sum2 += f * f;
    }
    total = EvaluateObjective(graph, truth);
    const double mean = sum / m;
    const double standard_error = std::sqrt((sum2 / m - mean * mean) / (m - 1));
    const double expected = ExpectedGroundTruthObjective(c.d, m, c.kappa) / m;
    EXPECT_NEAR(total, sum, 1e-9 * sum);
    EXPECT_LE(std::abs(mean - expected), 5 * standard_error)
        << "d=" << c.d << " kappa=" << c.kappa << ": mean " << mean
        << " expected " << expected << " se " << standard_error;
  }
  // Closed form at the paper's default: 4 * 16.67 * (1 - A(33.34)) ~ 1.0,
  // plus d: about 4 per edge in 3D.
  EXPECT_NEAR(ExpectedGroundTruthObjective(3, 1, 16.67), 4.0, 0.05);
}

TEST(GenerateCube, PaperDefaultsGiveTheStatedRmsErrors) {
  // Section 6.1: kappa = 16.67 "corresponds to an expected angular RMS error
  // of 10 deg" (eq. 63) and tau = 75 to "an expected RMS error of 0.20 m"
  // (sqrt(d / tau) in 3D). Measured on the generated measurements against
  // the ground truth: mean squared angle and mean squared translation error
  // within 5 standard errors of 10 deg^2 and 0.2^2 (pooled over seeds).
  for (int d : {2, 3}) {
    std::vector<double> angle2, translation2;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
      CubeOptions options;  // kappa 16.67, tau 75, pLC 0.1
      options.dimension = d;
      options.side = d == 3 ? 10 : 30;
      options.seed = seed;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      for (const RelativePoseMeasurement& e : graph.measurements) {
        const Eigen::MatrixXd noise =
            (truth[e.i].R.transpose() * truth[e.j].R).transpose() * e.R;
        const double c = std::clamp((noise.trace() - (d - 2)) / 2, -1.0, 1.0);
        const double angle = std::acos(c);
        angle2.push_back(angle * angle);
        translation2.push_back(
            (e.t - truth[e.i].R.transpose() * (truth[e.j].t - truth[e.i].t))
                .squaredNorm());
      }
    }
    auto expect_mean = [](const std::vector<double>& x, double expected,
                          const char* what) {
      double sum = 0, sum2 = 0;
      for (double v : x) sum += v;
      const double mean = sum / x.size();
      for (double v : x) sum2 += (v - mean) * (v - mean);
      const double se = std::sqrt(sum2 / (x.size() - 1) / x.size());
      EXPECT_LE(std::abs(mean - expected), 5 * se)
          << what << ": mean " << mean << " expected " << expected;
    };
    SCOPED_TRACE(d);
    const double rms_angle = LangevinAngularStandardDeviation(16.67);
    EXPECT_NEAR(rms_angle * 180 / 3.14159265358979323846, 10.0, 0.01);
    expect_mean(angle2, rms_angle * rms_angle, "squared angle");
    expect_mean(translation2, d / 75.0, "squared translation error");
    if (d == 3) {
      EXPECT_NEAR(std::sqrt(d / 75.0), 0.2, 1e-12);
    }
  }
}

TEST(GenerateCube, RejectsInvalidOptions) {
  auto expect_error = [](const CubeOptions& options) {
    PoseGraph graph;
    Poses truth;
    std::string error;
    EXPECT_FALSE(GenerateCube(options, &graph, &truth, &error));
    EXPECT_FALSE(error.empty());
  };
  CubeOptions o;
  o.dimension = 4;
  expect_error(o);
  o = CubeOptions();
  o.side = 1;
  expect_error(o);
  o = CubeOptions();
  o.side = 100000;  // 1e15 poses
  expect_error(o);
  o = CubeOptions();
  o.loop_closure_probability = 1.5;
  expect_error(o);
  o = CubeOptions();
  o.loop_closure_probability = NAN;
  expect_error(o);
  o = CubeOptions();
  o.kappa = 0;
  expect_error(o);
  o = CubeOptions();
  o.tau = INFINITY;
  expect_error(o);
  o = CubeOptions();
  o.spacing = -1;
  expect_error(o);
  for (double radius : {0.0, 0.99, 4.5, double(NAN), double(INFINITY)}) {
    o = CubeOptions();
    o.loop_closure_radius = radius;
    expect_error(o);
  }
}

using test_util::RunTool;

TEST(GenerateCommand, WritesTheGeneratedGraph) {
  if (!test_util::ToolBuilt()) {
    GTEST_SKIP() << "the ceres_sesync tool is not built";
  }
  const std::string dir = std::string(CERES_SESYNC_BINARY_DIR);
  const std::string output = dir + "/cube_generator_test_graph.g2o";
  const std::string truth_path = dir + "/cube_generator_test_truth.g2o";
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    std::remove(output.c_str());
    std::remove(truth_path.c_str());
    ASSERT_EQ(
        RunTool("generate cube --side 3 --dimension " + std::to_string(d) +
                " --loop_closure_probability 0.5 --kappa 20 --tau 50 "
                "--seed 17 --output " +
                output + " --ground_truth " + truth_path),
        0);
    CubeOptions options;
    options.dimension = d;
    options.side = 3;
    options.loop_closure_probability = 0.5;
    options.kappa = 20;
    options.tau = 50;
    options.seed = 17;
    Poses truth;
    const PoseGraph expected = Generate(options, &truth);

    PoseGraph graph;
    std::string error;
    ASSERT_TRUE(ReadG2oFile(output, G2oReadOptions(), &graph, &error)) << error;
    ASSERT_EQ(graph.dimension, d);
    ASSERT_EQ(graph.num_poses, expected.num_poses);
    ASSERT_EQ(graph.measurements.size(), expected.measurements.size());
    for (size_t k = 0; k < graph.measurements.size(); ++k) {
      const RelativePoseMeasurement& a = graph.measurements[k];
      const RelativePoseMeasurement& b = expected.measurements[k];
      EXPECT_EQ(graph.vertex_ids[a.i], b.i);
      EXPECT_EQ(graph.vertex_ids[a.j], b.j);
      // The file stores rotations as angles / quaternions: ~1e-15 apart.
      EXPECT_LT((a.R - b.R).norm(), 1e-12);
      EXPECT_LT((a.t - b.t).norm(), 1e-12);
      EXPECT_NEAR(a.kappa, b.kappa, 1e-12 * b.kappa);
      EXPECT_NEAR(a.tau, b.tau, 1e-12 * b.tau);
    }
    // Default VERTEX lines: dead reckoning along the odometry from identity.
    ASSERT_EQ(static_cast<int>(graph.initial_poses.size()), graph.num_poses);
    EXPECT_LT(graph.initial_poses[0].t.norm(), 1e-15);
    Poses file_truth;
    ASSERT_TRUE(ReadG2oPoses(truth_path, graph, &file_truth, &error)) << error;
    for (int i = 0; i < graph.num_poses; ++i) {
      const int v = static_cast<int>(graph.vertex_ids[i]);
      EXPECT_LT((file_truth[i].R - truth[v].R).norm(), 1e-12);
      EXPECT_LT((file_truth[i].t - truth[v].t).norm(), 1e-12);
    }
  }
  // Usage errors exit with 2 and write nothing.
  std::remove(output.c_str());
  EXPECT_EQ(RunTool("generate"), 2);
  EXPECT_EQ(RunTool("generate sphere --output " + output), 2);
  EXPECT_EQ(RunTool("generate cube"), 2);
  EXPECT_EQ(RunTool("generate cube extra --output " + output), 2);
  EXPECT_EQ(RunTool("generate cube --side 1 --output " + output), 2);
  EXPECT_EQ(RunTool("generate cube --dimension 4 --output " + output), 2);
  EXPECT_EQ(RunTool("generate cube --kappa -1 --output " + output), 2);
  EXPECT_EQ(RunTool("generate cube --vertices bogus --output " + output), 2);
  EXPECT_FALSE(test_util::FileExists(output)) << "a failed run left " << output;
  std::remove(truth_path.c_str());
}

}  // namespace
}  // namespace ceres_sesync
