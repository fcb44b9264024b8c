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

}  // namespace
}  // namespace ceres_sesync
