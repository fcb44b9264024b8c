// Tests of the city-walk generator (city_generator.h): the walk and its
// lattice, odometry and loop closures on revisits (checked against brute
// force on the ground truth), the closure-sampling law, noise statistics
// against closed forms, determinism, growth of the extent with sqrt(n),
// option validation, the CLI, and an SE-Sync solve of a small city checked
// by an independent dense certificate.

#include "ceres_sesync/city_generator.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/sesync_solver.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"
#include "tests/util/tool_runner.h"

namespace ceres_sesync {
namespace {

using Node = std::array<long, 3>;

PoseGraph Generate(const CityOptions& options, Poses* truth) {
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateCity(options, &graph, truth, &error)) << error;
  return graph;
}

// The documented lattice side L = max(2, ceil(scale * sqrt(n / levels))).
long LatticeSide(const CityOptions& o) {
  const int levels = o.dimension == 3 ? o.levels : 1;
  return std::max(
      2L, static_cast<long>(std::ceil(
              o.lattice_scale * std::sqrt(double(o.num_poses) / levels))));
}

// The lattice node of a ground-truth pose (its translation / spacing must be
// an integer vector; checked by the structure test).
Node NodeOf(const Pose& pose, double spacing) {
  Node node = {0, 0, 0};
  for (int k = 0; k < pose.t.size(); ++k) {
    node[k] = std::lround(pose.t[k] / spacing);
  }
  return node;
}

bool IsRotation(const Eigen::MatrixXd& R, int d) {
  return R.rows() == d && R.cols() == d &&
         (R.transpose() * R - Eigen::MatrixXd::Identity(d, d)).norm() < 1e-12 &&
         std::abs(R.determinant() - 1) < 1e-12;
}

// For each pose j, the earlier poses at its lattice node, newest first (brute
// force from the ground truth).
std::vector<std::vector<int>> EarlierVisits(const Poses& truth,
                                            double spacing) {
  std::map<Node, std::vector<int>> at;
  std::vector<std::vector<int>> earlier(truth.size());
  for (int j = 0; j < static_cast<int>(truth.size()); ++j) {
    std::vector<int>& visits = at[NodeOf(truth[j], spacing)];
    earlier[j].assign(visits.rbegin(), visits.rend());
    visits.push_back(j);
  }
  return earlier;
}

TEST(GenerateCity, StructureOfWalkAndGraph) {
  for (int d : {2, 3}) {
    for (int n : {2, 3, 50, 3000}) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " n=" << n);
      CityOptions options;
      options.dimension = d;
      options.num_poses = n;
      options.spacing = 2.5;
      options.seed = 11;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      ASSERT_EQ(graph.num_poses, n);
      ASSERT_EQ(static_cast<int>(truth.size()), n);
      EXPECT_EQ(graph.dimension, d);
      EXPECT_TRUE(graph.initial_poses.empty());
      EXPECT_EQ(graph.fixed_pose, -1);
      std::string error;
      EXPECT_TRUE(ValidatePoseGraph(graph, &error)) << error;  // connected
      for (int i = 0; i < n; ++i) EXPECT_EQ(graph.vertex_ids[i], i);

      // The walk: pose 0 at the origin; lattice points (translation /
      // spacing integral) inside the documented L x L (x levels) lattice
      // around the start node (floor(L/2), floor(L/2), 0); unit steps along
      // one axis, never straight back; each pose faces its next step.
      const long side = LatticeSide(options);
      const long height = d == 3 ? options.levels : 1;
      EXPECT_LT(truth[0].t.norm(), 1e-15);
      for (int i = 0; i < n; ++i) {
        ASSERT_TRUE(IsRotation(truth[i].R, d));
        ASSERT_EQ(truth[i].t.size(), d);
        const Node node = NodeOf(truth[i], options.spacing);
        for (int k = 0; k < d; ++k) {
          EXPECT_NEAR(truth[i].t[k] / options.spacing, node[k], 1e-12);
        }
        EXPECT_GE(node[0] + side / 2, 0);
        EXPECT_LT(node[0] + side / 2, side);
        EXPECT_GE(node[1] + side / 2, 0);
        EXPECT_LT(node[1] + side / 2, side);
        EXPECT_GE(node[2], 0);
        EXPECT_LT(node[2], height);
        if (i + 1 < n) {
          const Eigen::VectorXd step = truth[i + 1].t - truth[i].t;
          EXPECT_NEAR(step.norm(), options.spacing, 1e-12);
          EXPECT_NEAR(step.cwiseAbs().maxCoeff(), options.spacing, 1e-12);
          EXPECT_LT((truth[i].R.col(0) - step / options.spacing).norm(), 1e-12)
              << "pose " << i << " does not face its direction of travel";
          if (i > 0) {
            EXPECT_GT((step + truth[i].t - truth[i - 1].t).norm(), 1e-9)
                << "the walk reversed at pose " << i;
          }
        }
      }
      if (n > 1) {
        EXPECT_LT((truth[n - 1].R - truth[n - 2].R).norm(), 1e-15);
      }

      // Odometry: exactly one edge (j - 1, j) per j >= 1. Loop closures: two
      // poses at the same lattice node, non-consecutive, each pair once, at
      // most max_loop_closures_per_visit per later pose, edges in order of
      // the later pose.
      std::vector<int> odometry(n, 0), closures_of(n, 0);
      std::set<std::pair<int, int>> closures;
      int previous_j = 0;
      for (const RelativePoseMeasurement& e : graph.measurements) {
        EXPECT_EQ(e.kappa, options.kappa);
        EXPECT_EQ(e.tau, options.tau);
        ASSERT_LT(e.i, e.j);
        EXPECT_GE(e.j, previous_j);
        previous_j = e.j;
        if (e.j == e.i + 1) {
          ++odometry[e.j];
        } else {
          EXPECT_EQ(NodeOf(truth[e.i], options.spacing),
                    NodeOf(truth[e.j], options.spacing))
              << e.i << " " << e.j;
          EXPECT_LT((truth[e.i].t - truth[e.j].t).norm(), 1e-12);
          EXPECT_TRUE(closures.insert({e.i, e.j}).second);
          ++closures_of[e.j];
        }
      }
      for (int j = 1; j < n; ++j) EXPECT_EQ(odometry[j], 1) << j;
      for (int j = 0; j < n; ++j) {
        EXPECT_LE(closures_of[j], options.max_loop_closures_per_visit);
      }
      if (n >= 3000) {
        // The walk revisits places: the default options give ~0.6 closures
        // per pose; far fewer means the lattice or the sampling is broken.
        EXPECT_GT(static_cast<int>(closures.size()), n / 5);
      }
    }
  }
}

TEST(GenerateCity, ClosuresGoToTheNewestEarlierVisits) {
  // pLC = 1: every arrival gets exactly min(k, cap) closures, to the cap
  // newest of its k earlier visits (brute force). pLC = 0 or cap = 0: an
  // odometry chain. Also on a 2 x 2 lattice (scale tiny), where every node
  // is revisited thousands of times.
  for (int d : {2, 3}) {
    for (double scale : {0.5, 1e-6}) {
      for (int cap : {1, 3}) {
        SCOPED_TRACE(::testing::Message()
                     << "d=" << d << " scale=" << scale << " cap=" << cap);
        CityOptions options;
        options.dimension = d;
        options.num_poses = 4000;
        options.lattice_scale = scale;
        options.loop_closure_probability = 1;
        options.max_loop_closures_per_visit = cap;
        options.seed = 3;
        Poses truth;
        const PoseGraph graph = Generate(options, &truth);
        const std::vector<std::vector<int>> earlier =
            EarlierVisits(truth, options.spacing);
        std::vector<std::vector<int>> got(graph.num_poses);
        for (const RelativePoseMeasurement& e : graph.measurements) {
          if (e.j != e.i + 1) got[e.j].push_back(e.i);
        }
        long total = 0;
        for (int j = 0; j < graph.num_poses; ++j) {
          const size_t count =
              std::min(earlier[j].size(), static_cast<size_t>(cap));
          const std::vector<int> expected(earlier[j].begin(),
                                          earlier[j].begin() + count);
          EXPECT_EQ(got[j], expected) << "pose " << j;
          total += count;
        }
        EXPECT_GT(total, graph.num_poses / 4);
      }
    }
  }
  CityOptions options;
  options.num_poses = 2000;
  options.loop_closure_probability = 0;
  EXPECT_EQ(Generate(options, nullptr).measurements.size(), 1999u);
  options.loop_closure_probability = 0.5;
  options.max_loop_closures_per_visit = 0;
  EXPECT_EQ(Generate(options, nullptr).measurements.size(), 1999u);
}

TEST(GenerateCity, ClosureCountsFollowTheSamplingLaw) {
  // Each earlier visit is accepted independently with probability p, newest
  // first, until cap acceptances. For an arrival with k earlier visits the
  // closure count is min(Binomial(k, p), cap). Checked against exact means
  // and variances summed over all arrivals (5 standard deviations), for a
  // cap that never binds (pure Binomial) and for cap 2; plus the acceptance
  // rate of the newest and of the second-newest candidate separately (the
  // geometric skips must not favour any position).
  for (double p : {0.1, 0.5, 0.9}) {
    for (int cap : {2, 100000}) {
      SCOPED_TRACE(::testing::Message() << "p=" << p << " cap=" << cap);
      CityOptions options;
      options.num_poses = 20000;
      options.loop_closure_probability = p;
      options.max_loop_closures_per_visit = cap;
      options.seed = 17;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      const std::vector<std::vector<int>> earlier =
          EarlierVisits(truth, options.spacing);
      std::vector<std::set<int>> got(graph.num_poses);
      long closures = 0;
      for (const RelativePoseMeasurement& e : graph.measurements) {
        if (e.j == e.i + 1) continue;
        got[e.j].insert(e.i);
        ++closures;
      }
      double mean = 0, variance = 0;
      long newest_trials = 0, newest_hits = 0;
      long second_trials = 0, second_hits = 0;
      for (int j = 0; j < graph.num_poses; ++j) {
        const int k = static_cast<int>(earlier[j].size());
        // Distribution of min(B, cap) for B ~ Binomial(k, p).
        double pk = std::pow(1 - p, k);  // P(B = 0)
        double e1 = 0, e2 = 0;
        for (int b = 0; b <= k; ++b) {
          const double v = std::min(b, cap);
          e1 += v * pk;
          e2 += v * v * pk;
          pk *= (k - b) * p / ((b + 1) * (1 - p));
        }
        mean += e1;
        variance += e2 - e1 * e1;
        if (k >= 1) {
          ++newest_trials;
          newest_hits += got[j].count(earlier[j][0]);
        }
        // The second-newest candidate is examined whatever the newest did
        // when cap >= 2.
        if (k >= 2) {
          ++second_trials;
          second_hits += got[j].count(earlier[j][1]);
        }
      }
      EXPECT_GT(mean, 1000);
      EXPECT_LE(std::abs(closures - mean), 5 * std::sqrt(variance))
          << closures << " closures, expected " << mean;
      auto expect_rate = [p](long hits, long trials, const char* what) {
        EXPECT_LE(std::abs(hits - p * trials),
                  5 * std::sqrt(trials * p * (1 - p)))
            << what << ": " << hits << " of " << trials;
      };
      expect_rate(newest_hits, newest_trials, "newest earlier visit");
      expect_rate(second_hits, second_trials, "second-newest earlier visit");
    }
  }
}

TEST(GenerateCity, NoiseMatchesTheRequestedKappaAndTau) {
  // Measured on the generated measurements against the ground truth: the
  // mean squared rotation angle is LangevinAngularStandardDeviation(kappa)^2
  // (eq. 63), the mean squared translation error d / tau, and the mean
  // per-edge objective at the ground truth 4 kappa (1 - I1(2 kappa) /
  // I0(2 kappa)) + d (ExpectedGroundTruthObjective), each within 5 standard
  // errors.
  struct Case {
    int d;
    double kappa, tau;
  };
  for (const Case& c : {Case{2, 100, 100}, Case{2, 16.67, 75},
                        Case{3, 100, 100}, Case{3, 2.0, 5}}) {
    SCOPED_TRACE(::testing::Message()
                 << "d=" << c.d << " kappa=" << c.kappa << " tau=" << c.tau);
    CityOptions options;
    options.dimension = c.d;
    // ~64000 edges: 5 standard errors of the mean squared angle are ~3%,
    // so a 5% error in kappa or tau is detected.
    options.num_poses = 40000;
    options.kappa = c.kappa;
    options.tau = c.tau;
    options.seed = 5;
    Poses truth;
    const PoseGraph graph = Generate(options, &truth);
    std::vector<double> angle2, translation2, objective;
    for (const RelativePoseMeasurement& e : graph.measurements) {
      const Pose& a = truth[e.i];
      const Pose& b = truth[e.j];
      const Eigen::MatrixXd noise = (a.R.transpose() * b.R).transpose() * e.R;
      const double cosine =
          std::clamp((noise.trace() - (c.d - 2)) / 2, -1.0, 1.0);
      angle2.push_back(std::pow(std::acos(cosine), 2));
      translation2.push_back(
          (e.t - a.R.transpose() * (b.t - a.t)).squaredNorm());
      objective.push_back(e.kappa * (b.R - a.R * e.R).squaredNorm() +
                          e.tau * (b.t - a.t - a.R * e.t).squaredNorm());
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
    const double rms = LangevinAngularStandardDeviation(c.kappa);
    expect_mean(angle2, rms * rms, "squared angle");
    expect_mean(translation2, c.d / c.tau, "squared translation error");
    const int m = static_cast<int>(graph.measurements.size());
    expect_mean(objective, ExpectedGroundTruthObjective(c.d, m, c.kappa) / m,
                "objective per edge");
    double total = 0;
    for (double f : objective) total += f;
    EXPECT_NEAR(EvaluateObjective(graph, truth), total, 1e-9 * total);
  }
  // The documented default: 100 ~ 4.06 degrees RMS.
  EXPECT_NEAR(LangevinAngularStandardDeviation(CityOptions().kappa) * 180 /
                  3.14159265358979323846,
              4.06, 0.01);
}

TEST(GenerateCity, DeterministicForASeed) {
  for (int d : {2, 3}) {
    CityOptions options;
    options.dimension = d;
    options.num_poses = 3000;
    options.seed = 123;
    Poses truth_a, truth_b, truth_c;
    const PoseGraph a = Generate(options, &truth_a);
    const PoseGraph b = Generate(options, &truth_b);
    ASSERT_EQ(a.measurements.size(), b.measurements.size());
    for (size_t k = 0; k < a.measurements.size(); ++k) {
      EXPECT_EQ(a.measurements[k].i, b.measurements[k].i);
      EXPECT_EQ(a.measurements[k].j, b.measurements[k].j);
      EXPECT_EQ(a.measurements[k].R, b.measurements[k].R);  // bitwise
      EXPECT_EQ(a.measurements[k].t, b.measurements[k].t);
    }
    for (size_t i = 0; i < truth_a.size(); ++i) {
      EXPECT_EQ(truth_a[i].t, truth_b[i].t);
      EXPECT_EQ(truth_a[i].R, truth_b[i].R);
    }
    // Another seed: another walk and other noise.
    options.seed = 124;
    const PoseGraph c = Generate(options, &truth_c);
    EXPECT_NE(a.measurements[0].t, c.measurements[0].t);
    bool same_walk = true;
    for (size_t i = 0; i < truth_a.size(); ++i) {
      same_walk = same_walk && truth_a[i].t == truth_c[i].t;
    }
    EXPECT_FALSE(same_walk);
  }
}

TEST(GenerateCity, ExtentGrowsWithTheSquareRootOfN) {
  // The walk fills its L x L lattice, L ~ lattice_scale sqrt(n / levels):
  // the bounding box of the ground truth spans between L / 2 and L nodes per
  // horizontal axis, so quadrupling n about doubles it; the number of loop
  // closures per pose stays about constant (revisits at every size).
  for (int d : {2, 3}) {
    double previous_span = 0, previous_rate = 0;
    for (int n : {4000, 16000, 64000}) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " n=" << n);
      CityOptions options;
      options.dimension = d;
      options.num_poses = n;
      options.seed = 1;
      Poses truth;
      const PoseGraph graph = Generate(options, &truth);
      const long side = LatticeSide(options);
      double span = 0;
      for (int k = 0; k < 2; ++k) {
        double lo = 0, hi = 0;
        for (const Pose& pose : truth) {
          lo = std::min(lo, pose.t[k]);
          hi = std::max(hi, pose.t[k]);
        }
        const double nodes = (hi - lo) / options.spacing + 1;
        EXPECT_LE(nodes, side);
        EXPECT_GE(nodes, 0.5 * side);
        span = std::max(span, nodes);
      }
      const double rate =
          double(graph.measurements.size() - (n - 1)) / graph.num_poses;
      if (previous_span > 0) {
        EXPECT_NEAR(span / previous_span, 2.0, 0.3);
        EXPECT_NEAR(rate / previous_rate, 1.0, 0.25);
      }
      previous_span = span;
      previous_rate = rate;
    }
  }
}

TEST(GenerateCity, RejectsInvalidOptions) {
  auto expect_error = [](const CityOptions& options) {
    PoseGraph graph;
    Poses truth;
    std::string error;
    EXPECT_FALSE(GenerateCity(options, &graph, &truth, &error));
    EXPECT_FALSE(error.empty());
  };
  CityOptions o;
  o.dimension = 4;
  expect_error(o);
  for (int n : {-5, 0, 1, 10000001}) {
    o = CityOptions();
    o.num_poses = n;
    expect_error(o);
  }
  for (double p : {-0.1, 1.5, double(NAN)}) {
    o = CityOptions();
    o.loop_closure_probability = p;
    expect_error(o);
    o = CityOptions();
    o.turn_probability = p;
    expect_error(o);
  }
  for (double scale : {0.0, -1.0, 2.5, double(NAN), double(INFINITY)}) {
    o = CityOptions();
    o.lattice_scale = scale;
    expect_error(o);
  }
  for (int levels : {0, 101}) {
    o = CityOptions();
    o.dimension = 3;
    o.levels = levels;
    expect_error(o);
  }
  o = CityOptions();
  o.max_loop_closures_per_visit = -1;
  expect_error(o);
  o = CityOptions();
  o.kappa = 0;
  expect_error(o);
  o = CityOptions();
  o.tau = INFINITY;
  expect_error(o);
  o = CityOptions();
  o.spacing = -1;
  expect_error(o);
}

// F(x) of eq. (12) summed directly from the measurements (independent of
// EvaluateObjective and of the solver).
double DirectObjective(const PoseGraph& graph, const Poses& x) {
  double f = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    f += e.kappa * (x[e.j].R - x[e.i].R * e.R).squaredNorm() +
         e.tau * (x[e.j].t - x[e.i].t - x[e.i].R * e.t).squaredNorm();
  }
  return f;
}

TEST(GenerateCity, SESyncCertifiesASmallCity) {
  // Default noise. Checked independently of the solver's own certificate:
  // its objective equals a direct evaluation at the returned poses; it is no
  // worse than Ceres LM started at the ground truth (a local optimum cannot
  // beat the global one); and the dense certificate matrix S = Q - Lambda
  // at the returned rotations (Q built densely from the measurements by
  // test_util::DenseQ) has lambda_min(S) >= -tol F / (d n), which proves
  // F(x) within tol of the optimum (Rosen et al. 2019, Sec. 5.3).
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    CityOptions options;
    options.dimension = d;
    options.num_poses = d == 2 ? 300 : 200;
    options.seed = 2;
    Poses truth;
    const PoseGraph graph = Generate(options, &truth);
    ASSERT_GT(graph.measurements.size(), graph.num_poses + 20u);
    SolverSummary summary;
    const Poses x = Solve(graph, SolverOptions(), &summary);
    ASSERT_EQ(summary.status, SolverSummary::Status::kCertifiedOptimum)
        << summary.FullReport();
    const double f = DirectObjective(graph, x);
    EXPECT_NEAR(summary.objective, f, 1e-10 * f);
    EXPECT_LE(summary.lower_bound, f);
    EXPECT_LE(f, DirectObjective(graph, truth));

    CeresBaselineOptions ceres_options;
    ceres_options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
    ceres_options.function_tolerance = 1e-14;
    Poses local;
    CeresBaselineSummary ceres_summary;
    std::string error;
    ASSERT_TRUE(SolveWithCeres(graph, truth, ceres_options, &local,
                               &ceres_summary, &error))
        << error;
    EXPECT_LE(f, DirectObjective(graph, local) * (1 + 1e-8));

    const int n = graph.num_poses;
    const Eigen::MatrixXd Q = test_util::DenseQ(graph);
    const Eigen::MatrixXd R = test_util::StackRotations(x);
    const Eigen::MatrixXd QRR = Q * R.transpose() * R;
    Eigen::MatrixXd S = Q;
    for (int i = 0; i < n; ++i) {
      const Eigen::MatrixXd B = QRR.block(d * i, d * i, d, d);
      S.block(d * i, d * i, d, d) -= 0.5 * (B + B.transpose());
    }
    const double lambda_min = test_util::DenseMinEigenvalue(S);
    EXPECT_GE(lambda_min, -1e-6 * f / (d * n)) << summary.FullReport();
  }
}

TEST(GenerateCommand, WritesTheCity) {
  if (!test_util::ToolBuilt()) {
    GTEST_SKIP() << "the ceres_sesync tool is not built";
  }
  const std::string dir = std::string(CERES_SESYNC_BINARY_DIR);
  const std::string output = dir + "/city_generator_test_graph.g2o";
  const std::string truth_path = dir + "/city_generator_test_truth.g2o";
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    std::remove(output.c_str());
    std::remove(truth_path.c_str());
    // Flags not given take CityOptions' defaults (kappa, tau).
    ASSERT_EQ(test_util::RunTool("generate city --poses 400 --dimension " +
                                 std::to_string(d) +
                                 " --loop_closure_probability 0.6 --seed 9 "
                                 "--output " +
                                 output + " --ground_truth " + truth_path),
              0);
    CityOptions options;
    options.dimension = d;
    options.num_poses = 400;
    options.loop_closure_probability = 0.6;
    options.seed = 9;
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
      EXPECT_LT((a.R - b.R).norm(), 1e-12);
      EXPECT_LT((a.t - b.t).norm(), 1e-12);
      EXPECT_NEAR(a.kappa, b.kappa, 1e-12 * b.kappa);
      EXPECT_NEAR(a.tau, b.tau, 1e-12 * b.tau);
    }
    Poses file_truth;
    ASSERT_TRUE(ReadG2oPoses(truth_path, graph, &file_truth, &error)) << error;
    for (int i = 0; i < graph.num_poses; ++i) {
      const int v = static_cast<int>(graph.vertex_ids[i]);
      EXPECT_LT((file_truth[i].R - truth[v].R).norm(), 1e-12);
      EXPECT_LT((file_truth[i].t - truth[v].t).norm(), 1e-12);
    }
  }
  // Given flags override the defaults.
  std::remove(output.c_str());
  ASSERT_EQ(test_util::RunTool("generate city --poses 100 --kappa 7 --tau 3 "
                               "--vertices none --output " +
                               output),
            0);
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(ReadG2oFile(output, G2oReadOptions(), &graph, &error)) << error;
  EXPECT_EQ(graph.dimension, 2);
  EXPECT_TRUE(graph.initial_poses.empty());
  for (const RelativePoseMeasurement& e : graph.measurements) {
    EXPECT_NEAR(e.kappa, 7, 1e-12);
    EXPECT_NEAR(e.tau, 3, 1e-12);
  }

  // Usage errors exit with 2 and write nothing.
  std::remove(output.c_str());
  for (const std::string& args : std::vector<std::string>{
           "generate city --output " + output,  // no --poses
           "generate city --poses 1 --output " + output,
           "generate city --poses 100",  // no --output
           "generate city --poses 100 --dimension 4 --output " + output,
           "generate city --poses 100 --kappa -1 --output " + output,
           "generate city --poses 100 --loop_closure_probability 2 --output " +
               output,
           "generate city --poses 100 --side 5 --output " + output,
           "generate city --poses 100 --loop_closure_radius 2 --output " +
               output,
           "generate city extra --poses 100 --output " + output,
           "generate cube --poses 100 --output " + output,
           "generate town --poses 100 --output " + output,
       }) {
    EXPECT_EQ(test_util::RunTool(args), 2) << args;
  }
  EXPECT_FALSE(test_util::FileExists(output)) << "a failed run left " << output;
  std::remove(truth_path.c_str());
}

}  // namespace
}  // namespace ceres_sesync
