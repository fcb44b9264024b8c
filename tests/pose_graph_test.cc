#include "ceres_sesync/pose_graph.h"

#include <cmath>
#include <random>

#include "Eigen/Geometry"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/sesync_solver.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

TEST(PoseGraphTest, ConnectedComponentsCountsIslands) {
  PoseGraph g;
  g.dimension = 2;
  for (int v : {10, 20, 30, 40}) g.AddVertex(v);
  RelativePoseMeasurement e;
  e.R = Eigen::MatrixXd::Identity(2, 2);
  e.t = Eigen::VectorXd::Zero(2);
  e.kappa = e.tau = 1;
  e.i = 0, e.j = 1;
  g.measurements.push_back(e);
  e.i = 2, e.j = 3;
  g.measurements.push_back(e);
  std::vector<int> label;
  EXPECT_EQ(ConnectedComponents(g, &label), 2);
  EXPECT_EQ(label[0], label[1]);
  EXPECT_NE(label[1], label[2]);
  std::string error;
  EXPECT_FALSE(ValidatePoseGraph(g, &error));
  EXPECT_NE(error.find("disconnected"), std::string::npos);
  EXPECT_EQ(g.FindVertex(30), 2);
  EXPECT_EQ(g.FindVertex(31), -1);
}

// ---- landmarks and priors
// ----------------------------------------------------

PoseGraph LandmarkGraph(int d, uint64_t seed, Solution* truth,
                        bool noiseless = false) {
  test_util::RandomLandmarkGraphOptions options;
  options.poses.dimension = d;
  options.poses.num_poses = 7;
  options.poses.num_loop_closures = 2;
  options.poses.noiseless = noiseless;
  options.poses.seed = seed;
  options.num_landmarks = 6;
  options.observations_per_landmark = 3;
  options.num_position_priors = 2;
  options.num_rotation_priors = 2;
  options.num_pose_priors = 1;
  return test_util::RandomLandmarkGraph(options, truth);
}

// F(x, p) against tr(X M X^T) with the dense data matrix assembled from the
// residual definitions (tests/util/test_graphs.h), at the noisy ground truth
// and at random points.
TEST(LandmarkObjectiveTest, EqualsTheDenseQuadraticForm) {
  for (int d : {2, 3}) {
    for (uint64_t seed : {1, 2, 3}) {
      SCOPED_TRACE(testing::Message() << "d=" << d << " seed=" << seed);
      Solution truth;
      const PoseGraph g = LandmarkGraph(d, seed, &truth);
      std::string error;
      ASSERT_TRUE(ValidatePoseGraph(g, ValidationOptions(), &error)) << error;
      const Eigen::MatrixXd M = test_util::DenseLandmarkDataMatrix(g);
      std::mt19937_64 rng(seed);
      Solution random{test_util::RandomPoses(d, g.num_poses, 5, &rng), {}};
      for (int l = 0; l < g.num_landmarks; ++l) {
        random.landmarks.push_back(5 * Eigen::VectorXd::Random(d));
      }
      for (const Solution* x : {&truth, &random}) {
        const Eigen::MatrixXd X = test_util::StackLandmarkSolution(g, *x);
        const double dense = (X * M * X.transpose()).trace();
        const double f = EvaluateObjective(g, *x);
        ASSERT_GT(dense, 0);
        EXPECT_NEAR(f, dense, 1e-11 * dense);
        EXPECT_EQ(f, EvaluateObjective(g, x->poses, x->landmarks));
      }
    }
  }
}

TEST(LandmarkObjectiveTest, EachTermCounts) {
  // Moving one landmark changes F by exactly its measurements' terms, and a
  // noiseless graph has F = 0 at the truth.
  Solution truth;
  const PoseGraph g = LandmarkGraph(3, 9, &truth, /*noiseless=*/true);
  EXPECT_LT(EvaluateObjective(g, truth), 1e-20);
  Solution moved = truth;
  const Eigen::Vector3d delta(0.1, -0.2, 0.3);
  moved.landmarks[2] += delta;
  double expected = 0;
  for (const auto& m : g.landmark_measurements) {
    if (m.l == 2) expected += m.nu * delta.squaredNorm();
  }
  EXPECT_NEAR(EvaluateObjective(g, moved), expected, 1e-12 * expected);
  // A global rigid motion leaves F unchanged without priors, not with them.
  PoseGraph no_priors = g;
  no_priors.priors.clear();
  const Eigen::MatrixXd Q =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())
          .toRotationMatrix();
  const Eigen::Vector3d c(1, -1, 2);
  Solution moved_all = moved;
  for (Pose& p : moved_all.poses) {
    p.R = Q * p.R;
    p.t = Q * p.t + c;
  }
  for (Eigen::VectorXd& p : moved_all.landmarks) p = Q * p + c;
  EXPECT_NEAR(EvaluateObjective(no_priors, moved_all),
              EvaluateObjective(no_priors, moved), 1e-12);
  EXPECT_GT(EvaluateObjective(g, moved_all), EvaluateObjective(g, moved) + 1);
}

TEST(LandmarkObjectiveTest, WrongSizesGiveNaN) {
  Solution truth;
  const PoseGraph g = LandmarkGraph(2, 4, &truth);
  EXPECT_TRUE(std::isnan(EvaluateObjective(g, truth.poses)));  // No landmarks.
  Solution short_poses = truth;
  short_poses.poses.pop_back();
  EXPECT_TRUE(std::isnan(EvaluateObjective(g, short_poses)));
}

TEST(LandmarkValidationTest, AcceptsValidGraphsAndNamesEachProblem) {
  Solution truth;
  const PoseGraph good = LandmarkGraph(2, 5, &truth);
  std::string error;
  ASSERT_TRUE(ValidatePoseGraph(good, ValidationOptions(), &error)) << error;
  const struct {
    const char* name;
    void (*mutate)(PoseGraph*);
    const char* contains;
  } cases[] = {
      {"unseen landmark", [](PoseGraph* g) { g->AddLandmark(1000); },
       "landmark 1000 is not observed by any pose"},
      {"landmark index",
       [](PoseGraph* g) { g->landmark_measurements[0].l = 99; },
       "landmark index out of range"},
      {"observer index",
       [](PoseGraph* g) { g->landmark_measurements[0].i = -1; },
       "pose index out of range"},
      {"nu", [](PoseGraph* g) { g->landmark_measurements[1].nu = 0; },
       "nu must be finite and positive"},
      {"z", [](PoseGraph* g) { g->landmark_measurements[1].z(0) = NAN; },
       "not a finite d-vector"},
      {"landmark id is a pose id",
       [](PoseGraph* g) { g->landmark_ids[0] = g->vertex_ids[0]; },
       "also a pose id"},
      {"initial landmarks",
       [](PoseGraph* g) { g->initial_landmarks.resize(1); },
       "initial_landmarks must be empty or have one position per landmark"},
      {"prior without information",
       [](PoseGraph* g) { g->priors[0].kappa = g->priors[0].tau = 0; },
       "not both zero"},
      {"negative prior", [](PoseGraph* g) { g->priors[0].tau = -1; },
       "non-negative"},
      {"prior rotation",
       [](PoseGraph* g) {
         for (PosePrior& p : g->priors) {
           if (p.has_rotation()) p.R *= 2;
         }
       },
       "rotation is not in SO(d)"},
      {"prior position",
       [](PoseGraph* g) {
         for (PosePrior& p : g->priors) {
           if (p.has_position()) p.t.resize(3);
         }
       },
       "position is not a finite d-vector"},
      {"FIX with priors", [](PoseGraph* g) { g->fixed_pose = 0; },
       "fixed_pose (FIX) together with priors"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    PoseGraph bad = good;
    c.mutate(&bad);
    EXPECT_FALSE(ValidatePoseGraph(bad, ValidationOptions(), &error));
    EXPECT_NE(error.find(c.contains), std::string::npos) << error;
  }
}

// Poses 0-1 and 2-3 with no edge between them.
PoseGraph TwoIslands() {
  PoseGraph g;
  g.dimension = 2;
  for (int v : {0, 1, 2, 3}) g.AddVertex(v);
  RelativePoseMeasurement e;
  e.R = Eigen::MatrixXd::Identity(2, 2);
  e.t = Eigen::VectorXd::Ones(2);
  e.kappa = e.tau = 1;
  e.i = 0, e.j = 1;
  g.measurements.push_back(e);
  e.i = 2, e.j = 3;
  g.measurements.push_back(e);
  return g;
}

TEST(LandmarkValidationTest, ConnectivityCountsLandmarksAndPriors) {
  std::string error;
  PoseGraph g = TwoIslands();
  EXPECT_FALSE(ValidatePoseGraph(g, ValidationOptions(), &error));
  // A landmark seen from both islands connects them.
  PoseGraph linked = g;
  const int l = linked.AddLandmark(10);
  for (int i : {1, 2}) {
    linked.landmark_measurements.push_back({i, l, Eigen::Vector2d(1, 0), 1.0});
  }
  std::vector<int> label;
  EXPECT_EQ(ConnectedComponents(linked, &label), 1);
  EXPECT_EQ(label.size(), 5u);  // Four poses and one landmark.
  EXPECT_TRUE(ValidatePoseGraph(linked, ValidationOptions(), &error)) << error;
  // Landmarks seen only within each island: still two components.
  PoseGraph separate = g;
  separate.AddLandmark(10);
  separate.AddLandmark(11);
  separate.landmark_measurements.push_back({0, 0, Eigen::Vector2d(1, 0), 1.0});
  separate.landmark_measurements.push_back({3, 1, Eigen::Vector2d(1, 0), 1.0});
  EXPECT_EQ(ConnectedComponents(separate, nullptr), 2);
  EXPECT_FALSE(ValidatePoseGraph(separate, ValidationOptions(), &error));
  EXPECT_NE(error.find("disconnected"), std::string::npos) << error;
  // A prior on each island ties both to the world frame: no FIX, no edge
  // between them needed.
  PoseGraph anchored = g;
  PosePrior prior;
  prior.t = Eigen::Vector2d(0, 0);
  prior.tau = 1;
  prior.i = 0;
  anchored.priors.push_back(prior);
  EXPECT_FALSE(ValidatePoseGraph(anchored, ValidationOptions(), &error));
  // A rotation-only prior on the other island links it in rotation only:
  // its translation would be free.
  PoseGraph rotation_only = anchored;
  prior.i = 3;
  prior.R = Eigen::Matrix2d::Identity();
  prior.kappa = 2;
  prior.tau = 0;
  rotation_only.priors.push_back(prior);
  EXPECT_EQ(ConnectedComponents(rotation_only, nullptr), 1);
  EXPECT_EQ(TranslationalComponents(rotation_only, nullptr), 2);
  EXPECT_FALSE(ValidatePoseGraph(rotation_only, ValidationOptions(), &error));
  EXPECT_NE(error.find("translational terms are disconnected"),
            std::string::npos)
      << error;
  // A position (or full pose) prior does tie it.
  prior.tau = 3;
  anchored.priors.push_back(prior);
  EXPECT_EQ(TranslationalComponents(anchored, nullptr), 1);
  EXPECT_TRUE(ValidatePoseGraph(anchored, ValidationOptions(), &error))
      << error;
  // Rotation-only priors on a connected graph are fine.
  PoseGraph rotations = linked;
  prior.tau = 0;
  rotations.priors.push_back(prior);
  EXPECT_TRUE(ValidatePoseGraph(rotations, ValidationOptions(), &error))
      << error;
  EXPECT_EQ(anchored.fixed_pose, -1);
}

// The solver core does not handle landmarks and priors yet: it must refuse
// such graphs explicitly (issue #15), never ignore the extra terms.
// The solver core takes landmarks and priors (issue #15); the overloads that
// cannot carry landmark positions say so instead of ignoring them.
TEST(LandmarkValidationTest, SolverCoreAcceptsLandmarksAndPriors) {
  Solution truth;
  const PoseGraph g = LandmarkGraph(3, 6, &truth);
  ASSERT_GT(g.num_landmarks, 0);
  ASSERT_FALSE(g.priors.empty());
  std::string error;
  EXPECT_TRUE(ValidatePoseGraph(g, &error)) << error;
  SolverSummary summary;
  Solution x;
  Solve(g, SolverOptions(), &x, &summary);
  EXPECT_TRUE(summary.certified()) << summary.FullReport();
  EXPECT_EQ(static_cast<int>(x.landmarks.size()), g.num_landmarks);
  EXPECT_EQ(summary.num_landmarks, g.num_landmarks);
  EXPECT_EQ(summary.num_priors, static_cast<int>(g.priors.size()));
  Certificate certificate;
  EXPECT_TRUE(Certify(g, x, {}, &certificate, &error)) << error;
  EXPECT_TRUE(certificate.certified) << certificate.FullReport();
  EXPECT_FALSE(Certify(g, x.poses, {}, &certificate, &error));
  EXPECT_NE(error.find("landmark"), std::string::npos) << error;
  Solution chordal;
  EXPECT_TRUE(ChordalInitialization(g, &chordal, &error)) << error;
  EXPECT_EQ(static_cast<int>(chordal.landmarks.size()), g.num_landmarks);
}

}  // namespace
}  // namespace ceres_sesync
