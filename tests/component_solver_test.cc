// Tests of the per-component solve (component_solver.h) and of the progress
// reports every solve gives (SolverOptions::progress).

#include "ceres_sesync/component_solver.h"

#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "Eigen/Core"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Status = SolverSummary::Status;
using test_util::RandomGraphOptions;
using testing::HasSubstr;

PoseGraph Random(int d, int n, uint64_t seed, bool noiseless = false) {
  RandomGraphOptions o;
  o.dimension = d;
  o.num_poses = n;
  o.num_loop_closures = n / 2;
  o.noiseless = noiseless;
  o.kappa = 50;
  o.tau = 20;
  o.seed = seed;
  return test_util::RandomPoseGraph(o, nullptr);
}

// Where the poses of each part went in the merged graph.
struct Merged {
  PoseGraph graph;
  std::vector<std::vector<int>> index;  // index[part][local pose]
};

// The parts as one disconnected graph, their poses and measurements
// interleaved (part p's pose k gets vertex id 1000 p + k), so that splitting
// has to undo a non-trivial permutation.
Merged Merge(const std::vector<PoseGraph>& parts) {
  Merged merged;
  merged.graph.dimension = parts[0].dimension;
  merged.index.resize(parts.size());
  for (int k = 0;; ++k) {
    bool any = false;
    for (size_t p = 0; p < parts.size(); ++p) {
      if (k >= parts[p].num_poses) continue;
      any = true;
      merged.index[p].push_back(merged.graph.AddVertex(1000 * p + k));
    }
    if (!any) break;
  }
  for (size_t e = 0;; ++e) {
    bool any = false;
    for (size_t p = 0; p < parts.size(); ++p) {
      if (e >= parts[p].measurements.size()) continue;
      any = true;
      RelativePoseMeasurement m = parts[p].measurements[e];
      m.i = merged.index[p][m.i];
      m.j = merged.index[p][m.j];
      merged.graph.measurements.push_back(std::move(m));
    }
    if (!any) break;
  }
  return merged;
}

TEST(ComponentSolver, EachComponentIsSolvedExactlyAsItsOwnGraph) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    const std::vector<PoseGraph> parts = {Random(d, 15, 1), Random(d, 9, 2)};
    const Merged merged = Merge(parts);
    std::string error;
    ASSERT_FALSE(ValidatePoseGraph(merged.graph, &error));
    EXPECT_THAT(error, HasSubstr("disconnected"));
    ValidationOptions disconnected;
    disconnected.require_connected = false;
    ASSERT_TRUE(ValidatePoseGraph(merged.graph, disconnected, &error)) << error;

    const SolverOptions options;
    ComponentsSummary summary;
    const Poses x = SolveByComponent(merged.graph, options, &summary);
    ASSERT_EQ(static_cast<int>(x.size()), merged.graph.num_poses);
    ASSERT_EQ(summary.components.size(), 2u);
    EXPECT_EQ(summary.status, Status::kCertifiedOptimum)
        << summary.FullReport();
    EXPECT_EQ(summary.StatusString(), "CERTIFIED_OPTIMUM");
    double objective = 0, lower_bound = 0;
    for (size_t p = 0; p < parts.size(); ++p) {
      SolverSummary alone;
      const Poses y = Solve(parts[p], options, &alone);
      const ComponentsSummary::Component& c = summary.components[p];
      EXPECT_EQ(c.poses, merged.index[p]);
      EXPECT_EQ(c.num_measurements,
                static_cast<int>(parts[p].measurements.size()));
      EXPECT_EQ(c.gauge_vertex_id, static_cast<int64_t>(1000 * p));
      // Same data in the same order: bitwise the same solve.
      EXPECT_EQ(c.summary.objective, alone.objective);
      EXPECT_EQ(c.summary.lower_bound, alone.lower_bound);
      EXPECT_EQ(c.summary.iterations, alone.iterations);
      for (int k = 0; k < parts[p].num_poses; ++k) {
        EXPECT_EQ(x[merged.index[p][k]].R, y[k].R);
        EXPECT_EQ(x[merged.index[p][k]].t, y[k].t);
      }
      objective += alone.objective;
      lower_bound += alone.lower_bound;
    }
    EXPECT_EQ(summary.objective, objective);
    EXPECT_EQ(summary.lower_bound, lower_bound);
    EXPECT_DOUBLE_EQ(summary.objective, EvaluateObjective(merged.graph, x));
    EXPECT_DOUBLE_EQ(summary.relative_suboptimality_bound,
                     (objective - lower_bound) / lower_bound);
    EXPECT_LE(summary.relative_suboptimality_bound,
              options.certification_max_relative_bound);
    const std::string report = summary.FullReport();
    EXPECT_THAT(report, HasSubstr("Connected components"));
    EXPECT_THAT(report, HasSubstr("CERTIFIED_OPTIMUM"));
  }
}

// A landmark graph (test_util::RandomLandmarkGraph) with priors or without.
PoseGraph RandomWithLandmarks(int d, int n, uint64_t seed, bool priors) {
  test_util::RandomLandmarkGraphOptions o;
  o.poses.dimension = d;
  o.poses.num_poses = n;
  o.poses.num_loop_closures = n / 3;
  o.poses.kappa = 50;
  o.poses.tau = 20;
  o.poses.seed = seed;
  o.num_landmarks = 6;
  o.observations_per_landmark = 3;
  if (priors) {
    o.num_position_priors = 2;
    o.num_pose_priors = 1;
  }
  return test_util::RandomLandmarkGraph(o, nullptr);
}

// Merge() with the landmarks (part p's landmark k gets id 1000 p + 500 + k),
// landmark measurements and priors interleaved too; lm_index[part][local
// landmark] is where each landmark went.
Merged MergeWithLandmarks(const std::vector<PoseGraph>& parts,
                          std::vector<std::vector<int>>* lm_index) {
  Merged merged = Merge(parts);
  lm_index->assign(parts.size(), {});
  PoseGraph& g = merged.graph;
  for (int k = 0;; ++k) {
    bool any = false;
    for (size_t p = 0; p < parts.size(); ++p) {
      if (k >= parts[p].num_landmarks) continue;
      any = true;
      (*lm_index)[p].push_back(g.AddLandmark(1000 * p + 500 + k));
    }
    if (!any) break;
  }
  for (size_t q = 0;; ++q) {
    bool any = false;
    for (size_t p = 0; p < parts.size(); ++p) {
      if (q < parts[p].landmark_measurements.size()) {
        any = true;
        LandmarkMeasurement o = parts[p].landmark_measurements[q];
        o.i = merged.index[p][o.i];
        o.l = (*lm_index)[p][o.l];
        g.landmark_measurements.push_back(std::move(o));
      }
      if (q < parts[p].priors.size()) {
        any = true;
        PosePrior prior = parts[p].priors[q];
        prior.i = merged.index[p][prior.i];
        g.priors.push_back(std::move(prior));
      }
    }
    if (!any) break;
  }
  return merged;
}

TEST(ComponentSolver, LandmarksAndPriorsAreSolvedWithTheirComponent) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    // A landmark map in the world frame, a landmark map in a gauge of its
    // own, and a plain pose graph.
    const std::vector<PoseGraph> parts = {
        RandomWithLandmarks(d, 12, 21, /*priors=*/true),
        RandomWithLandmarks(d, 9, 22, /*priors=*/false), Random(d, 7, 23)};
    ASSERT_FALSE(parts[0].priors.empty());
    ASSERT_GT(parts[1].num_landmarks, 0);
    std::vector<std::vector<int>> lm_index;
    const Merged merged = MergeWithLandmarks(parts, &lm_index);
    const PoseGraph& g = merged.graph;
    ASSERT_EQ(ConnectedComponents(g, nullptr), 3);

    const std::vector<PoseGraphComponent> split = SplitIntoComponents(g);
    ASSERT_EQ(split.size(), 3u);
    const SolverOptions options;
    ComponentsSummary summary;
    Solution x;
    SolveByComponent(g, options, &x, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    ASSERT_EQ(static_cast<int>(x.poses.size()), g.num_poses);
    ASSERT_EQ(static_cast<int>(x.landmarks.size()), g.num_landmarks);
    EXPECT_EQ(summary.num_landmarks, g.num_landmarks);
    EXPECT_EQ(summary.num_priors, static_cast<int>(g.priors.size()));
    double objective = 0;
    for (size_t p = 0; p < parts.size(); ++p) {
      SCOPED_TRACE(p);
      const PoseGraph& part = parts[p];
      // The split gives back the part: its terms in order, re-indexed.
      const PoseGraph& back = split[p].graph;
      ASSERT_EQ(back.num_landmarks, part.num_landmarks);
      ASSERT_EQ(back.landmark_measurements.size(),
                part.landmark_measurements.size());
      ASSERT_EQ(back.priors.size(), part.priors.size());
      EXPECT_EQ(split[p].landmarks, lm_index[p]);
      for (int k = 0; k < part.num_landmarks; ++k) {
        EXPECT_EQ(back.landmark_ids[k], g.landmark_ids[lm_index[p][k]]);
      }
      for (size_t q = 0; q < part.landmark_measurements.size(); ++q) {
        const LandmarkMeasurement& a = part.landmark_measurements[q];
        const LandmarkMeasurement& b = back.landmark_measurements[q];
        EXPECT_EQ(b.i, a.i);
        EXPECT_EQ(b.l, a.l);
        EXPECT_EQ(b.z, a.z);
        EXPECT_EQ(g.landmark_measurements[split[p].landmark_measurements[q]].z,
                  a.z);
      }
      for (size_t q = 0; q < part.priors.size(); ++q) {
        EXPECT_EQ(back.priors[q].i, part.priors[q].i);
        EXPECT_EQ(back.priors[q].t, part.priors[q].t);
        EXPECT_EQ(g.priors[split[p].priors[q]].t, part.priors[q].t);
      }

      // Same data in the same order: bitwise the same solve as the part
      // alone, poses and landmarks.
      SolverSummary alone;
      Solution y;
      Solve(part, options, &y, &alone);
      ASSERT_TRUE(alone.certified()) << alone.FullReport();
      const ComponentsSummary::Component& c = summary.components[p];
      EXPECT_EQ(c.poses, merged.index[p]);
      EXPECT_EQ(c.landmarks, lm_index[p]);
      EXPECT_EQ(c.num_landmark_measurements,
                static_cast<int>(part.landmark_measurements.size()));
      EXPECT_EQ(c.num_priors, static_cast<int>(part.priors.size()));
      EXPECT_EQ(c.gauge_vertex_id,
                part.priors.empty() ? static_cast<int64_t>(1000 * p) : -1);
      EXPECT_EQ(c.summary.objective, alone.objective);
      EXPECT_EQ(c.summary.lower_bound, alone.lower_bound);
      for (int k = 0; k < part.num_poses; ++k) {
        EXPECT_EQ(x.poses[merged.index[p][k]].R, y.poses[k].R);
        EXPECT_EQ(x.poses[merged.index[p][k]].t, y.poses[k].t);
      }
      for (int k = 0; k < part.num_landmarks; ++k) {
        EXPECT_EQ(x.landmarks[lm_index[p][k]], y.landmarks[k]);
      }
      objective += alone.objective;
    }
    EXPECT_EQ(summary.objective, objective);
    // Every term of the whole graph is counted once.
    EXPECT_NEAR(summary.objective, EvaluateObjective(g, x.poses, x.landmarks),
                1e-12 * summary.objective);
    const std::string report = summary.FullReport();
    EXPECT_THAT(report, HasSubstr("Landmark measurements"));
    EXPECT_THAT(report, HasSubstr("world"));
    // The poses-only overload returns the same poses.
    ComponentsSummary again;
    const Poses z = SolveByComponent(g, options, &again);
    ASSERT_EQ(z.size(), x.poses.size());
    for (size_t k = 0; k < z.size(); ++k) EXPECT_EQ(z[k].t, x.poses[k].t);
  }
}

TEST(ComponentSolver, PriorsJoinTheirComponentsInTheWorldFrame) {
  // Two landmark maps, each with priors: the priors tie both to the world
  // frame, so they are one component, solved as one graph.
  const std::vector<PoseGraph> parts = {
      RandomWithLandmarks(2, 10, 24, /*priors=*/true),
      RandomWithLandmarks(2, 8, 25, /*priors=*/true)};
  std::vector<std::vector<int>> lm_index;
  const Merged merged = MergeWithLandmarks(parts, &lm_index);
  std::string error;
  ASSERT_TRUE(ValidatePoseGraph(merged.graph, &error)) << error;
  ComponentsSummary summary;
  Solution x;
  SolveByComponent(merged.graph, SolverOptions(), &x, &summary);
  ASSERT_EQ(summary.components.size(), 1u);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  SolverSummary whole;
  Solution y;
  Solve(merged.graph, SolverOptions(), &y, &whole);
  EXPECT_EQ(summary.objective, whole.objective);
  EXPECT_EQ(x.landmarks, y.landmarks);
  EXPECT_EQ(summary.components[0].gauge_vertex_id, -1);
}

TEST(ComponentSolver, EachComponentHasItsOwnGauge) {
  const std::vector<PoseGraph> parts = {Random(3, 8, 3), Random(3, 6, 4),
                                        Random(3, 1, 5)};
  ASSERT_TRUE(parts[2].measurements.empty());  // An isolated vertex.
  Merged merged = Merge(parts);
  merged.graph.fixed_pose = merged.index[1][4];  // FIX in the second part.
  ComponentsSummary summary;
  const Poses x = SolveByComponent(merged.graph, SolverOptions(), &summary);
  ASSERT_EQ(summary.components.size(), 3u) << summary.FullReport();
  EXPECT_TRUE(summary.certified()) << summary.FullReport();
  EXPECT_EQ(summary.components[0].gauge_vertex_id, 0);
  EXPECT_EQ(summary.components[1].gauge_vertex_id, 1004);
  EXPECT_EQ(summary.components[2].gauge_vertex_id, 2000);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  for (int gauge :
       {merged.index[0][0], merged.index[1][4], merged.index[2][0]}) {
    EXPECT_LT((x[gauge].R - I).norm(), 1e-12) << gauge;
    EXPECT_LT(x[gauge].t.norm(), 1e-12) << gauge;
  }
  // The FIX pose is not the first pose of its component.
  EXPECT_GT((x[merged.index[1][0]].R - I).norm(), 1e-3);

  // With VERTEX poses, each gauge pose keeps its initial value.
  std::mt19937_64 rng(9);
  merged.graph.initial_poses =
      test_util::RandomPoses(3, merged.graph.num_poses, 2, &rng);
  const Poses z = SolveByComponent(merged.graph, SolverOptions(), &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  for (int gauge :
       {merged.index[0][0], merged.index[1][4], merged.index[2][0]}) {
    EXPECT_LT((z[gauge].R - merged.graph.initial_poses[gauge].R).norm(), 1e-12);
    EXPECT_LT((z[gauge].t - merged.graph.initial_poses[gauge].t).norm(), 1e-12);
  }
}

TEST(ComponentSolver, StatusIsTheFirstComponentNotCertified) {
  // Tolerance 0: only the noiseless component (F = 0) can be certified.
  SolverOptions options;
  options.certification_max_relative_bound = 0;
  options.max_rank = 4;
  const Merged merged =
      Merge({Random(2, 10, 6, /*noiseless=*/true), Random(2, 12, 7)});
  ComponentsSummary summary;
  const Poses x = SolveByComponent(merged.graph, options, &summary);
  ASSERT_EQ(summary.components.size(), 2u);
  EXPECT_TRUE(summary.components[0].summary.certified());
  EXPECT_FALSE(summary.components[1].summary.certified());
  EXPECT_FALSE(summary.certified());
  EXPECT_EQ(summary.status, summary.components[1].summary.status);
  EXPECT_EQ(summary.StatusString(),
            summary.components[1].summary.StatusString());
  EXPECT_EQ(static_cast<int>(x.size()), merged.graph.num_poses);
  EXPECT_GT(summary.relative_suboptimality_bound, 0);
}

TEST(ComponentSolver, InvalidGraphIsRejectedWithTheGlobalIndex) {
  Merged merged = Merge({Random(2, 5, 8), Random(2, 5, 9)});
  merged.graph.measurements[5].kappa = std::nan("");
  ComponentsSummary summary;
  const Poses x = SolveByComponent(merged.graph, SolverOptions(), &summary);
  EXPECT_TRUE(x.empty());
  EXPECT_EQ(summary.status, Status::kInvalidInput);
  EXPECT_EQ(summary.StatusString(), "INVALID_INPUT");
  EXPECT_THAT(summary.message, HasSubstr("measurement 5 "));
  EXPECT_TRUE(summary.components.empty());
  EXPECT_THAT(summary.BriefReport(), HasSubstr("INVALID_INPUT"));
}

TEST(ComponentSolver, ReaderAcceptsDisconnectedFilesOnlyWhenAsked) {
  const std::string text =
      "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
      "EDGE_SE2 5 6 1 0 0.5 1 0 0 1 0 1\n"
      "EDGE_SE2 6 7 1 0 0 1 0 0 1 0 1\n";
  PoseGraph graph;
  std::string error;
  std::istringstream in(text);
  EXPECT_FALSE(ReadG2o(in, "t.g2o", G2oReadOptions(), &graph, &error));
  EXPECT_THAT(error, HasSubstr("t.g2o:2: measurement graph is disconnected"));
  G2oReadOptions options;
  options.allow_disconnected = true;
  std::istringstream again(text);
  ASSERT_TRUE(ReadG2o(again, "t.g2o", options, &graph, &error)) << error;
  EXPECT_EQ(ConnectedComponents(graph, nullptr), 2);
  const std::vector<PoseGraphComponent> parts = SplitIntoComponents(graph);
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].poses, (std::vector<int>{0, 1}));
  EXPECT_EQ(parts[1].poses, (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(parts[1].measurements, (std::vector<int>{1, 2}));
  EXPECT_EQ(parts[1].graph.vertex_ids, (std::vector<int64_t>{5, 6, 7}));
  EXPECT_EQ(parts[1].graph.measurements[0].i, 0);
  EXPECT_EQ(parts[1].graph.measurements[1].j, 2);
  EXPECT_TRUE(ValidatePoseGraph(parts[1].graph, &error)) << error;
}

// ---- progress reports ------------------------------------------------------

struct Report {
  std::string stage;
  SolverProgress progress;
};

TEST(SolverProgress, ReportsEveryStageInOrder) {
  const PoseGraph graph = Random(3, 30, 10);
  std::vector<Report> reports;
  SolverOptions options;
  options.progress = [&](const SolverProgress& p) {
    reports.push_back({p.stage, p});
  };
  SolverSummary summary;
  Solve(graph, options, &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  ASSERT_GE(reports.size(), 6u);
  EXPECT_EQ(reports[0].stage, "data");
  EXPECT_EQ(reports[1].stage, "initialize");
  EXPECT_EQ(reports.back().stage, "done");
  EXPECT_EQ(reports.back().progress.objective, summary.objective);
  EXPECT_EQ(reports.back().progress.rank, summary.final_rank);
  EXPECT_EQ(reports[reports.size() - 2].stage, "round");
  double elapsed = 0;
  size_t level = 0;
  int last_iteration = 0;
  for (size_t k = 2; k + 2 < reports.size(); ++k) {
    const SolverProgress& p = reports[k].progress;
    EXPECT_GE(p.elapsed_s, elapsed);
    elapsed = p.elapsed_s;
    EXPECT_EQ(p.component, 0);
    EXPECT_EQ(p.num_components, 1);
    ASSERT_LT(level, summary.levels.size());
    const SolverSummary::Level& l = summary.levels[level];
    EXPECT_EQ(p.rank, l.rank);
    if (reports[k].stage == "optimize") {
      EXPECT_GE(p.iteration, last_iteration);
      last_iteration = p.iteration;
    } else {
      // The level ends with its verification: the level's F(Y), and the
      // last iteration reported is the level's iteration count.
      ASSERT_EQ(reports[k].stage, "verify");
      EXPECT_EQ(p.objective, l.sdp_value);
      EXPECT_EQ(p.iteration, l.iterations);
      EXPECT_EQ(last_iteration, l.iterations);
      ++level;
      last_iteration = 0;
    }
  }
  EXPECT_EQ(level, summary.levels.size());
}

TEST(SolverProgress, ComponentsAreNamedInTheReports) {
  const Merged merged = Merge({Random(2, 6, 11), Random(2, 7, 12)});
  std::set<std::pair<int, int>> seen;
  int done = 0;
  SolverOptions options;
  options.progress = [&](const SolverProgress& p) {
    seen.insert({p.component, p.num_components});
    done += std::string(p.stage) == "done";
  };
  ComponentsSummary summary;
  SolveByComponent(merged.graph, options, &summary);
  EXPECT_EQ(seen, (std::set<std::pair<int, int>>{{0, 2}, {1, 2}}));
  EXPECT_EQ(done, 2);
}

}  // namespace
}  // namespace ceres_sesync
