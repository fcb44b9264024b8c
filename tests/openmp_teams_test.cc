// ScopedSerialOpenMpTeams (internal/openmp_teams.h): it finds the OpenMP
// runtime CHOLMOD uses, makes the teams the calling thread opens teams of one
// (checked with an OpenMP region of this test, compiled with -fopenmp against
// the same libgomp), leaves other threads alone, restores the thread's ICVs,
// and the factors CHOLMOD computes under it are bitwise those computed
// without it (its teams only scatter, so the team size cannot change them).

#include "ceres_sesync/internal/openmp_teams.h"

#include <algorithm>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "Eigen/Core"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "gtest/gtest.h"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace ceres_sesync::internal {
namespace {

// The size of a team of `asked` threads opened by the calling thread (0
// without OpenMP in this build).
int TeamSize(int asked) {
  int size = 0;
#ifdef _OPENMP
#pragma omp parallel num_threads(asked)
  {
#pragma omp single
    size = omp_get_num_threads();
  }
#else
  (void)asked;
#endif
  return size;
}

TEST(ScopedSerialOpenMpTeams, TeamsOfOneOnThisThreadOnlyAndRestored) {
  // Every program linking the library loads CHOLMOD and with it libgomp.
  ASSERT_TRUE(ScopedSerialOpenMpTeams::RuntimeLoaded());
  const bool dynamic = ScopedSerialOpenMpTeams::Dynamic();
  const int max_threads = ScopedSerialOpenMpTeams::MaxThreads();
  ASSERT_GE(max_threads, 1);
  bool other_dynamic = true;
  int other_max_threads = 0;
  {
    ScopedSerialOpenMpTeams outer;
    EXPECT_TRUE(ScopedSerialOpenMpTeams::Dynamic());
    EXPECT_EQ(ScopedSerialOpenMpTeams::MaxThreads(), 1);
#ifdef _OPENMP
    EXPECT_EQ(TeamSize(4), 1);  // As CHOLMOD's num_threads(4) regions.
#endif
    {
      ScopedSerialOpenMpTeams inner;  // Nested: restores the outer's.
    }
    EXPECT_TRUE(ScopedSerialOpenMpTeams::Dynamic());
    EXPECT_EQ(ScopedSerialOpenMpTeams::MaxThreads(), 1);
    std::thread([&] {
      other_dynamic = ScopedSerialOpenMpTeams::Dynamic();
      other_max_threads = ScopedSerialOpenMpTeams::MaxThreads();
    }).join();
  }
  EXPECT_EQ(other_dynamic, dynamic) << "dyn-var leaked to another thread";
  EXPECT_EQ(other_max_threads, max_threads);
  EXPECT_EQ(ScopedSerialOpenMpTeams::Dynamic(), dynamic);
  EXPECT_EQ(ScopedSerialOpenMpTeams::MaxThreads(), max_threads);
#ifdef _OPENMP
  // Without the guard a team of 4 gets 4 threads (oversubscribing 2 cores
  // if need be) unless OMP_DYNAMIC is set in the environment.
  if (!dynamic) {
    EXPECT_EQ(TeamSize(4), std::min(4, omp_get_thread_limit()));
  }
#endif
}

// A supernodal factorization with large supernodes (a 3D cube's rotation
// block D + I, dense enough for CHOLMOD to open its teams) gives the same
// solution to the last bit with and without the guard.
TEST(ScopedSerialOpenMpTeams, FactorIndependentOfTeams) {
  CubeOptions options;
  options.side = 9;
  options.loop_closure_radius = 1.732;
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(GenerateCube(options, &graph, nullptr, &error)) << error;
  const SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  SparseMatrix identity(problem.D().rows(), problem.D().cols());
  identity.setIdentity();
  const SparseMatrix K = problem.D() + identity;
  const int size = static_cast<int>(K.rows());
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd b(size, 3);
  for (double& x : b.reshaped()) x = normal(rng);

  auto solve = [&](bool serial) {
    CholmodFactor factor;
    ConfigureCholmod(CholmodLayout::kSupernodal, &factor);
    factor.analyzePattern(K);
    if (serial) {
      factor.factorize(K);  // CholmodFactor's: under the guard.
    } else {
      factor.Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower>::factorize(
          K);
    }
    EXPECT_EQ(factor.info(), Eigen::Success);
    return Eigen::MatrixXd(factor.solve(b));
  };
  const Eigen::MatrixXd with = solve(true), without = solve(false);
  ASSERT_EQ(with.rows(), size);
  EXPECT_TRUE(with.array().isFinite().all());
  EXPECT_TRUE((with.array() == without.array()).all())
      << "max difference " << (with - without).cwiseAbs().maxCoeff();
}

}  // namespace
}  // namespace ceres_sesync::internal
