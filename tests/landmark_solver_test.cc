// Solve, Certify and the chordal initialization on graphs with landmarks and
// priors (issue #15): exact recovery of noiseless maps (in the frame of pose
// 0 without priors, in the world frame with them), certificates on noisy
// maps whose objective an independent evaluation (Ceres's residuals, after a
// g2o round trip) reproduces and that no local search from the ground truth
// beats, the gauge fixed by priors alone, sound bounds for perturbed
// candidates, and the small cases (one pose, rotation-only priors).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "ceres/problem.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/sesync_solver.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

PoseGraph RandomGraph(int d, int n, uint64_t seed, bool noiseless,
                      int position_priors, int rotation_priors, int pose_priors,
                      Solution* truth) {
  test_util::RandomLandmarkGraphOptions o;
  o.poses.dimension = d;
  o.poses.num_poses = n;
  o.poses.num_loop_closures = n / 4;
  o.poses.noiseless = noiseless;
  o.poses.seed = seed;
  o.num_landmarks = 2 * n;
  o.observations_per_landmark = 3;
  o.num_position_priors = position_priors;
  o.num_rotation_priors = rotation_priors;
  o.num_pose_priors = pose_priors;
  return test_util::RandomLandmarkGraph(o, truth);
}

LandmarkGraphOptions Manhattan(int d, int n, uint64_t seed) {
  LandmarkGraphOptions o;
  o.dimension = d;
  o.num_poses = n;
  o.world_size = 20;
  o.num_landmarks = 150;
  o.sensor_range = 4;
  o.gps_interval = 25;
  o.start_prior = true;
  o.seed = seed;
  return o;
}

PoseGraph Generate(const LandmarkGraphOptions& o, Solution* truth) {
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(GenerateLandmarkGraph(o, &graph, truth, &error)) << error;
  return graph;
}

// x expressed in the frame of its pose 0 (the gauge of a graph without
// priors and without initial poses: pose 0 at the identity).
Solution InFrameOfPose0(const Solution& x) {
  const MatrixXd A = x.poses[0].R.transpose();
  const VectorXd c = x.poses[0].t;
  Solution y = x;
  for (Pose& p : y.poses) {
    p.R = A * p.R;
    p.t = A * (p.t - c);
  }
  for (VectorXd& p : y.landmarks) p = A * (p - c);
  return y;
}

double Distance(const Solution& a, const Solution& b) {
  EXPECT_EQ(a.poses.size(), b.poses.size());
  EXPECT_EQ(a.landmarks.size(), b.landmarks.size());
  double worst = 0;
  for (size_t i = 0; i < a.poses.size(); ++i) {
    worst = std::max({worst, (a.poses[i].R - b.poses[i].R).norm(),
                      (a.poses[i].t - b.poses[i].t).norm()});
  }
  for (size_t l = 0; l < a.landmarks.size(); ++l) {
    worst = std::max(worst, (a.landmarks[l] - b.landmarks[l]).norm());
  }
  return worst;
}

// F evaluated independently of the library's EvaluateObjective: the Ceres
// baseline's residuals (autodiff cost functors, ceres_baseline.h) at x,
// F = 2 * cost.
double CeresObjective(const PoseGraph& graph, const Solution& x) {
  CeresPoseBlocks blocks;
  std::string error;
  EXPECT_TRUE(blocks.FromSolution(graph.dimension, x, &error)) << error;
  ceres::Problem problem;
  EXPECT_TRUE(BuildCeresProblem(graph, &blocks, &problem, &error)) << error;
  double cost = 0;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr,
                   nullptr);
  return 2 * cost;
}

Solution SolveOrDie(const PoseGraph& graph, SolverSummary* summary,
                    const SolverOptions& options = {}) {
  Solution x;
  Solve(graph, options, &x, summary);
  EXPECT_EQ(x.poses.size(), static_cast<size_t>(graph.num_poses));
  EXPECT_EQ(x.landmarks.size(), static_cast<size_t>(graph.num_landmarks));
  return x;
}

// ---- noiseless maps are recovered exactly ---------------------------------

TEST(LandmarkSolve, NoiselessMapsAreRecoveredExactly) {
  for (int d : {2, 3}) {
    for (bool priors : {false, true}) {
      SCOPED_TRACE(testing::Message() << "d " << d << " priors " << priors);
      Solution truth;
      const PoseGraph graph =
          RandomGraph(d, 30, 10 + d, /*noiseless=*/true, priors ? 3 : 0,
                      priors ? 1 : 0, priors ? 1 : 0, &truth);
      SolverSummary summary;
      const Solution x = SolveOrDie(graph, &summary);
      EXPECT_TRUE(summary.certified()) << summary.FullReport();
      // Without priors: up to the gauge (pose 0 at the identity). With
      // priors: in the world frame, no gauge left. Exact data, translations
      // of size ~3: the solution is exact to the solver's precision.
      const Solution expected = priors ? truth : InFrameOfPose0(truth);
      EXPECT_LT(Distance(x, expected), 1e-7);
      EXPECT_LT(summary.objective, 1e-12 * summary.sdp_value + 1e-14);
    }
  }
  // The generated Manhattan walks: GPS priors and a start prior, 2D and 3D.
  for (int d : {2, 3}) {
    LandmarkGraphOptions o = Manhattan(d, 200, 3);
    o.noiseless = true;
    Solution truth;
    const PoseGraph graph = Generate(o, &truth);
    SolverSummary summary;
    const Solution x = SolveOrDie(graph, &summary);
    EXPECT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT(Distance(x, truth), 1e-6) << "d " << d;
  }
}

// ---- noisy maps certify; the objective is reproduced independently --------

TEST(LandmarkSolve, NoisyMapsCertifyAndTheObjectiveIsIndependent) {
  struct Case {
    std::string name;
    PoseGraph graph;
    Solution truth;
  };
  std::vector<Case> cases;
  for (int d : {2, 3}) {
    for (int priors = 0; priors < 2; ++priors) {
      Case c;
      c.name = "random d " + std::to_string(d) + (priors ? " priors" : "");
      c.graph = RandomGraph(d, 40, 20 + d + 2 * priors, false, 2 * priors,
                            priors, priors, &c.truth);
      cases.push_back(std::move(c));
    }
    Case m;
    m.name = "manhattan d " + std::to_string(d);
    m.graph = Generate(Manhattan(d, 300, 7), &m.truth);
    cases.push_back(std::move(m));
  }
  LandmarkGraphOptions victoria = VictoriaParkLikeOptions();
  victoria.num_poses = 300;
  Case v;
  v.name = "victoria-like, 300 poses";
  v.graph = Generate(victoria, &v.truth);
  cases.push_back(std::move(v));

  const std::string path = std::string(CERES_SESYNC_BINARY_DIR) +
                           "/landmark_solver_test_solution.g2o";
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    SolverSummary summary;
    const Solution x = SolveOrDie(c.graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LE(summary.relative_suboptimality_bound, 1e-6);
    EXPECT_LE(summary.lower_bound, summary.objective);
    // Written and read back with their ids: the same objective, evaluated
    // by independent code (shortest round-trip decimals; 2D angles and 3D
    // quaternions perturb rotations by ~1e-16).
    std::string error;
    ASSERT_TRUE(WriteG2oSolution(path, c.graph, x, &error)) << error;
    Solution read;
    ASSERT_TRUE(ReadG2oSolution(path, c.graph, &read, &error)) << error;
    EXPECT_LT(Distance(read, x), 1e-12);
    const double f = CeresObjective(c.graph, read);
    EXPECT_NEAR(f, summary.objective, 1e-9 * summary.objective);
    // Certified optimal: local search from the ground truth cannot do
    // better (up to Ceres's tolerance it finds the same minimum), and its
    // answer certifies too.
    Solution from_truth;
    CeresBaselineOptions ceres_options;
    ceres_options.function_tolerance = 1e-12;
    ASSERT_TRUE(SolveWithCeres(c.graph, c.truth, ceres_options, &from_truth,
                               nullptr, &error))
        << error;
    const double f_ceres = CeresObjective(c.graph, from_truth);
    EXPECT_GE(f_ceres, summary.lower_bound);
    EXPECT_LE(summary.objective, f_ceres * (1 + 1e-9));
    Certificate certificate;
    ASSERT_TRUE(Certify(c.graph, from_truth, {}, &certificate, &error))
        << error;
    EXPECT_TRUE(certificate.certified) << certificate.FullReport();
    // SE-Sync's landmarks are optimal for its poses: Ceres started there
    // does not move them.
    Solution polished;
    ASSERT_TRUE(
        SolveWithCeres(c.graph, x, ceres_options, &polished, nullptr, &error))
        << error;
    EXPECT_LT(Distance(polished, x), 1e-5);
    EXPECT_GE(CeresObjective(c.graph, polished),
              summary.objective * (1 - 1e-9));
  }
  std::remove(path.c_str());
}

// ---- priors fix the gauge --------------------------------------------------

// With priors there is no gauge left (no FIX needed): solutions from
// different initializations, and from initial poses in an arbitrary frame,
// are the same absolute poses and landmarks, and the same as Ceres's (which
// holds nothing constant with position priors).
TEST(LandmarkSolve, PriorsAloneFixTheGauge) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph graph = RandomGraph(d, 25, 40 + d, false, 3, 1, 0, &truth);
    ASSERT_EQ(graph.fixed_pose, -1);
    SolverSummary summary;
    const Solution chordal = SolveOrDie(graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    // The priors put the map near its true place (3 m scale, noise ~0.1).
    EXPECT_LT(Distance(chordal, truth), 1.0);
    SolverOptions random;
    random.initialization = SolverOptions::Initialization::kRandom;
    for (uint64_t seed : {1, 2}) {
      random.seed = seed;
      const Solution x = SolveOrDie(graph, &summary, random);
      ASSERT_TRUE(summary.certified()) << summary.FullReport();
      EXPECT_LT(Distance(x, chordal), 1e-6) << "seed " << seed;
    }
    // Initial poses moved by a rigid motion far from the world frame.
    std::mt19937_64 rng(5);
    const MatrixXd G = test_util::RandomRotation(d, &rng);
    Poses moved = truth.poses;
    for (Pose& p : moved) {
      p.R = G * p.R;
      p.t = G * p.t + VectorXd::Constant(d, 100.0);
    }
    Solution x;
    Solve(graph, moved, SolverOptions(), &x, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT(Distance(x, chordal), 1e-6);
    Solution ceres;
    std::string error;
    CeresBaselineOptions ceres_options;
    ceres_options.function_tolerance = 1e-14;
    ceres_options.gradient_tolerance = 1e-14;
    ASSERT_TRUE(
        SolveWithCeres(graph, truth, ceres_options, &ceres, nullptr, &error))
        << error;
    EXPECT_LT(Distance(ceres, chordal), 1e-5);
  }
}

// Position-only priors (GPS) leave nothing of the gauge either; rotation-only
// priors fix the rotations, and the translations are then placed with pose 0
// at the origin (no initial poses) or at its initial position.
TEST(LandmarkSolve, PositionOnlyAndRotationOnlyPriors) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph gps = RandomGraph(d, 20, 60 + d, true, 4, 0, 0, &truth);
    SolverSummary summary;
    Solution x = SolveOrDie(gps, &summary);
    EXPECT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT(Distance(x, truth), 1e-7);

    PoseGraph rotations = RandomGraph(d, 20, 70 + d, true, 0, 2, 0, &truth);
    x = SolveOrDie(rotations, &summary);
    EXPECT_TRUE(summary.certified()) << summary.FullReport();
    Solution expected = truth;  // Rotations absolute, pose 0 at the origin.
    for (Pose& p : expected.poses) p.t -= truth.poses[0].t;
    for (VectorXd& p : expected.landmarks) p -= truth.poses[0].t;
    EXPECT_LT(Distance(x, expected), 1e-7);
    rotations.initial_poses = truth.poses;
    x = SolveOrDie(rotations, &summary);
    EXPECT_LT(Distance(x, truth), 1e-7);
  }
}

// ---- Certify ------------------------------------------------------------

TEST(LandmarkCertify, PerturbedCandidatesGetSoundBoundsAndImprove) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph graph = Generate(Manhattan(d, 200, 11), &truth);
    SolverSummary summary;
    const Solution x = SolveOrDie(graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    Certificate certificate;
    std::string error;
    ASSERT_TRUE(Certify(graph, x, {}, &certificate, &error)) << error;
    EXPECT_TRUE(certificate.certified);
    EXPECT_NEAR(certificate.objective, summary.objective,
                1e-12 * summary.objective);
    EXPECT_LE(certificate.lower_bound, summary.objective);

    // One landmark 1 m off: F grows by ~nu * observations; the optimum is
    // known (x), so the bound must cover the true gap.
    Solution moved = x;
    moved.landmarks[3] += VectorXd::Constant(d, 1.0);
    CertifyOptions improve;
    improve.improve_if_not_certified = true;
    ASSERT_TRUE(Certify(graph, moved, improve, &certificate, &error)) << error;
    const double f_moved = EvaluateObjective(graph, moved);
    EXPECT_FALSE(certificate.certified) << certificate.FullReport();
    EXPECT_LE(certificate.lower_bound, summary.objective);
    EXPECT_GE(certificate.suboptimality_bound, f_moved - summary.objective);
    ASSERT_TRUE(certificate.has_improved_poses);
    EXPECT_TRUE(certificate.improvement_summary.certified());
    const Solution improved{certificate.improved_poses,
                            certificate.improved_landmarks};
    EXPECT_LT(Distance(improved, x), 1e-6);

    // A rotation turned by 0.5 rad: the rotations themselves are not
    // optimal; a witness of negative curvature or a loose bound.
    Solution turned = x;
    const MatrixXd turn =
        d == 2 ? MatrixXd(Eigen::Rotation2Dd(0.5).toRotationMatrix())
               : MatrixXd(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())
                              .toRotationMatrix());
    for (int i = 50; i < 100; ++i) turned.poses[i].R = turned.poses[i].R * turn;
    ASSERT_TRUE(Certify(graph, turned, {}, &certificate, &error)) << error;
    EXPECT_FALSE(certificate.certified);
    EXPECT_LE(certificate.lower_bound, summary.objective);

    // Wrong candidates: a message, no certificate.
    Solution missing = x;
    missing.landmarks.pop_back();
    EXPECT_FALSE(Certify(graph, missing, {}, &certificate, &error));
    EXPECT_NE(error.find("landmark"), std::string::npos) << error;
    EXPECT_FALSE(Certify(graph, x.poses, {}, &certificate, &error));
    EXPECT_NE(error.find("landmarks"), std::string::npos) << error;
    Solution nan = x;
    nan.landmarks[0](0) = std::nan("");
    EXPECT_FALSE(Certify(graph, nan, {}, &certificate, &error));
  }
}

// ---- small cases -----------------------------------------------------------

// One pose observing landmarks (no priors): the pose is the gauge, each
// landmark sits at the nu-weighted mean of its measurements.
TEST(LandmarkSolve, SinglePoseObservingLandmarks) {
  for (int d : {2, 3}) {
    PoseGraph graph;
    graph.dimension = d;
    graph.AddVertex(7);
    std::mt19937_64 rng(d);
    std::normal_distribution<double> normal;
    std::vector<VectorXd> weighted(3, VectorXd::Zero(d));
    std::vector<double> weight(3, 0);
    for (int l = 0; l < 3; ++l) graph.AddLandmark(100 + l);
    for (int k = 0; k < 7; ++k) {
      LandmarkMeasurement m;
      m.l = k % 3;
      m.z = VectorXd(d);
      for (int a = 0; a < d; ++a) m.z(a) = 3 * normal(rng);
      m.nu = 1 + k;
      weighted[m.l] += m.nu * m.z;
      weight[m.l] += m.nu;
      graph.landmark_measurements.push_back(m);
    }
    SolverSummary summary;
    const Solution x = SolveOrDie(graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT((x.poses[0].R - MatrixXd::Identity(d, d)).norm(), 1e-14);
    EXPECT_LT(x.poses[0].t.norm(), 1e-14);
    for (int l = 0; l < 3; ++l) {
      EXPECT_LT((x.landmarks[l] - weighted[l] / weight[l]).norm(), 1e-12);
    }
  }
}

// One pose with priors only: two full pose priors (the optimum is the
// weighted mean position and the projected weighted sum of rotations), and a
// rotation-only prior (no translation term at all).
TEST(LandmarkSolve, SinglePoseWithPriors) {
  for (int d : {2, 3}) {
    std::mt19937_64 rng(d + 10);
    PoseGraph graph;
    graph.dimension = d;
    graph.AddVertex(0);
    MatrixXd weighted_rotation = MatrixXd::Zero(d, d);
    VectorXd weighted_position = VectorXd::Zero(d);
    double tau_sum = 0;
    for (double w : {2.0, 5.0}) {
      PosePrior p;
      p.R = test_util::RandomRotation(d, &rng);
      p.t = VectorXd::Random(d);
      p.kappa = w;
      p.tau = 3 * w;
      weighted_rotation += p.kappa * p.R;
      weighted_position += p.tau * p.t;
      tau_sum += p.tau;
      graph.priors.push_back(p);
    }
    SolverSummary summary;
    Solution x = SolveOrDie(graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT((x.poses[0].t - weighted_position / tau_sum).norm(), 1e-12);
    // argmin sum kappa ||R - R_k||^2 = argmax tr(R^T sum kappa R_k).
    Eigen::JacobiSVD<MatrixXd> svd(weighted_rotation,
                                   Eigen::ComputeFullU | Eigen::ComputeFullV);
    MatrixXd S = MatrixXd::Identity(d, d);
    S(d - 1, d - 1) =
        (svd.matrixU() * svd.matrixV().transpose()).determinant() > 0 ? 1 : -1;
    const MatrixXd best = svd.matrixU() * S * svd.matrixV().transpose();
    EXPECT_LT((x.poses[0].R - best).norm(), 1e-8);

    graph.priors.resize(1);
    graph.priors[0].tau = 0;
    x = SolveOrDie(graph, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT((x.poses[0].R - graph.priors[0].R).norm(), 1e-8);
    EXPECT_LT(x.poses[0].t.norm(), 1e-14);
  }
}

// ---- chordal initialization -------------------------------------------------

// The rotation graph is disconnected where the problem is not: the world
// block with GPS priors only, and two trajectories tied together only by
// the landmarks they both see. Each part is estimated on its own and
// rotated into place (internal/chordal.h); on exact data that is exact.
TEST(LandmarkChordal, ComponentsTiedByTranslationsAreAligned) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    Solution truth;
    const PoseGraph gps = RandomGraph(d, 20, 80 + d, true, 4, 0, 0, &truth);
    Solution chordal;
    std::string error;
    ASSERT_TRUE(ChordalInitialization(gps, &chordal, &error)) << error;
    EXPECT_LT(Distance(chordal, truth), 1e-8);

    // Two chains of 6 poses, no edge between them, 12 landmarks each seen by
    // one pose of each chain.
    PoseGraph two;
    two.dimension = d;
    std::mt19937_64 rng(90 + d);
    Solution x;
    x.poses = test_util::RandomPoses(d, 12, 3, &rng);
    for (int i = 0; i < 12; ++i) two.AddVertex(i);
    for (int i = 0; i < 12; ++i) {
      if (i % 6 == 0) continue;
      RelativePoseMeasurement e;
      e.i = i - 1;
      e.j = i;
      e.R = x.poses[i - 1].R.transpose() * x.poses[i].R;
      e.t = x.poses[i - 1].R.transpose() * (x.poses[i].t - x.poses[i - 1].t);
      e.kappa = e.tau = 10;
      two.measurements.push_back(e);
    }
    for (int l = 0; l < 12; ++l) {
      two.AddLandmark(100 + l);
      VectorXd p(d);
      for (int a = 0; a < d; ++a)
        p(a) = std::uniform_real_distribution<>(-3, 3)(rng);
      x.landmarks.push_back(p);
      for (int i : {l % 6, 6 + (l * 5) % 6}) {
        LandmarkMeasurement m;
        m.i = i;
        m.l = l;
        m.z = x.poses[i].R.transpose() * (p - x.poses[i].t);
        m.nu = 5;
        two.landmark_measurements.push_back(m);
      }
    }
    ASSERT_TRUE(ValidatePoseGraph(two, &error)) << error;
    ASSERT_TRUE(ChordalInitialization(two, &chordal, &error)) << error;
    EXPECT_LT(Distance(chordal, InFrameOfPose0(x)), 1e-8);
    SolverSummary summary;
    const Solution solved = SolveOrDie(two, &summary);
    EXPECT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_LT(Distance(solved, InFrameOfPose0(x)), 1e-7);
  }
}

}  // namespace
}  // namespace ceres_sesync
