// The Ceres LBFGS local solver option reaches the same certified optimum as
// the built-in trust-region method.

#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/sesync_solver.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

TEST(CeresLocalSolverTest, MatchesTrustRegionOnCubes) {
  for (int d : {2, 3}) {
    CubeOptions cube;
    cube.dimension = d;
    cube.side = d == 2 ? 8 : 4;
    cube.seed = 3;
    PoseGraph graph;
    Poses truth;
    std::string error;
    ASSERT_TRUE(GenerateCube(cube, &graph, &truth, &error)) << error;

    SolverOptions options;
    SolverSummary rtr;
    Solve(graph, options, &rtr);
    options.local_solver = SolverOptions::LocalSolver::kCeresLbfgs;
    SolverSummary lbfgs;
    Solve(graph, options, &lbfgs);
    ASSERT_EQ(rtr.status, SolverSummary::Status::kCertifiedOptimum)
        << rtr.FullReport();
    EXPECT_EQ(lbfgs.status, SolverSummary::Status::kCertifiedOptimum)
        << lbfgs.FullReport();
    // Both are certified optima of the same problem: equal objectives up to
    // the solvers' stopping precision (relative decrease 1e-12).
    EXPECT_NEAR(lbfgs.objective, rtr.objective, 1e-8 * rtr.objective);
    EXPECT_NE(lbfgs.levels.front().termination.find("ceres LBFGS"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace ceres_sesync
