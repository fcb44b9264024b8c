// The staircase's choice of the certificate test during a descent after an
// escape (internal::PlanDescentTest): its shift, arithmetic and schedule
// price as double's reach moves from below half the tolerance's shift to
// beyond three quarters of it, for each ProofArithmetic.

#include "ceres_sesync/internal/staircase.h"

#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

using internal::DescentTestPlan;
using internal::PlanDescentTest;
using internal::ProofPrecision;
using Arithmetic = SolverOptions::ProofArithmetic;

constexpr double kHalf = 2e-4, kThreeQuarters = 3e-4;

TEST(PlanDescentTest, DoubleAtHalfTheToleranceWhereDoubleReachesIt) {
  for (Arithmetic a : {Arithmetic::kAutomatic, Arithmetic::kDouble}) {
    for (double reach : {0.0, 1e-9, kHalf}) {
      const DescentTestPlan t =
          PlanDescentTest(kHalf, kThreeQuarters, reach, a);
      EXPECT_TRUE(t.run);
      EXPECT_EQ(t.eta, kHalf);
      EXPECT_EQ(t.precision, ProofPrecision::kDouble);
      EXPECT_EQ(t.price, 1.0);
    }
  }
}

// Double's reach between half and three quarters of the tolerance's shift
// (the 10^6-pose city: 0.64): a double test at the reach, priced like the
// double-double test it replaces, so the schedule is the same.
TEST(PlanDescentTest, DoubleAtItsReachUpToThreeQuartersOfTheTolerance) {
  for (Arithmetic a : {Arithmetic::kAutomatic, Arithmetic::kDouble}) {
    for (double reach : {1.0001 * kHalf, 2.5e-4, kThreeQuarters}) {
      const DescentTestPlan t =
          PlanDescentTest(kHalf, kThreeQuarters, reach, a);
      EXPECT_TRUE(t.run);
      EXPECT_EQ(t.eta, reach);
      EXPECT_EQ(t.precision, ProofPrecision::kDouble);
      EXPECT_EQ(t.price, 1.5);
    }
  }
}

TEST(PlanDescentTest, DoubleDoubleAtHalfBeyondDoublesReach) {
  const double reach = 1.0001 * kThreeQuarters;
  const DescentTestPlan automatic =
      PlanDescentTest(kHalf, kThreeQuarters, reach, Arithmetic::kAutomatic);
  EXPECT_TRUE(automatic.run);
  EXPECT_EQ(automatic.eta, kHalf);
  EXPECT_EQ(automatic.precision, ProofPrecision::kDoubleDouble);
  EXPECT_EQ(automatic.price, 1.5);
  // Double only: no test can succeed there, none is run.
  EXPECT_FALSE(
      PlanDescentTest(kHalf, kThreeQuarters, reach, Arithmetic::kDouble).run);
  // Double-double only: always at half, whatever double reaches.
  for (double r : {0.0, 2.5e-4, reach}) {
    const DescentTestPlan t =
        PlanDescentTest(kHalf, kThreeQuarters, r, Arithmetic::kDoubleDouble);
    EXPECT_TRUE(t.run);
    EXPECT_EQ(t.eta, kHalf);
    EXPECT_EQ(t.precision, ProofPrecision::kDoubleDouble);
    EXPECT_EQ(t.price, 1.5);
  }
}

}  // namespace
}  // namespace ceres_sesync
