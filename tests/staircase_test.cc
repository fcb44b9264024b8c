// The staircase's choice of the certificate test during a descent after an
// escape (internal::PlanDescentTest): its shift, arithmetic and schedule
// price as double's reach moves from below half the tolerance's shift to
// beyond three quarters of it, for each ProofArithmetic. And the "continue"
// stage (Staircase::Continue): a relaxation certified within the tolerance
// whose rounded poses are not, for want of a tighter proof.

#include "ceres_sesync/internal/staircase.h"

#include <string>

#include "ceres_sesync/cube_generator.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

using internal::DescentTestPlan;
using internal::PlanDescentTest;
using internal::ProofPrecision;
using Arithmetic = SolverOptions::ProofArithmetic;

constexpr double kHalf = 2e-4, kThreeQuarters = 3e-4;

void ExpectTest(const DescentTestPlan& t, double eta, ProofPrecision precision,
                double price) {
  EXPECT_TRUE(t.run);
  EXPECT_EQ(t.eta, eta);
  EXPECT_EQ(t.precision, precision);
  EXPECT_EQ(t.price, price);
}

TEST(PlanDescentTest, DoubleAtHalfTheToleranceWhereDoubleReachesIt) {
  for (Arithmetic a : {Arithmetic::kAutomatic, Arithmetic::kDouble}) {
    for (double reach : {0.0, 1e-9, kHalf}) {
      ExpectTest(PlanDescentTest(kHalf, kThreeQuarters, reach, a), kHalf,
                 ProofPrecision::kDouble, 1.0);
    }
  }
}

// Double's reach between half and three quarters of the tolerance's shift
// (the 10^6-pose city: 0.64): a double test at the reach, priced like the
// double-double test it replaces, so the schedule is the same.
TEST(PlanDescentTest, DoubleAtItsReachUpToThreeQuartersOfTheTolerance) {
  for (Arithmetic a : {Arithmetic::kAutomatic, Arithmetic::kDouble}) {
    for (double reach : {1.0001 * kHalf, 2.5e-4, kThreeQuarters}) {
      ExpectTest(PlanDescentTest(kHalf, kThreeQuarters, reach, a), reach,
                 ProofPrecision::kDouble, 1.5);
    }
  }
}

TEST(PlanDescentTest, DoubleDoubleAtHalfBeyondDoublesReach) {
  const double reach = 1.0001 * kThreeQuarters;
  ExpectTest(
      PlanDescentTest(kHalf, kThreeQuarters, reach, Arithmetic::kAutomatic),
      kHalf, ProofPrecision::kDoubleDouble, 1.5);
  // Double only: no test can succeed there, none is run.
  EXPECT_FALSE(
      PlanDescentTest(kHalf, kThreeQuarters, reach, Arithmetic::kDouble).run);
  // Double-double only: always at half, whatever double reaches.
  for (double r : {0.0, 2.5e-4, reach}) {
    ExpectTest(
        PlanDescentTest(kHalf, kThreeQuarters, r, Arithmetic::kDoubleDouble),
        kHalf, ProofPrecision::kDoubleDouble, 1.5);
  }
}

// The paper's cube at its default noise (kappa 16.67, tau 75, pLC 0.1, s
// 10; `generate cube --side 10 --seed 33`): the relaxation is not exact
// (F(x) 4.4e-4 above F(Y)), and the rank-6 proof, within the tolerance for
// the relaxation (eta d n = 2.9e-4 F), leaves the rounded poses at 1.06e-3,
// above it. F(Y) - F(x) / (1 + tol) leaves room for a tighter proof.
PoseGraph ContinueCube() {
  CubeOptions o;
  o.side = 10;
  o.seed = 33;
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateCube(o, &graph, nullptr, &error)) << error;
  return graph;
}

// The stages without "continue": problem -> initialize -> staircase -> round
// -> report.
Solution SolveWithoutContinue(const PoseGraph& graph,
                              const SolverOptions& options,
                              SolverSummary* summary) {
  internal::Staircase staircase(graph, options, summary);
  EXPECT_TRUE(staircase.ok());
  Eigen::MatrixXd Y;
  EXPECT_TRUE(staircase.Initialize(nullptr, &Y));
  staircase.Run(&Y);
  Solution x = staircase.Round(Y);
  staircase.Report(Y, x);
  return x;
}

int CountContinuedLevels(const SolverSummary& s) {
  int count = 0;
  for (const SolverSummary::Level& level : s.levels) {
    if (level.termination.find("verified again") != std::string::npos) ++count;
  }
  return count;
}

TEST(StaircaseContinue, ProvesTheBoundTheRoundedPosesNeed) {
  const PoseGraph graph = ContinueCube();
  SolverOptions options;
  options.num_threads = 1;
  const double tol = options.certification_max_relative_bound;
  SolverSummary before;
  SolveWithoutContinue(graph, options, &before);
  // The fixture: certified relaxation, rounded poses above the tolerance,
  // with the relaxation's own gap below it.
  ASSERT_EQ(before.status, SolverSummary::Status::kBoundAboveTolerance)
      << before.FullReport();
  ASSERT_GT(before.relative_suboptimality_bound, tol);
  ASSERT_LT(before.rounding_gap, 0.9 * tol);

  SolverSummary after;
  const Poses x = Solve(graph, options, &after);
  EXPECT_EQ(after.status, SolverSummary::Status::kCertifiedOptimum)
      << after.FullReport();
  EXPECT_LE(after.relative_suboptimality_bound, tol);
  EXPECT_EQ(CountContinuedLevels(after), 1);
  // The lower bound rose; the poses are no worse (the lower of the two
  // roundings), and the bound is consistent with them.
  EXPECT_GT(after.lower_bound, before.lower_bound);
  EXPECT_LE(after.objective, before.objective * (1 + 1e-12));
  EXPECT_NEAR(EvaluateObjective(graph, x), after.objective,
              1e-12 * after.objective);
  EXPECT_LE(after.lower_bound, after.objective);
  EXPECT_NEAR(after.relative_suboptimality_bound,
              (after.objective - after.lower_bound) / after.lower_bound, 1e-9);
  // A bound on every feasible objective: none of the levels' F(Y) (each an
  // upper bound on the relaxation's optimum) is below it.
  for (const SolverSummary::Level& level : after.levels) {
    EXPECT_LE(after.lower_bound, level.sdp_value);
  }
  EXPECT_GT(after.final_rank, before.final_rank);
}

// Where the bound cannot be reached (here: the maximum rank allows no
// escape from the rank-6 point that cannot prove it), everything "continue"
// touched is restored: the same poses, bound and status as without it, and
// the level it ran is in the summary.
TEST(StaircaseContinue, RestoresTheResultWhereTheBoundIsOutOfReach) {
  const PoseGraph graph = ContinueCube();
  SolverOptions options;
  options.num_threads = 1;
  SolverSummary first;
  SolveWithoutContinue(graph, options, &first);
  ASSERT_EQ(first.status, SolverSummary::Status::kBoundAboveTolerance);
  options.max_rank = first.final_rank;
  SolverSummary before;
  const Solution x0 = SolveWithoutContinue(graph, options, &before);
  ASSERT_EQ(before.status, SolverSummary::Status::kBoundAboveTolerance);

  SolverSummary after;
  const Poses x = Solve(graph, options, &after);
  EXPECT_EQ(after.status, SolverSummary::Status::kBoundAboveTolerance)
      << after.FullReport();
  EXPECT_EQ(CountContinuedLevels(after), 1);
  EXPECT_EQ(after.final_rank, before.final_rank);
  EXPECT_EQ(after.objective, before.objective);
  EXPECT_EQ(after.lower_bound, before.lower_bound);
  EXPECT_EQ(after.eta, before.eta);
  EXPECT_EQ(after.sdp_value, before.sdp_value);
  EXPECT_EQ(after.relative_suboptimality_bound,
            before.relative_suboptimality_bound);
  ASSERT_EQ(x.size(), x0.poses.size());
  for (size_t i = 0; i < x.size(); ++i) {
    EXPECT_EQ(x[i].R, x0.poses[i].R);
    EXPECT_EQ(x[i].t, x0.poses[i].t);
  }
}

}  // namespace
}  // namespace ceres_sesync
