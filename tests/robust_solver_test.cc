// The outlier-robust solve (robust_solver.h): exact recovery on noiseless
// data with wrong loop closures (and with wrong landmark associations and
// false position fixes), equality with Solve() without outliers,
// binary weights, determinism, the disconnected-inlier status; the
// chi-square threshold; the Ceres robust-loss baselines on the same terms.

#include "ceres_sesync/robust_solver.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "Eigen/Geometry"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/internal/chi_square.h"
#include "ceres_sesync/internal/staircase.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/outlier_generator.h"
#include "ceres_sesync/sesync_solver.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using test_util::RandomGraphOptions;

PoseGraph ChainGraph(int d, int n, int loops, bool noiseless, uint64_t seed,
                     Poses* truth) {
  RandomGraphOptions o;
  o.dimension = d;
  o.num_poses = n;
  o.num_loop_closures = loops;
  o.chain = true;
  o.noiseless = noiseless;
  o.kappa = 100;
  o.tau = 100;
  o.seed = seed;
  return test_util::RandomPoseGraph(o, truth);
}

RobustSolverOptions Options() {
  RobustSolverOptions options;
  options.solver_options.num_threads = 1;
  return options;
}

double Sum(const RobustSolverSummary& s) {
  double f = 0;
  for (const RobustSolverSummary::Edge& e : s.edges) f += e.cost;
  return f;
}

TEST(ChiSquare, QuantilesMatchTables) {
  // Abramowitz & Stegun, Table 26.8.
  EXPECT_NEAR(internal::ChiSquareQuantile(0.95, 1), 3.841459, 1e-6);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.99, 2), 9.210340, 1e-6);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.999, 3), 16.266236, 1e-6);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.99, 6), 16.811894, 1e-6);
  EXPECT_NEAR(internal::ChiSquareQuantile(0.5, 4), 3.356694, 1e-6);
  for (int k = 1; k <= 7; ++k) {
    for (double p : {1e-6, 0.3, 0.999999}) {
      EXPECT_NEAR(internal::ChiSquareCdf(internal::ChiSquareQuantile(p, k), k),
                  p, 1e-12);
    }
  }
  EXPECT_TRUE(std::isnan(internal::ChiSquareQuantile(1.0, 3)));
  RobustSolverOptions o;
  EXPECT_NEAR(InlierThreshold(o, 2), 30.664850, 1e-5);  // chi^2(3)
  EXPECT_NEAR(InlierThreshold(o, 3), 38.258336, 1e-5);  // chi^2(6)
  o.inlier_threshold = 7;
  EXPECT_EQ(InlierThreshold(o, 3), 7);
}

// Noiseless measurements plus random wrong loop closures: the ground truth
// exactly, every outlier flagged and nothing else, weights binary, the
// inlier problem certified (F = 0).
TEST(RobustSolver, NoiselessDataWithOutliersRecoversGroundTruthExactly) {
  for (int d : {2, 3}) {
    for (double fraction : {0.3, 0.6}) {
      Poses truth;
      const PoseGraph clean = ChainGraph(d, 40, 40, true, 7 + d, &truth);
      OutlierOptions o;
      o.fraction = fraction;
      o.seed = 3;
      PoseGraph corrupted;
      std::vector<int> added;
      ASSERT_TRUE(AddOutliers(clean, o, &corrupted, &added, nullptr));
      ASSERT_GT(added.size(), 10u);
      RobustSolverSummary s;
      const Poses poses = SolveRobust(corrupted, Options(), &s);
      ASSERT_TRUE(s.certified()) << s.FullReport();
      EXPECT_EQ(s.outlier_edges, added) << s.FullReport();
      EXPECT_EQ(s.num_outliers, static_cast<int>(added.size()));
      EXPECT_TRUE(s.weights_binary);
      EXPECT_LT(test_util::GaugeInvariantPoseDistance(poses, truth), 1e-6);
      EXPECT_LT(s.inlier_summary.objective, 1e-12);
      EXPECT_EQ(s.num_rejected_within_threshold, 0);
      EXPECT_EQ(s.num_accepted_beyond_threshold, 0);
      EXPECT_GT(s.iterations, 0);
      for (size_t k = 0; k < s.edges.size(); ++k) {
        EXPECT_EQ(s.edges[k].known_inlier,
                  IsOdometry(corrupted.measurements[k]));
        if (s.edges[k].known_inlier) {
          EXPECT_EQ(s.edges[k].weight, 1);
        }
      }
    }
  }
}

// Without outliers the robust solve is Solve(): same poses (bitwise), same
// certificate, nothing rejected, no GNC step.
TEST(RobustSolver, WithoutOutliersEqualsSolve) {
  CubeOptions cube;
  cube.side = 4;
  cube.seed = 5;
  PoseGraph cube_graph;
  ASSERT_TRUE(GenerateCube(cube, &cube_graph, nullptr, nullptr));
  for (const PoseGraph& graph :
       {cube_graph, ChainGraph(2, 50, 30, false, 2, nullptr)}) {
    RobustSolverOptions options = Options();
    SolverSummary plain;
    const Poses expected = Solve(graph, options.solver_options, &plain);
    ASSERT_TRUE(plain.certified());
    RobustSolverSummary s;
    const Poses poses = SolveRobust(graph, options, &s);
    EXPECT_EQ(s.status, RobustSolverSummary::Status::kConverged);
    EXPECT_TRUE(s.certified());
    EXPECT_EQ(s.num_outliers, 0);
    EXPECT_EQ(s.iterations, 0);
    EXPECT_EQ(s.inlier_summary.objective, plain.objective);
    EXPECT_EQ(s.inlier_summary.lower_bound, plain.lower_bound);
    ASSERT_EQ(poses.size(), expected.size());
    for (size_t i = 0; i < poses.size(); ++i) {
      EXPECT_EQ(poses[i].R, expected[i].R);
      EXPECT_EQ(poses[i].t, expected[i].t);
    }
    // The verdicts' costs are the terms of F.
    EXPECT_NEAR(Sum(s), plain.objective, 1e-9 * plain.objective);
  }
}

// A noisy 60-pose chain with 60 loop closures plus 40% random wrong ones.
bool NoisyChainWithOutliers(int d, PoseGraph* corrupted,
                            std::vector<int>* added) {
  const PoseGraph clean = ChainGraph(d, 60, 60, false, 11, nullptr);
  OutlierOptions o;
  o.fraction = 0.4;
  o.seed = 1;
  return AddOutliers(clean, o, corrupted, added, nullptr);
}

// Noisy data with outliers: the weights end binary and the verdicts follow
// them; the outliers are exactly the added measurements.
TEST(RobustSolver, WeightsConvergeToZeroOrOne) {
  for (int d : {2, 3}) {
    PoseGraph corrupted;
    std::vector<int> added;
    ASSERT_TRUE(NoisyChainWithOutliers(d, &corrupted, &added));
    RobustSolverSummary s;
    SolveRobust(corrupted, Options(), &s);
    ASSERT_EQ(s.status, RobustSolverSummary::Status::kConverged)
        << s.FullReport();
    EXPECT_TRUE(s.weights_binary);
    for (const RobustSolverSummary::Edge& e : s.edges) {
      EXPECT_LE(std::min(e.weight, 1 - e.weight), 1e-4);
      if (s.consistency_rounds == 0) {
        EXPECT_EQ(e.inlier, e.weight > 0.5);
      }
    }
    EXPECT_EQ(s.outlier_edges, added);
    EXPECT_TRUE(s.certified()) << s.FullReport();
    ASSERT_FALSE(s.runs.empty());
    ASSERT_GE(s.selected_run, 0);
    for (const RobustSolverSummary::Run& r : s.runs) {
      EXPECT_GE(r.tls_cost, s.runs[s.selected_run].tls_cost);
    }
    // The selected run's time after its GNC steps (the inlier problem was
    // solved: > 0) is part of that run's, which is part of all runs'.
    EXPECT_GT(s.inlier_time_s, 0);
    EXPECT_LE(s.inlier_time_s, s.runs[s.selected_run].time_s);
    EXPECT_LE(s.gnc_time_s, s.total_time_s);
    double runs = 0;
    for (const RobustSolverSummary::Run& r : s.runs) runs += r.time_s;
    EXPECT_LE(runs, s.gnc_time_s);
  }
}

// GNC's steps stop their local searches early (gnc_relative_gradient_
// tolerance) and prove in double; the reported inlier problem is still
// solved with the caller's options, also when the last GNC step already had
// binary weights and the caller proves in double (that step's problem is
// then the inlier problem itself, solved loosely): its optimum is Solve()'s on
// the accepted measurements, to the caller's tolerance (relative 1e-6 on the
// preconditioned gradient: F within ~1e-12 F of the optimum; 1e-3 leaves ~1e-6
// F).
TEST(RobustSolver, InlierProblemIsSolvedWithTheCallersOptions) {
  for (int d : {2, 3}) {
    PoseGraph corrupted;
    ASSERT_TRUE(NoisyChainWithOutliers(d, &corrupted, nullptr));
    RobustSolverOptions options = Options();
    options.solver_options.proof_arithmetic =
        SolverOptions::ProofArithmetic::kDouble;
    // GNC runs until the weights are exactly 0 or 1 (then its last step
    // solved the inlier problem already, loosely), and nothing solves it
    // after GNC but the final solve under test.
    options.weight_tolerance = 0;
    options.relative_cost_tolerance = 0;
    options.max_consistency_rounds = 0;
    options.max_readmission_trials = 0;
    // GNC steps far looser than the default 1e-3 (the difference would
    // hide in F's last digits, RTR converging superlinearly).
    options.gnc_relative_gradient_tolerance = 0.3;
    RobustSolverSummary s;
    SolveRobust(corrupted, options, &s);
    ASSERT_TRUE(s.certified()) << s.FullReport();
    ASSERT_TRUE(s.weights_binary);
    PoseGraph accepted = corrupted;
    accepted.measurements.clear();
    for (size_t k = 0; k < s.edges.size(); ++k) {
      if (s.edges[k].inlier) {
        accepted.measurements.push_back(corrupted.measurements[k]);
      }
    }
    SolverSummary plain;
    Solve(accepted, options.solver_options, &plain);
    ASSERT_TRUE(plain.certified());
    EXPECT_NEAR(s.inlier_summary.objective, plain.objective,
                1e-10 * plain.objective)
        << "d = " << d;
  }
}

// The GNC steps' staircase climbs at most to gnc_max_rank and skips the
// certificate test there (GNC uses only the step's poses; a test at the top
// rank has nothing to escape to). The final inlier problem keeps the
// caller's ranks and is certified as before.
TEST(RobustSolver, GncStepsStopAtGncMaxRankWithoutTheTopCertificateTest) {
  for (int d : {2, 3}) {
    PoseGraph corrupted;
    std::vector<int> added;
    ASSERT_TRUE(NoisyChainWithOutliers(d, &corrupted, &added));
    const int r0 = d + 2;
    // Capped at r0: every step is one level at r0 with no certificate test.
    RobustSolverOptions options = Options();
    options.gnc_max_rank = r0;
    RobustSolverSummary s;
    SolveRobust(corrupted, options, &s);
    ASSERT_EQ(s.status, RobustSolverSummary::Status::kConverged)
        << s.FullReport();
    ASSERT_GT(s.history.size(), 0u);
    for (const RobustSolverSummary::Iteration& step : s.history) {
      EXPECT_EQ(step.rank, r0);
      EXPECT_EQ(step.status, SolverSummary::Status::kMaxRankReached);
      EXPECT_EQ(step.verification_time_s, 0.0);
    }
    EXPECT_TRUE(s.certified()) << s.FullReport();
    EXPECT_EQ(s.outlier_edges, added) << s.FullReport();
    // Default: at most r0 + 2.
    SolveRobust(corrupted, Options(), &s);
    for (const RobustSolverSummary::Iteration& step : s.history) {
      EXPECT_LE(step.rank, r0 + 2);
    }
    EXPECT_EQ(s.outlier_edges, added) << s.FullReport();
  }
}

// gnc_relative_decrease_tolerance (its default) ends the GNC steps' local
// searches earlier than the caller's 1e-12 and touches nothing after GNC:
// the verdicts and the certified inlier optimum are those of the tight
// steps. (With the Newton preconditioner at rank d, the 2D default, the
// tight steps take 1-5 iterations each on this chain and the loose ones lead
// GNC through more steps, 15 -> 28, so the comparison is made without it;
// on intel + 10-50% outliers the default still saves a third of the time
// with it.)
TEST(RobustSolver, GncStepsStopAtTheirRelativeDecreaseTolerance) {
  for (int d : {2, 3}) {
    PoseGraph corrupted;
    std::vector<int> added;
    ASSERT_TRUE(NoisyChainWithOutliers(d, &corrupted, &added));
    auto steps_iterations = [](const RobustSolverSummary& s) {
      int iterations = 0;
      for (const RobustSolverSummary::Iteration& step : s.history) {
        iterations += step.solver_iterations;
      }
      return iterations;
    };
    RobustSolverOptions options = Options();
    options.solver_options.newton_at_rank_d = false;
    options.gnc_relative_decrease_tolerance = 0;  // The caller's 1e-12.
    RobustSolverSummary tight;
    SolveRobust(corrupted, options, &tight);
    options.gnc_relative_decrease_tolerance =
        RobustSolverOptions().gnc_relative_decrease_tolerance;
    RobustSolverSummary loose;
    SolveRobust(corrupted, options, &loose);
    for (const RobustSolverSummary* s : {&tight, &loose}) {
      ASSERT_EQ(s->status, RobustSolverSummary::Status::kConverged)
          << s->FullReport();
      EXPECT_EQ(s->outlier_edges, added) << s->FullReport();
      EXPECT_TRUE(s->certified()) << s->FullReport();
    }
    EXPECT_LT(steps_iterations(loose), steps_iterations(tight)) << "d = " << d;
    EXPECT_NEAR(loose.inlier_summary.objective, tight.inlier_summary.objective,
                1e-10 * tight.inlier_summary.objective)
        << "d = " << d;
  }
}

// max_time_s limits the whole robust solve. Out of time during GNC: status
// kTimeLimit, not certified, the poses and verdicts of where it stopped;
// with time to spare: the result of the unlimited solve. Also with two
// threads (the GNC runs at once).
TEST(RobustSolver, TimeLimitHoldsForTheWholeSolve) {
  for (const auto& [d, threads] :
       {std::pair{2, 1}, std::pair{3, 1}, std::pair{2, 2}, std::pair{3, 2}}) {
    SCOPED_TRACE("d = " + std::to_string(d) +
                 ", threads = " + std::to_string(threads));
    PoseGraph corrupted;
    std::vector<int> added;
    ASSERT_TRUE(NoisyChainWithOutliers(d, &corrupted, &added));
    RobustSolverSummary unlimited;
    const Poses full = SolveRobust(corrupted, Options(), &unlimited);
    ASSERT_TRUE(unlimited.certified()) << unlimited.FullReport();

    RobustSolverOptions options = Options();
    options.solver_options.num_threads = threads;
    options.max_time_s = 1e-4;
    RobustSolverSummary s;
    const auto start = std::chrono::steady_clock::now();
    const Poses poses = SolveRobust(corrupted, options, &s);
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
            .count();
    EXPECT_EQ(s.status, RobustSolverSummary::Status::kTimeLimit)
        << s.FullReport();
    EXPECT_FALSE(s.certified());
    // Far below the unlimited solve's time, or any solve's per-solve limit
    // (none here): each solve got only what was left.
    EXPECT_LT(elapsed, 0.5 * unlimited.total_time_s + 0.05);
    EXPECT_EQ(static_cast<int>(poses.size()), corrupted.num_poses);
    ASSERT_EQ(s.edges.size(), corrupted.measurements.size());
    EXPECT_EQ(s.num_inliers + s.num_outliers,
              static_cast<int>(corrupted.measurements.size()));
    EXPECT_THAT(s.FullReport(), testing::HasSubstr("TIME_LIMIT"));
    // No inlier problem was solved: its summary proves nothing.
    EXPECT_EQ(s.inlier_summary.status, SolverSummary::Status::kTimeLimit);
    EXPECT_FALSE(s.inlier_summary.certified());
    EXPECT_TRUE(std::isinf(s.inlier_summary.relative_suboptimality_bound));
    EXPECT_EQ(s.inlier_summary.num_measurements, s.num_inliers);

    options.max_time_s = 1000;
    SolveRobust(corrupted, options, &s);
    EXPECT_EQ(s.status, unlimited.status);
    EXPECT_TRUE(s.certified());
    EXPECT_EQ(s.outlier_edges, unlimited.outlier_edges);
    EXPECT_TRUE(s.message.empty()) << s.message;

    options.max_time_s = -1;
    SolveRobust(corrupted, options, &s);
    EXPECT_EQ(s.status, RobustSolverSummary::Status::kInvalidInput);
  }
}

// Staircase::Run without the test at max_rank: the level is optimized as
// usual (the same factor as with the test) but neither factorized nor
// bounded; with the test, the same point is certified.
TEST(RobustSolver, StaircaseCanSkipTheCertificateTestAtMaxRank) {
  for (int d : {2, 3}) {
    const PoseGraph graph = ChainGraph(d, 30, 20, false, 5, nullptr);
    SolverOptions options;
    options.num_threads = 1;
    options.max_rank = d + 2;
    SolverSummary skipped, tested;
    internal::Staircase a(graph, options, &skipped,
                          internal::Staircase::Clock::now());
    internal::Staircase b(graph, options, &tested,
                          internal::Staircase::Clock::now());
    ASSERT_TRUE(a.ok() && b.ok());
    Eigen::MatrixXd Ya, Yb;
    ASSERT_TRUE(a.Initialize(nullptr, &Ya));
    ASSERT_TRUE(b.Initialize(nullptr, &Yb));
    a.Run(&Ya, /*verify_at_max_rank=*/false);
    b.Run(&Yb);
    EXPECT_EQ(skipped.status, SolverSummary::Status::kMaxRankReached);
    ASSERT_EQ(skipped.levels.size(), 1u);
    EXPECT_EQ(skipped.levels[0].factorizations, 0);
    EXPECT_EQ(skipped.factorizations + skipped.extended_factorizations, 0);
    EXPECT_FALSE(skipped.levels[0].certified);
    EXPECT_TRUE(std::isinf(skipped.levels[0].eta));
    EXPECT_EQ(skipped.verification_time_s, 0.0);
    EXPECT_FALSE(a.verification().certified);
    EXPECT_EQ(tested.status, SolverSummary::Status::kCertifiedOptimum);
    EXPECT_GT(tested.factorizations + tested.extended_factorizations, 0);
    EXPECT_EQ(Ya, Yb);
  }
}

// The same for a top level entered by an escape: no certificate test
// during its optimization either (SolverOptions::
// test_certificate_after_escape), and the same factor. Rank d + 1 from a
// random start, then d + 2; the seed is the first of 40 whose escape
// level tests its certificate on the way when allowed to.
TEST(RobustSolver, StaircaseSkipsTheTestsDuringATopLevelEnteredByAnEscape) {
  for (int d : {2, 3}) {
    RandomGraphOptions g;
    g.dimension = d;
    // (Noise at which rank d + 1 from a random start often stalls.)
    g.num_poses = 60;
    g.num_loop_closures = 60;
    g.chain = true;
    g.noiseless = false;
    g.kappa = d == 2 ? 1 : 2;
    g.tau = 10;
    g.seed = 9;
    const PoseGraph graph = test_util::RandomPoseGraph(g, nullptr);
    SolverOptions options;
    options.num_threads = 1;
    options.initialization = SolverOptions::Initialization::kRandom;
    options.initial_rank = d + 1;
    options.max_rank = d + 2;
    bool found = false;
    for (uint64_t seed = 0; seed < 40 && !found; ++seed) {
      options.seed = seed;
      SolverSummary tested, skipped;
      internal::Staircase b(graph, options, &tested,
                            internal::Staircase::Clock::now());
      ASSERT_TRUE(b.ok());
      Eigen::MatrixXd Yb;
      ASSERT_TRUE(b.Initialize(nullptr, &Yb));
      b.Run(&Yb);
      if (tested.levels.size() != 2 ||
          tested.levels[1].certificate_tests == 0) {
        continue;
      }
      found = true;
      internal::Staircase a(graph, options, &skipped,
                            internal::Staircase::Clock::now());
      ASSERT_TRUE(a.ok());
      Eigen::MatrixXd Ya;
      ASSERT_TRUE(a.Initialize(nullptr, &Ya));
      a.Run(&Ya, /*verify_at_max_rank=*/false);
      ASSERT_EQ(skipped.levels.size(), 2u) << "seed " << seed;
      EXPECT_EQ(skipped.levels[0].factorizations,
                tested.levels[0].factorizations);
      EXPECT_EQ(skipped.levels[1].certificate_tests, 0);
      EXPECT_EQ(skipped.levels[1].factorizations +
                    skipped.levels[1].extended_factorizations,
                0);
      EXPECT_EQ(skipped.status, SolverSummary::Status::kMaxRankReached);
      // Without the tests the level runs to its gradient tolerance; a
      // passed test may have stopped it earlier, at a point as good.
      if (!tested.levels[1].certificate_test_passed) {
        EXPECT_EQ(Ya, Yb) << "seed " << seed;
      }
    }
    EXPECT_TRUE(found) << "d = " << d;
  }
}

// A side^3 cube (3 x 3 x 3 by default) at the paper's noise (kappa 16.67,
// tau 75) plus random wrong closures at `fraction` (30% by default; cube
// and outlier seed `seed`).
bool SmallNoisyCubeWithOutliers(uint64_t seed, PoseGraph* corrupted,
                                std::vector<int>* added, int side = 3,
                                double fraction = 0.3) {
  CubeOptions cube;
  cube.side = side;
  cube.kappa = 16.67;
  cube.tau = 75;
  cube.seed = seed;
  PoseGraph clean;
  if (!GenerateCube(cube, &clean, nullptr, nullptr)) return false;
  OutlierOptions o;
  o.fraction = fraction;
  o.seed = seed;
  return AddOutliers(clean, o, corrupted, added, nullptr);
}

// The GNC steps round without the local refinement unless
// gnc_refine_rounded_solution: one step from the same start, the same
// staircase run, and the refinement's iterations on top when asked for,
// wherever the step's relaxation is not exact (its wrong closures still
// weighted, it ends at the GNC steps' top rank untested).
TEST(RobustSolver, GncStepsRefineTheirRoundingOnlyWhenAsked) {
  int inexact_steps = 0;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    PoseGraph corrupted;
    // (Refused where the cube has no loop closure to replace.)
    if (!SmallNoisyCubeWithOutliers(seed, &corrupted, nullptr)) continue;
    RobustSolverOptions options = Options();
    options.max_iterations = 1;
    options.gnc_threshold_fractions = {1.0};
    RobustSolverSummary plain, refined;
    SolveRobust(corrupted, options, &plain);
    if (plain.history.empty() ||
        plain.history[0].status != SolverSummary::Status::kMaxRankReached) {
      continue;
    }
    ++inexact_steps;
    options.gnc_refine_rounded_solution = true;
    SolveRobust(corrupted, options, &refined);
    ASSERT_EQ(refined.history.size(), 1u) << refined.FullReport();
    EXPECT_EQ(plain.history[0].rank, refined.history[0].rank);
    EXPECT_GT(refined.history[0].solver_iterations,
              plain.history[0].solver_iterations)
        << "seed " << seed;
  }
  EXPECT_GE(inexact_steps, 3) << inexact_steps;
}

// A wrong closure the map bends to fit within c^2: the first solve
// accepts every measurement but its relaxation is not exact (not
// certified). GNC must still run (at the fractions of c^2 below the largest
// f_k) instead of returning the uncertified all-inlier answer; here the run
// at 0.1 c^2 rejects exactly the injected closure and certifies. (Before
// the fix: no GNC step, nothing rejected, not certified.)
TEST(RobustSolver, UncertifiedFirstSolveThatFitsEveryMeasurementStartsGnc) {
  PoseGraph corrupted;
  std::vector<int> added;
  ASSERT_TRUE(SmallNoisyCubeWithOutliers(4, &corrupted, &added));
  // The complete staircase in the first solve: at its rank-10 optimum the
  // map fits the wrong closure (at the default rank r0 it does not, and
  // run 1 already rejects it).
  RobustSolverOptions options = Options();
  options.initial_max_rank = options.solver_options.max_rank;
  RobustSolverSummary s;
  SolveRobust(corrupted, options, &s);
  // The premise: the first solve fits every measurement, uncertified.
  ASSERT_FALSE(s.initial_summary.certified()) << s.FullReport();
  ASSERT_EQ(s.runs.size(), 2u);
  EXPECT_EQ(s.runs[0].iterations, 0);  // Every TLS weight 1 at c^2.
  EXPECT_EQ(s.runs[0].num_outliers, 0);
  EXPECT_FALSE(s.runs[0].certified);
  EXPECT_GT(s.runs[1].iterations, 0);
  EXPECT_EQ(s.selected_run, 1);
  EXPECT_TRUE(s.certified()) << s.FullReport();
  EXPECT_EQ(s.outlier_edges, added) << s.FullReport();
  EXPECT_LT(s.runs[1].tls_cost, s.runs[0].tls_cost);
}

// Re-admission: on a small noisy cube with one wrong closure, GNC's
// accepted set leaves out a true closure too (the map without it bends
// away, f_k > c^2 at that optimum, so the consistency rounds keep it out);
// re-admitting it lowers the TLS cost, and exactly the wrong closure is
// rejected.
TEST(RobustSolver, ReadmissionRecoversATrueClosureAndLowersTheTlsCost) {
  PoseGraph corrupted;
  std::vector<int> added;
  ASSERT_TRUE(SmallNoisyCubeWithOutliers(3, &corrupted, &added));
  RobustSolverOptions options = Options();
  options.max_readmission_trials = 0;
  RobustSolverSummary without;
  SolveRobust(corrupted, options, &without);
  // The premise: without re-admission a true closure is rejected as well.
  ASSERT_TRUE(without.certified()) << without.FullReport();
  ASSERT_GT(without.num_outliers, static_cast<int>(added.size()));
  EXPECT_EQ(without.readmissions, 0);
  RobustSolverSummary with;
  SolveRobust(corrupted, Options(), &with);
  EXPECT_TRUE(with.certified()) << with.FullReport();
  EXPECT_EQ(with.outlier_edges, added) << with.FullReport();
  EXPECT_GE(with.readmissions, 1);
  EXPECT_EQ(with.num_rejected_within_threshold, 0);
  EXPECT_LT(with.runs[with.selected_run].tls_cost,
            without.runs[without.selected_run].tls_cost);
  // The TLS cost of the result, recomputed from its verdicts.
  const double c2 = with.inlier_threshold;
  double tls = 0;
  for (const RobustSolverSummary::Edge& e : with.edges) {
    tls += e.known_inlier ? e.cost : std::min(e.cost, c2);
  }
  EXPECT_NEAR(tls, with.runs[with.selected_run].tls_cost, 1e-9 * tls);
}

// Removal: a noiseless ring of 12 poses (odometry known inliers) with two
// true closures, 11 -> 0 and 10 -> 1, and a wrong 11 -> 0 beside the true
// one, 1 m and 0.2 rad off, five times as precise. GNC keeps the wrong one
// and rejects the true 11 -> 0 (the ring bends to the precise measurement;
// the re-admission trials cannot undo it one closure at a time). The removal
// trial drops the wrong closure; the consistency rounds then re-admit the
// true one: TLS cost c^2 instead of ~1.6 c^2, exactly the truth.
TEST(RobustSolver, RemovalTrialDropsAWrongClosureTheMapBentTo) {
  const int n = 12;
  PoseGraph graph;
  graph.dimension = 2;
  Poses truth;
  for (int i = 0; i < n; ++i) {
    graph.AddVertex(i);
    const double a = 2 * M_PI * i / n;
    Pose p;
    p.R = Eigen::Rotation2Dd(a + M_PI / 2).toRotationMatrix();
    p.t = Eigen::Vector2d(5 * std::cos(a), 5 * std::sin(a));
    truth.push_back(p);
  }
  auto add = [&](int i, int j, double precision) {
    RelativePoseMeasurement m;
    m.i = i;
    m.j = j;
    m.kappa = m.tau = precision;
    graph.measurements.push_back(m);
  };
  for (int i = 0; i + 1 < n; ++i) add(i, i + 1, 100);
  add(n - 1, 0, 100);  // 11: true.
  add(n - 2, 1, 100);  // 12: true.
  add(n - 1, 0, 500);  // 13: wrong (below).
  test_util::MakeMeasurementsExact(truth, &graph);
  RelativePoseMeasurement& wrong = graph.measurements.back();
  wrong.t += Eigen::Vector2d(1, 0);
  wrong.R = wrong.R * Eigen::Rotation2Dd(0.2).toRotationMatrix();

  RobustSolverOptions options = Options();
  options.max_removal_trials = 0;
  RobustSolverSummary without;
  SolveRobust(graph, options, &without);
  // The premise: without removal trials the wrong closure stays in.
  ASSERT_EQ(without.outlier_edges, std::vector<int>{11})
      << without.FullReport();
  EXPECT_EQ(without.removals, 0);

  RobustSolverSummary with;
  const Poses x = SolveRobust(graph, Options(), &with);
  EXPECT_TRUE(with.certified()) << with.FullReport();
  EXPECT_EQ(with.outlier_edges, std::vector<int>{13}) << with.FullReport();
  EXPECT_GE(with.removals, 1);
  EXPECT_GE(with.runs[with.selected_run].removal_trials, with.removals);
  EXPECT_EQ(with.num_rejected_within_threshold, 0);
  EXPECT_EQ(with.num_accepted_beyond_threshold, 0);
  const double c2 = with.inlier_threshold;
  EXPECT_NEAR(with.runs[with.selected_run].tls_cost, c2, 1e-8 * c2);
  EXPECT_LT(with.runs[with.selected_run].tls_cost,
            without.runs[without.selected_run].tls_cost);
  // The truth, up to the gauge.
  EXPECT_LT(test_util::GaugeInvariantPoseDistance(x, truth), 1e-6);
  EXPECT_THAT(with.FullReport(), ::testing::HasSubstr("Removed measurements"));
}

// A removal trial must not let a wrong closure in: on this 4x4x4 cube at
// the paper's noise with 30% wrong closures, dropping a true closure lets
// the map bend until a wrong one fits, at a lower TLS cost but with the
// relaxation no longer exact (the inlier problem not certified). Either of
// the trials' two guards keeps that trial out (the rounds run only where
// the removal lets a rejected term fit, and the result must be certified);
// exactly the wrong closures are rejected, certified. (Without both guards
// a wrong closure stays in, uncertified.)
TEST(RobustSolver, RemovalTrialDoesNotLetAWrongClosureIn) {
  PoseGraph corrupted;
  std::vector<int> added;
  ASSERT_TRUE(SmallNoisyCubeWithOutliers(14, &corrupted, &added, 4, 0.3));
  RobustSolverSummary s;
  SolveRobust(corrupted, Options(), &s);
  EXPECT_TRUE(s.certified()) << s.FullReport();
  EXPECT_EQ(s.outlier_edges, added) << s.FullReport();
  int trials = 0;
  for (const RobustSolverSummary::Run& r : s.runs) trials += r.removal_trials;
  EXPECT_GT(trials, 0);
}

// The re-admission test scaled by the variance factor: with 50% wrong
// closures on a small noisy cube, the bare TLS rule re-admits a wrong
// closure that the map bends to fit (it lowers the TLS cost); the scaled
// rule (default) keeps it out, and exactly the wrong closures are rejected.
TEST(RobustSolver, ScaledReadmissionKeepsOutAWrongClosureTheMapBendsToFit) {
  PoseGraph corrupted;
  std::vector<int> added;
  ASSERT_TRUE(SmallNoisyCubeWithOutliers(25, &corrupted, &added, 3, 0.5));
  ASSERT_FALSE(added.empty());
  // Both with the complete staircase in the first solve (from its result
  // GNC accepts the set that the bare rule then extends).
  RobustSolverOptions options = Options();
  options.initial_max_rank = options.solver_options.max_rank;
  // The re-admission rule alone: with removal trials, GNC's first run drops
  // one of its two accepted wrong closures, the rounds re-admit a true one,
  // and that run ends at the TLS optimum itself (117.56, below the truth's
  // 122.71), which keeps the other wrong closure.
  options.max_removal_trials = 0;
  RobustSolverOptions bare = options;
  bare.readmission_min_scale = 1;
  RobustSolverSummary bare_rule;
  SolveRobust(corrupted, bare, &bare_rule);
  // The premise: a wrong closure is re-admitted and stays in.
  ASSERT_GE(bare_rule.readmissions, 1) << bare_rule.FullReport();
  int accepted_wrong = 0;
  for (int k : added) accepted_wrong += bare_rule.edges[k].inlier;
  ASSERT_GE(accepted_wrong, 1) << bare_rule.FullReport();
  RobustSolverSummary scaled;
  SolveRobust(corrupted, options, &scaled);
  EXPECT_TRUE(scaled.certified()) << scaled.FullReport();
  EXPECT_EQ(scaled.outlier_edges, added) << scaled.FullReport();
  EXPECT_EQ(scaled.readmissions, 0);
  // The TLS cost itself prefers the bent map (the wrong closure costs
  // less than c^2 there): the scaling, not the TLS rule, keeps it out.
  EXPECT_LT(bare_rule.runs[bare_rule.selected_run].tls_cost,
            scaled.runs[scaled.selected_run].tls_cost);
}

// A 3D chain of 40 poses with 30% of its loop closures replaced by wrong
// ones (both GNC runs work on it).
PoseGraph ChainWithOutliers() {
  const PoseGraph clean = ChainGraph(3, 40, 30, false, 4, nullptr);
  OutlierOptions o;
  o.fraction = 0.3;
  o.seed = 9;
  PoseGraph corrupted;
  EXPECT_TRUE(AddOutliers(clean, o, &corrupted, nullptr, nullptr));
  return corrupted;
}

// The same input and options (thread count included) give the same result,
// bitwise; so do 1 and 2 threads (the kernels' results do not depend on
// the thread count; with 2 the GNC runs go at once).
TEST(RobustSolver, DeterministicForSeedAndThreads) {
  const PoseGraph corrupted = ChainWithOutliers();
  RobustSolverOptions options = Options();
  RobustSolverSummary a, b, c;
  const Poses pa = SolveRobust(corrupted, options, &a);
  const Poses pb = SolveRobust(corrupted, options, &b);
  options.solver_options.num_threads = 2;
  const Poses pc = SolveRobust(corrupted, options, &c);
  for (const auto* other : {&b, &c}) {
    EXPECT_EQ(a.outlier_edges, other->outlier_edges);
    EXPECT_EQ(a.iterations, other->iterations);
    EXPECT_EQ(a.inlier_summary.objective, other->inlier_summary.objective);
    ASSERT_EQ(a.edges.size(), other->edges.size());
    for (size_t k = 0; k < a.edges.size(); ++k) {
      EXPECT_EQ(a.edges[k].weight, other->edges[k].weight);
    }
  }
  for (const Poses* other : {&pb, &pc}) {
    ASSERT_EQ(pa.size(), other->size());
    for (size_t i = 0; i < pa.size(); ++i) {
      EXPECT_EQ(pa[i].R, (*other)[i].R);
      EXPECT_EQ(pa[i].t, (*other)[i].t);
    }
  }
}

// With two threads the two GNC runs go at once, one thread each: progress
// reports still come from the calling thread alone, and the per-iteration
// callbacks (from both runs' threads) one at a time.
TEST(RobustSolver, ConcurrentRunsReportFromOneThreadAtATime) {
  const PoseGraph corrupted = ChainWithOutliers();
  RobustSolverSummary serial;
  SolveRobust(corrupted, Options(), &serial);
  ASSERT_EQ(serial.runs.size(), 2u);

  RobustSolverOptions options = Options();
  options.solver_options.num_threads = 2;
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> inside(0), overlaps(0), calls(0);
  std::mutex mutex;
  std::set<std::thread::id> callback_threads;
  options.solver_options.callback = [&](int, int, double, double, double) {
    if (inside.fetch_add(1) != 0) ++overlaps;
    ++calls;
    {
      std::lock_guard<std::mutex> lock(mutex);
      callback_threads.insert(std::this_thread::get_id());
    }
    // Long enough for two unserialized runs to meet here.
    std::this_thread::sleep_for(std::chrono::microseconds(100));
    inside.fetch_sub(1);
    return true;
  };
  std::atomic<int> progress_calls(0), progress_elsewhere(0);
  options.solver_options.progress = [&](const SolverProgress&) {
    ++progress_calls;
    if (std::this_thread::get_id() != caller) ++progress_elsewhere;
  };
  RobustSolverSummary s;
  SolveRobust(corrupted, options, &s);
  EXPECT_EQ(serial.concurrent_runs, 1);
  EXPECT_EQ(s.concurrent_runs, 2);
  EXPECT_EQ(callback_threads.size(), 2u);  // Both runs' threads called.
  EXPECT_GT(calls.load(), 0);
  EXPECT_EQ(overlaps.load(), 0);
  EXPECT_GT(progress_calls.load(), 0);
  EXPECT_EQ(progress_elsewhere.load(), 0);
  EXPECT_EQ(s.outlier_edges, serial.outlier_edges);
}

// An exception thrown in a run on another thread (here by the callback,
// only there) reaches the caller, as it would with one thread, and the
// calling thread's run stops at its next iteration instead of finishing.
TEST(RobustSolver, ExceptionsOfConcurrentRunsReachTheCaller) {
  const PoseGraph corrupted = ChainWithOutliers();
  RobustSolverSummary serial;
  SolveRobust(corrupted, Options(), &serial);
  int first_run_iterations = 0;  // Its GNC steps' trust-region iterations.
  for (const auto& step : serial.history) {
    first_run_iterations += step.solver_iterations;
  }
  ASSERT_EQ(serial.selected_run, 0);
  ASSERT_GT(first_run_iterations, 10);

  RobustSolverOptions options = Options();
  options.solver_options.num_threads = 2;
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<bool> thrown(false);
  std::atomic<int> caller_calls_after(0);
  options.solver_options.callback = [&](int, int, double, double, double) {
    if (std::this_thread::get_id() != caller) {
      thrown = true;
      throw std::runtime_error("from the second run");
    }
    if (thrown) {
      ++caller_calls_after;
      // Slow enough that the other run's exception surely unwinds (and
      // cancels) within one of these iterations, however loaded the machine.
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    return true;
  };
  RobustSolverSummary s;
  EXPECT_THROW(SolveRobust(corrupted, options, &s), std::runtime_error);
  // (Its iteration in progress when the other threw, and the next one's
  // callback before its progress report; 19-21 without the cancellation.)
  EXPECT_LE(caller_calls_after.load(), 3);
}

// Two clusters joined only by two contradicting measurements, neither of
// them odometry: the graph is connected, but both bridges are rejected
// (accepting them costs far more than c^2 each), which would disconnect the
// accepted graph: a clear status, no crash, no certificate.
TEST(RobustSolver, InlierSetThatDisconnectsTheGraphGetsAClearStatus) {
  for (int d : {2, 3}) {
    Poses truth;
    PoseGraph a = ChainGraph(d, 10, 12, true, 21, &truth);
    Poses truth_b;
    const PoseGraph b = ChainGraph(d, 10, 12, true, 22, &truth_b);
    // Poses 10..19 are b's, shifted.
    PoseGraph graph = a;
    graph.initial_poses.clear();
    for (int k = 10; k < 20; ++k) graph.AddVertex(k);
    for (RelativePoseMeasurement e : b.measurements) {
      e.i += 10;
      e.j += 10;
      graph.measurements.push_back(e);
    }
    // Bridges (4, 14): a relative pose turned by +-60 degrees about the
    // same axis. Their rotation terms add up to one term for the unturned
    // pose (R + R^T = I in the plane of the turn), so the least-squares fit
    // is that pose and both residuals are equal: 4 kappa (1 - cos 60) = 200
    // each, far above c^2.
    Eigen::MatrixXd turn = Eigen::MatrixXd::Identity(d, d);
    turn(0, 0) = turn(1, 1) = 0.5;
    turn(0, 1) = -std::sqrt(0.75);
    turn(1, 0) = std::sqrt(0.75);
    for (bool inverse : {false, true}) {
      RelativePoseMeasurement e;
      e.i = 4;
      e.j = 14;
      e.R = inverse ? Eigen::MatrixXd(turn.transpose()) : turn;
      e.t = Eigen::VectorXd::Zero(d);
      e.t(0) = 1;
      e.kappa = 100;
      e.tau = 100;
      graph.measurements.push_back(e);
    }
    ASSERT_TRUE(ValidatePoseGraph(graph, nullptr));
    for (auto known : {RobustSolverOptions::KnownInliers::kOdometry,
                       RobustSolverOptions::KnownInliers::kNone}) {
      RobustSolverOptions options = Options();
      options.known_inliers = known;
      RobustSolverSummary s;
      const Poses poses = SolveRobust(graph, options, &s);
      EXPECT_EQ(s.status, RobustSolverSummary::Status::kInlierGraphDisconnected)
          << s.FullReport();
      EXPECT_THAT(s.message, ::testing::HasSubstr("2 components"));
      EXPECT_FALSE(s.certified());
      EXPECT_EQ(poses.size(), 20u);  // The last connected step's.
      EXPECT_EQ(s.edges.size(), graph.measurements.size());
      EXPECT_THAT(s.FullReport(),
                  ::testing::HasSubstr("INLIER_GRAPH_DISCONNECTED"));
    }
  }
}

TEST(RobustSolver, InvalidOptionsAndInputsAreReported) {
  const PoseGraph graph = ChainGraph(2, 10, 5, false, 1, nullptr);
  RobustSolverSummary s;
  RobustSolverOptions options = Options();
  options.mu_step = 1;
  EXPECT_TRUE(SolveRobust(graph, options, &s).empty());
  EXPECT_EQ(s.status, RobustSolverSummary::Status::kInvalidInput);
  EXPECT_THAT(s.message, ::testing::HasSubstr("mu_step"));
  options = Options();
  options.inlier_probability = 1;
  SolveRobust(graph, options, &s);
  EXPECT_THAT(s.message, ::testing::HasSubstr("inlier_probability"));
  options = Options();
  options.gnc_threshold_fractions = {0.1, 2};
  SolveRobust(graph, options, &s);
  EXPECT_THAT(s.message, ::testing::HasSubstr("gnc_threshold_fractions"));
  options = Options();
  options.max_readmission_trials = -1;
  SolveRobust(graph, options, &s);
  EXPECT_THAT(s.message, ::testing::HasSubstr("max_readmission_trials"));
  options = Options();
  options.max_removal_trials = -1;
  SolveRobust(graph, options, &s);
  EXPECT_THAT(s.message, ::testing::HasSubstr("max_removal_trials"));
  options = Options();
  options.readmission_max_cost = std::nan("");
  SolveRobust(graph, options, &s);
  EXPECT_THAT(s.message, ::testing::HasSubstr("readmission_max_cost"));
  for (double scale : {-0.1, 1.5, std::nan("")}) {
    options = Options();
    options.readmission_min_scale = scale;
    SolveRobust(graph, options, &s);
    EXPECT_THAT(s.message, ::testing::HasSubstr("readmission_min_scale"));
  }
  for (double tolerance : {-1e-3, 1.0, std::nan("")}) {
    options = Options();
    options.gnc_relative_decrease_tolerance = tolerance;
    SolveRobust(graph, options, &s);
    EXPECT_THAT(s.message,
                ::testing::HasSubstr("gnc_relative_decrease_tolerance"));
  }
  PoseGraph bad = graph;
  bad.measurements[3].kappa = -1;
  SolveRobust(bad, Options(), &s);
  EXPECT_EQ(s.status, RobustSolverSummary::Status::kInvalidInput);
  EXPECT_THAT(s.BriefReport(), ::testing::HasSubstr("INVALID_INPUT"));
}

// A landmark graph with GPS-like position priors and a start prior.
LandmarkGraphOptions LandmarkCase(int d, bool noiseless, uint64_t seed) {
  LandmarkGraphOptions o;
  o.dimension = d;
  o.num_poses = 80;
  o.num_landmarks = 60;
  o.world_size = 16;
  o.sensor_range = 6;
  o.block_length = 4;
  o.landmark_nu = 400;  // 5 cm.
  o.gps_interval = 4;
  o.start_prior = true;
  o.noiseless = noiseless;
  o.seed = seed;
  return o;
}

// Noiseless landmark graph plus wrong data associations and false GPS
// fixes: the accepted problem is certified and its optimum is the ground
// truth itself (the priors fix the world frame); every false fix and no
// measurement or true prior is rejected; every wrong association is
// rejected except where the truth is not identifiable: a landmark that one
// pose alone observes truly is fit exactly by that observation or by one
// wrong association to it, at the same TLS cost.
TEST(RobustSolver, WrongLandmarkAssociationsAndFalseFixesAreRejected) {
  for (auto [d, fraction] : {std::pair{2, 0.3}, {2, 0.5}, {3, 0.3}}) {
    SCOPED_TRACE(testing::Message() << "d " << d << " fraction " << fraction);
    PoseGraph clean, corrupted;
    Solution truth;
    std::string error;
    ASSERT_TRUE(
        GenerateLandmarkGraph(LandmarkCase(d, true, 3), &clean, &truth, &error))
        << error;
    LandmarkOutlierOptions outliers;
    outliers.landmark_fraction = fraction;
    outliers.prior_fraction = fraction;
    outliers.seed = 11;
    std::vector<int> added_l, added_p;
    ASSERT_TRUE(AddLandmarkOutliers(clean, outliers, &corrupted, &added_l,
                                    &added_p, &error))
        << error;
    ASSERT_GT(added_l.size(), 100u);
    ASSERT_GT(added_p.size(), 5u);
    std::vector<int> seen_by(clean.num_landmarks, 0);
    for (const LandmarkMeasurement& o : clean.landmark_measurements) {
      ++seen_by[o.l];
    }
    RobustSolverSummary s;
    Solution x;
    SolveRobust(corrupted, Options(), &x, &s);
    EXPECT_TRUE(s.certified()) << s.FullReport();
    EXPECT_TRUE(s.outlier_edges.empty()) << s.FullReport();
    EXPECT_EQ(s.outlier_priors, added_p) << s.FullReport();
    // Wrong associations accepted and true observations rejected: only on
    // landmarks seen once, one for one.
    const std::set<int> wrong(added_l.begin(), added_l.end());
    std::set<int> rejected(s.outlier_landmark_measurements.begin(),
                           s.outlier_landmark_measurements.end());
    std::vector<int> ties(clean.num_landmarks, 0);
    for (int q : added_l) {
      if (!rejected.count(q)) {
        const int l = corrupted.landmark_measurements[q].l;
        EXPECT_EQ(seen_by[l], 1) << "wrong association " << q << " accepted";
        ++ties[l];
      }
    }
    for (int q : s.outlier_landmark_measurements) {
      if (wrong.count(q)) continue;
      const int l = corrupted.landmark_measurements[q].l;
      EXPECT_EQ(ties[l], 1) << "true observation " << q << " rejected";
      --ties[l];
    }
    for (int l = 0; l < clean.num_landmarks; ++l) EXPECT_EQ(ties[l], 0) << l;
    ASSERT_EQ(s.edges.size(), corrupted.measurements.size() +
                                  corrupted.landmark_measurements.size() +
                                  corrupted.priors.size());
    // The verdicts name their terms. Landmark measurements have d degrees
    // of freedom: their threshold is the chi^2(d) quantile.
    const RobustSolverSummary::Edge& bad =
        s.edges[corrupted.measurements.size() + added_l[0]];
    EXPECT_EQ(bad.kind, RobustSolverSummary::Edge::Kind::kLandmark);
    EXPECT_EQ(bad.index, added_l[0]);
    EXPECT_EQ(
        bad.vertex_j,
        corrupted.landmark_ids[corrupted.landmark_measurements[added_l[0]].l]);
    EXPECT_DOUBLE_EQ(bad.threshold,
                     internal::ChiSquareQuantile(
                         RobustSolverOptions().inlier_probability, d));
    // The public per-term costs and thresholds are the verdicts' own.
    const std::vector<double> costs = TermCosts(corrupted, x);
    const std::vector<double> thresholds = TermThresholds(Options(), corrupted);
    ASSERT_EQ(costs.size(), s.edges.size());
    ASSERT_EQ(thresholds.size(), s.edges.size());
    for (size_t k = 0; k < s.edges.size(); ++k) {
      EXPECT_EQ(costs[k], s.edges[k].cost) << k;
      EXPECT_EQ(thresholds[k], s.edges[k].threshold) << k;
    }
    const RobustSolverSummary::Edge& fix =
        s.edges[s.edges.size() - corrupted.priors.size() + added_p[0]];
    EXPECT_EQ(fix.kind, RobustSolverSummary::Edge::Kind::kPrior);
    EXPECT_FALSE(fix.inlier);
    EXPECT_GT(fix.cost, fix.threshold);
    ASSERT_EQ(x.poses.size(), truth.poses.size());
    ASSERT_EQ(x.landmarks.size(), truth.landmarks.size());
    for (int i = 0; i < clean.num_poses; ++i) {
      EXPECT_LT((x.poses[i].R - truth.poses[i].R).norm(), 1e-6) << i;
      EXPECT_LT((x.poses[i].t - truth.poses[i].t).norm(), 1e-6) << i;
    }
    for (int l = 0; l < clean.num_landmarks; ++l) {
      if (seen_by[l] == 1) continue;  // A tie may have placed it elsewhere.
      EXPECT_LT((x.landmarks[l] - truth.landmarks[l]).norm(), 1e-6) << l;
    }
  }
}

// A landmark whose observations GNC weights all down to 0 in the same step
// (here a landmark seen by a few poses, pulled between its true and wrong
// observations) is not cut off: one observation, fit exactly, keeps it in
// the problem (measured: without that rule this graph ends
// INLIER_GRAPH_DISCONNECTED at GNC step 4).
TEST(RobustSolver,
     LandmarkWhoseObservationsAllLoseTheirWeightStaysInTheProblem) {
  LandmarkGraphOptions o = LandmarkCase(2, true, 3);
  o.sensor_range = 5;
  o.landmark_nu = 25;
  PoseGraph clean, corrupted;
  std::string error;
  ASSERT_TRUE(GenerateLandmarkGraph(o, &clean, nullptr, &error)) << error;
  LandmarkOutlierOptions outliers;
  outliers.landmark_fraction = 0.1;
  outliers.seed = 11;
  ASSERT_TRUE(AddLandmarkOutliers(clean, outliers, &corrupted, nullptr, nullptr,
                                  &error))
      << error;
  RobustSolverSummary s;
  Solution x;
  SolveRobust(corrupted, Options(), &x, &s);
  EXPECT_EQ(s.status, RobustSolverSummary::Status::kConverged)
      << s.FullReport();
  EXPECT_TRUE(s.certified()) << s.FullReport();
  // Every landmark keeps an accepted observation.
  std::vector<char> observed(corrupted.num_landmarks, 0);
  for (const RobustSolverSummary::Edge& e : s.edges) {
    if (e.kind == RobustSolverSummary::Edge::Kind::kLandmark && e.inlier) {
      observed[corrupted.landmark_measurements[e.index].l] = 1;
    }
  }
  EXPECT_EQ(std::count(observed.begin(), observed.end(), 1),
            corrupted.num_landmarks);
}

// A 2D map with ~30 landmarks per pose, 30% wrong associations and 30%
// false GPS fixes: both GNC runs, started from the least-squares fit of
// every term, end at local minima of the TLS cost (measured: 64,558, not
// certified, and 62,729). The consensus run (the graph without landmarks
// solved robustly, then each landmark placed where most of its
// observations agree) reaches 54,280, is selected, and its map is the
// clean graph's certified optimum up to the few centimeters that the
// remaining accepted wrong associations move it.
TEST(RobustSolver, ConsensusRunRecoversAMapThatGncFolds) {
  LandmarkGraphOptions o = VictoriaParkLikeOptions();
  o.num_poses = 150;
  o.gps_interval = 20;
  o.start_prior = true;
  o.seed = 1;
  PoseGraph clean, corrupted;
  std::string error;
  ASSERT_TRUE(GenerateLandmarkGraph(o, &clean, nullptr, &error)) << error;
  LandmarkOutlierOptions outliers;
  outliers.landmark_fraction = 0.3;
  outliers.prior_fraction = 0.3;
  outliers.seed = 2;
  std::vector<int> added_l, added_p;
  ASSERT_TRUE(AddLandmarkOutliers(clean, outliers, &corrupted, &added_l,
                                  &added_p, &error))
      << error;
  SolverSummary clean_summary;
  Solution optimum;
  Solve(clean, Options().solver_options, &optimum, &clean_summary);
  ASSERT_TRUE(clean_summary.certified());
  RobustSolverSummary s;
  Solution x;
  SolveRobust(corrupted, Options(), &x, &s);
  const size_t gnc_runs = RobustSolverOptions().gnc_threshold_fractions.size();
  ASSERT_EQ(s.runs.size(), gnc_runs + 1);
  EXPECT_EQ(s.selected_run, static_cast<int>(gnc_runs)) << s.FullReport();
  EXPECT_EQ(s.runs.back().gnc_threshold, 0);
  EXPECT_EQ(s.runs.back().iterations, 0);
  for (size_t q = 0; q < gnc_runs; ++q) {
    EXPECT_LT(s.runs.back().tls_cost, s.runs[q].tls_cost);
  }
  EXPECT_TRUE(s.certified()) << s.FullReport();
  EXPECT_EQ(s.outlier_priors, added_p);
  EXPECT_TRUE(s.outlier_edges.empty());
  const std::set<int> wrong(added_l.begin(), added_l.end());
  int true_rejected = 0;
  for (int q : s.outlier_landmark_measurements)
    true_rejected += !wrong.count(q);
  EXPECT_LE(true_rejected, 10) << "of " << clean.landmark_measurements.size();
  double max_error = 0;
  for (int i = 0; i < clean.num_poses; ++i) {
    max_error = std::max(max_error, (x.poses[i].t - optimum.poses[i].t).norm());
  }
  EXPECT_LT(max_error, 0.1);
}

// Without outliers, on a noisy landmark graph with priors, the robust
// solve is Solve(): the same poses and landmarks, certified, nothing
// rejected.
TEST(RobustSolver, LandmarkGraphWithoutOutliersEqualsSolve) {
  for (int d : {2, 3}) {
    PoseGraph graph;
    std::string error;
    ASSERT_TRUE(GenerateLandmarkGraph(LandmarkCase(d, false, 5), &graph,
                                      nullptr, &error))
        << error;
    SolverSummary plain;
    Solution expected;
    Solve(graph, Options().solver_options, &expected, &plain);
    ASSERT_TRUE(plain.certified()) << plain.FullReport();
    RobustSolverSummary s;
    Solution x;
    SolveRobust(graph, Options(), &x, &s);
    EXPECT_TRUE(s.certified()) << s.FullReport();
    EXPECT_EQ(s.num_outliers, 0) << s.FullReport();
    EXPECT_EQ(s.iterations, 0);
    EXPECT_NEAR(s.inlier_summary.objective, plain.objective,
                1e-9 * plain.objective);
    for (int i = 0; i < graph.num_poses; ++i) {
      EXPECT_LT((x.poses[i].t - expected.poses[i].t).norm(), 1e-6) << i;
    }
    for (int l = 0; l < graph.num_landmarks; ++l) {
      EXPECT_LT((x.landmarks[l] - expected.landmarks[l]).norm(), 1e-6) << l;
    }
  }
}

// Ceres with Huber and Cauchy losses on the same terms: the robust
// objective it reports is sum_k rho(f_k) at its result, F is eq. (12), and
// it reduces to least squares without a loss.
TEST(CeresRobustLoss, LossesAreOnTheMeasurementTerms) {
  const PoseGraph clean = ChainGraph(3, 30, 20, false, 6, nullptr);
  OutlierOptions o;
  o.fraction = 0.2;
  PoseGraph graph;
  ASSERT_TRUE(AddOutliers(clean, o, &graph, nullptr, nullptr));
  const Poses initial = OdometryInitialization(clean);
  const double a2 = 9;
  for (auto type : {CeresRobustLoss::Type::kNone, CeresRobustLoss::Type::kHuber,
                    CeresRobustLoss::Type::kCauchy}) {
    CeresBaselineOptions options;
    options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
    options.loss.type = type;
    options.loss.threshold = a2;
    Poses result;
    CeresBaselineSummary summary;
    std::string error;
    ASSERT_TRUE(
        SolveWithCeres(graph, initial, options, &result, &summary, &error))
        << error;
    double robust = 0;
    for (const RelativePoseMeasurement& e : graph.measurements) {
      const Pose& p = result[e.i];
      const Pose& q = result[e.j];
      const double s = e.kappa * (q.R - p.R * e.R).squaredNorm() +
                       e.tau * (q.t - p.t - p.R * e.t).squaredNorm();
      switch (type) {
        case CeresRobustLoss::Type::kNone:
          robust += s;
          break;
        case CeresRobustLoss::Type::kHuber:
          robust += s <= a2 ? s : 2 * std::sqrt(a2 * s) - a2;
          break;
        case CeresRobustLoss::Type::kCauchy:
          robust += a2 * std::log1p(s / a2);
          break;
      }
    }
    EXPECT_NEAR(summary.final_robust_objective, robust, 1e-8 * robust);
    EXPECT_NEAR(summary.final_objective, EvaluateObjective(graph, result),
                1e-9 * summary.final_objective);
    if (type != CeresRobustLoss::Type::kNone) {
      EXPECT_LT(summary.final_robust_objective, summary.final_objective);
    }
  }
  CeresBaselineOptions bad;
  bad.loss.type = CeresRobustLoss::Type::kHuber;
  std::string error;
  EXPECT_FALSE(SolveWithCeres(graph, initial, bad, nullptr, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("threshold"));
}

// With landmark and prior thresholds the loss reaches those terms too: the
// robust objective Ceres reports is sum rho over the measurements, the
// landmark measurements and each prior's rotation and position term, each
// with its own a^2 (computed here from the result).
TEST(CeresRobustLoss, LandmarkAndPriorTermsGetTheirOwnThresholds) {
  LandmarkGraphOptions o = LandmarkCase(2, false, 4);
  PoseGraph clean, graph;
  std::string error;
  ASSERT_TRUE(GenerateLandmarkGraph(o, &clean, nullptr, &error)) << error;
  LandmarkOutlierOptions outliers;
  outliers.landmark_fraction = 0.2;
  outliers.prior_fraction = 0.2;
  ASSERT_TRUE(
      AddLandmarkOutliers(clean, outliers, &graph, nullptr, nullptr, &error))
      << error;
  const Poses poses = OdometryInitialization(graph);
  const Solution initial{poses, InitialLandmarkPositions(graph, poses)};
  const double a2 = 9, b2 = 5, p2 = 7;
  auto cauchy = [](double s, double t) { return t * std::log1p(s / t); };
  CeresBaselineOptions options;
  options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
  options.loss.type = CeresRobustLoss::Type::kCauchy;
  options.loss.threshold = a2;
  options.loss.landmark_threshold = b2;
  options.loss.prior_threshold = p2;
  Solution x;
  CeresBaselineSummary summary;
  ASSERT_TRUE(SolveWithCeres(graph, initial, options, &x, &summary, &error))
      << error;
  double robust = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    const Pose& p = x.poses[e.i];
    const Pose& q = x.poses[e.j];
    robust += cauchy(e.kappa * (q.R - p.R * e.R).squaredNorm() +
                         e.tau * (q.t - p.t - p.R * e.t).squaredNorm(),
                     a2);
  }
  for (const LandmarkMeasurement& m : graph.landmark_measurements) {
    const Pose& p = x.poses[m.i];
    robust +=
        cauchy(m.nu * (x.landmarks[m.l] - p.t - p.R * m.z).squaredNorm(), b2);
  }
  for (const PosePrior& prior : graph.priors) {
    const Pose& p = x.poses[prior.i];
    if (prior.has_rotation()) {
      robust += cauchy(prior.kappa * (p.R - prior.R).squaredNorm(), p2);
    }
    if (prior.has_position()) {
      robust += cauchy(prior.tau * (p.t - prior.t).squaredNorm(), p2);
    }
  }
  EXPECT_NEAR(summary.final_robust_objective, robust, 1e-8 * robust);
  EXPECT_LT(summary.final_robust_objective, summary.final_objective);
  options.loss.prior_threshold = -1;
  EXPECT_FALSE(SolveWithCeres(graph, initial, options, &x, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("prior"));
}

}  // namespace
}  // namespace ceres_sesync
