// Weighted problems (internal/measurement_weights.h): the data matrices,
// their rounding bounds, the objective and its bound, re-weighting in place,
// and the certificate, against
//  - the graph with kappa and tau scaled by the weights, built DENSELY from
//    first principles (tests/util/test_graphs.h), and
//  - for weights in {0, 1}, the graph of the weight-1 measurements alone
//    (whose certificate the weighted one must equal).

#include "ceres_sesync/internal/measurement_weights.h"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/objective_bound.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/staircase.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/sesync_solver.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Eigen::MatrixXd;
using internal::CertificateMatrix;
using internal::MeasurementWeights;
using internal::SESyncProblem;
using internal::SparseMatrix;
using test_util::RandomGraphOptions;

// A noisy graph whose chain 0-1-...-(n-1) keeps positive weights (so the
// weighted problems stay connected) and whose other measurements get
// weights in [0, 1], about a third of them exactly 0.
struct WeightedCase {
  PoseGraph graph;
  MeasurementWeights weights;
};

WeightedCase MakeCase(int d, uint64_t seed, bool binary) {
  RandomGraphOptions o;
  o.dimension = d;
  o.num_poses = 14;
  o.num_loop_closures = 25;
  o.chain = true;
  o.kappa = 40;
  o.tau = 7;
  o.seed = seed;
  WeightedCase c;
  c.graph = test_util::RandomPoseGraph(o, nullptr);
  std::mt19937_64 rng(seed + 100);
  std::uniform_real_distribution<double> uniform(0, 1);
  for (const RelativePoseMeasurement& e : c.graph.measurements) {
    const bool chain = std::abs(e.i - e.j) == 1;
    const double u = uniform(rng);
    double w = u < 1.0 / 3 ? 0.0 : uniform(rng);
    if (binary) w = u < 1.0 / 3 ? 0.0 : 1.0;
    c.weights.push_back(chain ? std::max(w, 0.25) : w);
    if (binary && chain) c.weights.back() = 1;
  }
  return c;
}

// kappa and tau replaced by the weighted problem's precisions.
PoseGraph Scaled(const PoseGraph& graph, const MeasurementWeights& w) {
  PoseGraph scaled = graph;
  for (size_t k = 0; k < scaled.measurements.size(); ++k) {
    scaled.measurements[k].kappa = w[k] * graph.measurements[k].kappa;
    scaled.measurements[k].tau = w[k] * graph.measurements[k].tau;
  }
  return scaled;
}

// The measurements of weight 1 alone (weights in {0, 1}).
PoseGraph Inliers(const PoseGraph& graph, const MeasurementWeights& w) {
  PoseGraph inliers = graph;
  inliers.measurements.clear();
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    if (w[k] == 1) inliers.measurements.push_back(graph.measurements[k]);
  }
  return inliers;
}

MatrixXd Dense(const SparseMatrix& A) { return MatrixXd(A); }

bool SamePattern(const SparseMatrix& a, const SparseMatrix& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols() ||
      a.nonZeros() != b.nonZeros()) {
    return false;
  }
  for (int k = 0; k <= a.outerSize(); ++k) {
    if (a.outerIndexPtr()[k] != b.outerIndexPtr()[k]) return false;
  }
  for (int k = 0; k < a.nonZeros(); ++k) {
    if (a.innerIndexPtr()[k] != b.innerIndexPtr()[k]) return false;
  }
  return true;
}

// The weighted matrices are those of the graph with kappa and tau scaled:
// M = [L(W^tau) -V; -V^T D] built densely, Q as its Schur complement.
TEST(MeasurementWeights, MatricesEqualThoseOfTheScaledGraph) {
  std::mt19937_64 rng(3);
  for (int d : {2, 3}) {
    for (uint64_t seed : {1, 2, 3}) {
      const WeightedCase c = MakeCase(d, seed, /*binary=*/false);
      ASSERT_TRUE(
          internal::CheckMeasurementWeights(c.graph, c.weights, nullptr));
      const PoseGraph scaled = Scaled(c.graph, c.weights);
      SESyncProblem problem(c.graph, 1, c.weights);
      ASSERT_TRUE(problem.ok());
      const int n = c.graph.num_poses;
      const MatrixXd M = test_util::DenseDataMatrix(scaled);
      const double scale = M.norm();
      // Sums of a few rounded terms each: 1e-13 of the scale.
      EXPECT_LT((Dense(problem.D()) - M.bottomRightCorner(d * n, d * n)).norm(),
                1e-13 * scale);
      EXPECT_LT((Dense(problem.Vbar()) + M.block(1, n, n - 1, d * n)).norm(),
                1e-13 * scale);
      EXPECT_LT((MatrixXd(Dense(problem.Lbar())) - M.block(1, 1, n - 1, n - 1))
                    .norm(),
                1e-13 * scale);
      const MatrixXd Q = test_util::DenseQ(scaled);
      std::normal_distribution<double> normal;
      MatrixXd Y(d + 2, d * n);
      for (int k = 0; k < Y.size(); ++k) Y.data()[k] = normal(rng);
      MatrixXd YQ;
      problem.MultiplyQ(Y, &YQ);
      // One solve with Lbar (condition <= ~1e4 here): 1e-10.
      EXPECT_LT((YQ - Y * Q).norm(), 1e-10 * (Y * Q).norm());
    }
  }
}

// UpdateWeights: the patterns never change (zero weights keep explicit
// zeros) and the values are bitwise those of a fresh construction.
TEST(MeasurementWeights, UpdateWeightsKeepsPatternsAndMatchesFreshProblem) {
  for (int d : {2, 3}) {
    const WeightedCase a = MakeCase(d, 7, false);
    const PoseGraph& graph = a.graph;
    // Other weights (another case's, same count), other zeros.
    MeasurementWeights w2 = MakeCase(d, 8, false).weights;
    ASSERT_EQ(w2.size(), graph.measurements.size());
    for (size_t k = 0; k < w2.size(); ++k) {
      const RelativePoseMeasurement& e = graph.measurements[k];
      if (std::abs(e.i - e.j) == 1) w2[k] = std::max(w2[k], 0.5);
    }
    ASSERT_TRUE(internal::CheckMeasurementWeights(graph, w2, nullptr));
    SESyncProblem unweighted(graph);
    SESyncProblem updated(graph, 1, a.weights);
    ASSERT_TRUE(updated.UpdateWeights(w2));
    const SESyncProblem fresh(graph, 1, w2);
    ASSERT_TRUE(fresh.ok());
    for (auto member :
         {&SESyncProblem::D, &SESyncProblem::Vbar, &SESyncProblem::Lbar,
          &SESyncProblem::RotationLaplacian}) {
      const SparseMatrix& u = (updated.*member)();
      const SparseMatrix& f = (fresh.*member)();
      EXPECT_TRUE(SamePattern(u, (unweighted.*member)()));
      EXPECT_TRUE(SamePattern(u, f));
      EXPECT_EQ(Dense(u), Dense(f));
    }
    EXPECT_EQ(updated.translation_row_rounding(),
              fresh.translation_row_rounding());
    EXPECT_EQ(updated.rotation_row_rounding(), fresh.rotation_row_rounding());
    EXPECT_EQ(updated.vertex_ordering(), unweighted.vertex_ordering());
    EXPECT_EQ(updated.weights(), w2);
  }
}

// The objective and its rigorous bound are those of the scaled graph.
TEST(MeasurementWeights, ObjectiveAndBoundAreThoseOfTheScaledGraph) {
  std::mt19937_64 rng(5);
  for (int d : {2, 3}) {
    const WeightedCase c = MakeCase(d, 11, false);
    const PoseGraph scaled = Scaled(c.graph, c.weights);
    const Poses poses = test_util::RandomPoses(d, c.graph.num_poses, 2.0, &rng);
    EXPECT_EQ(internal::WeightedObjective(c.graph, c.weights, poses),
              EvaluateObjective(scaled, poses));
    EXPECT_EQ(internal::WeightedObjective(c.graph, {}, poses),
              EvaluateObjective(c.graph, poses));
    EXPECT_EQ(internal::ObjectiveUpperBound(c.graph, poses, {}, c.weights),
              internal::ObjectiveUpperBound(scaled, poses));
    EXPECT_GE(internal::ObjectiveUpperBound(c.graph, poses, {}, c.weights),
              EvaluateObjective(scaled, poses));
  }
}

// Weights in {0, 1}: the matrices (values), the rounding bounds and the
// certificate are those of the graph of the weight-1 measurements.
TEST(MeasurementWeights, BinaryWeightsGiveTheInlierGraphsCertificate) {
  for (int d : {2, 3}) {
    const WeightedCase c = MakeCase(d, 21, /*binary=*/true);
    const PoseGraph inliers = Inliers(c.graph, c.weights);
    ASSERT_LT(inliers.measurements.size(), c.graph.measurements.size());
    ASSERT_TRUE(ValidatePoseGraph(inliers, nullptr));
    const SESyncProblem weighted(c.graph, 1, c.weights);
    const SESyncProblem reference(inliers);
    ASSERT_TRUE(weighted.ok() && reference.ok());
    // Zero-weight terms are exact zeros: the sums are bitwise the same.
    EXPECT_EQ(Dense(weighted.D()), Dense(reference.D()));
    EXPECT_EQ(Dense(weighted.Vbar()), Dense(reference.Vbar()));
    EXPECT_EQ(Dense(weighted.Lbar()), Dense(reference.Lbar()));
    EXPECT_EQ(weighted.translation_row_rounding(),
              reference.translation_row_rounding());
    EXPECT_EQ(weighted.rotation_row_rounding(),
              reference.rotation_row_rounding());

    // Solve the inlier graph; then prove the same shift for the
    // multipliers at its optimum in both problems, in both arithmetics.
    SolverOptions options;
    options.num_threads = 1;
    SolverSummary summary;
    const Poses optimum = Solve(inliers, options, &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    const MatrixXd R = test_util::StackRotations(optimum);
    MatrixXd RQ_w, RQ_r;
    weighted.MultiplyQ(R, &RQ_w);
    reference.MultiplyQ(R, &RQ_r);
    const MatrixXd Lambda_w = SymBlockDiagProduct(RQ_w, R, d);
    const MatrixXd Lambda_r = SymBlockDiagProduct(RQ_r, R, d);
    // Different fill (the zero-weight entries) changes only round-off.
    EXPECT_LT((Lambda_w - Lambda_r).norm(), 1e-11 * Lambda_r.norm());
    const double scale = Dense(reference.D()).diagonal().maxCoeff();
    // S = Q - Lambda of the inlier graph, densely: lambda_min = 0 at the
    // optimum (R spans its kernel). Below it no proof may succeed; the
    // graph with every measurement would allow one there (its outlier
    // terms add a positive semidefinite part), so this also checks that
    // the double-double assembly is weighted.
    const MatrixXd S_in = test_util::DenseQ(inliers) -
                          test_util::BlockDiagonalToDense(Lambda_r, d);
    const MatrixXd S_all = test_util::DenseQ(c.graph) -
                           test_util::BlockDiagonalToDense(Lambda_r, d);
    const double c_bad = -1e-4 * scale;
    ASSERT_LT(test_util::DenseMinEigenvalue(S_in), 1e-9 * scale);
    ASSERT_GT(test_util::DenseMinEigenvalue(S_all), -c_bad);
    for (auto precision : {internal::ProofPrecision::kDouble,
                           internal::ProofPrecision::kDoubleDouble}) {
      CertificateMatrix K_w(weighted), K_r(reference);
      const double c0 = 1e-8 * scale;
      ASSERT_TRUE(K_w.Prove(Lambda_r, c0, precision));
      ASSERT_TRUE(K_r.Prove(Lambda_r, c0, precision));
      // eta = c + the backward-error allowance (~1e-13 of the scale in
      // double): equal up to that allowance.
      EXPECT_NEAR(K_w.proven_shift(), K_r.proven_shift(), 1e-11 * scale);
      EXPECT_FALSE(K_w.Prove(Lambda_r, c_bad, precision));
      EXPECT_FALSE(K_r.Prove(Lambda_r, c_bad, precision));
    }

    // The staircase on the weighted problem reaches the inlier graph's
    // certified optimum.
    SolverSummary weighted_summary;
    internal::Staircase staircase(c.graph, options, &weighted_summary,
                                  internal::Staircase::Clock::now(), c.weights);
    ASSERT_TRUE(staircase.ok());
    Eigen::MatrixXd Y;
    ASSERT_TRUE(staircase.Initialize(nullptr, &Y));
    staircase.Run(&Y);
    const Solution solution_poses = staircase.Round(Y);
    const Poses& poses = solution_poses.poses;
    staircase.Report(Y, solution_poses);
    EXPECT_TRUE(weighted_summary.certified()) << weighted_summary.FullReport();
    EXPECT_EQ(weighted_summary.num_measurements,
              static_cast<int>(inliers.measurements.size()));
    EXPECT_NEAR(weighted_summary.objective, summary.objective,
                1e-10 * summary.objective);
    EXPECT_NEAR(weighted_summary.lower_bound, summary.lower_bound,
                1e-8 * summary.objective);
    EXPECT_LT(test_util::GaugeInvariantPoseDistance(poses, optimum), 1e-7);
  }
}

// Staircase::Reweight gives bitwise the solve of a Staircase built with the
// new weights (symbolic analyses reused, values and shifts refreshed).
TEST(MeasurementWeights, ReweightedStaircaseEqualsFreshStaircase) {
  for (int d : {2, 3}) {
    const WeightedCase a = MakeCase(d, 31, false);
    MeasurementWeights w2 = a.weights;
    for (double& w : w2) w = w > 0 ? 1 - 0.5 * w : 0;  // Same zeros.
    SolverOptions options;
    options.num_threads = 1;
    SolverSummary first, second;
    internal::Staircase reused(a.graph, options, &first,
                               internal::Staircase::Clock::now(), a.weights);
    ASSERT_TRUE(reused.ok());
    Eigen::MatrixXd Y;
    ASSERT_TRUE(reused.Initialize(nullptr, &Y));
    reused.Run(&Y);
    ASSERT_TRUE(reused.Reweight(w2));
    EXPECT_EQ(reused.problem().weights(), w2);
    Eigen::MatrixXd Y_reused = Y, Y_fresh = Y;
    reused.Run(&Y_reused);
    const Solution solution_p_reused = reused.Round(Y_reused);
    const Poses& p_reused = solution_p_reused.poses;
    reused.Report(Y_reused, solution_p_reused);
    internal::Staircase fresh(a.graph, options, &second,
                              internal::Staircase::Clock::now(), w2);
    ASSERT_TRUE(fresh.ok());
    fresh.Run(&Y_fresh);
    const Solution solution_p_fresh = fresh.Round(Y_fresh);
    const Poses& p_fresh = solution_p_fresh.poses;
    fresh.Report(Y_fresh, solution_p_fresh);
    // `first` now holds the reused staircase's second solve.
    EXPECT_EQ(Y_reused, Y_fresh);
    EXPECT_EQ(first.objective, second.objective);
    EXPECT_EQ(first.lower_bound, second.lower_bound);
    EXPECT_EQ(second.objective,
              internal::WeightedObjective(a.graph, w2, p_fresh));
    EXPECT_TRUE(first.certified()) << first.FullReport();
    ASSERT_EQ(p_reused.size(), p_fresh.size());
    for (size_t i = 0; i < p_fresh.size(); ++i) {
      EXPECT_EQ(p_reused[i].R, p_fresh[i].R);
      EXPECT_EQ(p_reused[i].t, p_fresh[i].t);
    }
    EXPECT_TRUE(second.certified()) << second.FullReport();
  }
}

// Weights that leave the positively weighted graph disconnected (or are
// malformed) are rejected with a message, never factorized.
TEST(MeasurementWeights, DisconnectingOrInvalidWeightsAreRejected) {
  const WeightedCase c = MakeCase(3, 41, false);
  const int isolated = 5;
  MeasurementWeights w(c.graph.measurements.size(), 1.0);
  for (size_t k = 0; k < w.size(); ++k) {
    const RelativePoseMeasurement& e = c.graph.measurements[k];
    if (e.i == isolated || e.j == isolated) w[k] = 0;
  }
  std::string error;
  EXPECT_FALSE(internal::CheckMeasurementWeights(c.graph, w, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("2 components"));
  EXPECT_THAT(error, ::testing::HasSubstr("pose 5 "));

  SolverOptions options;
  SolverSummary summary;
  internal::Staircase rejected(c.graph, options, &summary,
                               internal::Staircase::Clock::now(), w);
  EXPECT_FALSE(rejected.ok());
  EXPECT_EQ(summary.status, SolverSummary::Status::kInvalidInput);
  EXPECT_THAT(summary.message, ::testing::HasSubstr("components"));

  internal::Staircase staircase(c.graph, options, &summary);
  ASSERT_TRUE(staircase.ok());
  EXPECT_FALSE(staircase.Reweight(w));
  EXPECT_FALSE(staircase.ok());
  EXPECT_EQ(summary.status, SolverSummary::Status::kInvalidInput);
  EXPECT_TRUE(staircase.Reweight(c.weights));  // Usable again.
  EXPECT_TRUE(staircase.ok());

  MeasurementWeights bad = c.weights;
  bad[3] = -1;
  EXPECT_FALSE(internal::CheckMeasurementWeights(c.graph, bad, &error));
  bad[3] = std::nan("");
  EXPECT_FALSE(internal::CheckMeasurementWeights(c.graph, bad, &error));
  bad.pop_back();
  EXPECT_FALSE(internal::CheckMeasurementWeights(c.graph, bad, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("weights for"));
}

// A landmark graph with GPS-like position priors and a start prior, and
// weights for every term: odometry in [0.25, 1], landmark measurements and
// priors in [0, 1] with about a third of them 0 (binary: {0, 1}) where the
// graph stays connected (every landmark keeps its first observation, pose 0
// its start prior).
WeightedCase MakeLandmarkCase(int d, uint64_t seed, bool binary) {
  LandmarkGraphOptions o;
  o.dimension = d;
  o.num_poses = 24;
  o.num_landmarks = d == 2 ? 20 : 30;
  o.world_size = 12;
  o.block_length = 3;
  o.gps_interval = 4;
  o.start_prior = true;
  o.seed = seed;
  WeightedCase c;
  std::string error;
  EXPECT_TRUE(GenerateLandmarkGraph(o, &c.graph, nullptr, &error)) << error;
  std::mt19937_64 rng(seed + 200);
  std::uniform_real_distribution<double> uniform(0, 1);
  auto draw = [&](bool keep) {
    const double u = uniform(rng);
    double w = u < 1.0 / 3 ? 0.0 : (binary ? 1.0 : uniform(rng));
    if (keep) w = binary ? 1.0 : std::max(w, 0.25);
    return w;
  };
  for (size_t k = 0; k < c.graph.measurements.size(); ++k) {
    c.weights.push_back(draw(true));  // Odometry: connected.
  }
  std::vector<char> seen(c.graph.num_landmarks, 0);
  for (const LandmarkMeasurement& o : c.graph.landmark_measurements) {
    c.weights.push_back(draw(!seen[o.l]));
    seen[o.l] = 1;
  }
  for (const PosePrior& p : c.graph.priors) {
    c.weights.push_back(draw(p.has_rotation()));  // The start prior.
  }
  return c;
}

// nu, kappa and tau of every term replaced by the weighted precisions
// (weights > 0: a term of precision 0 is not a valid term).
PoseGraph ScaledAll(const PoseGraph& graph, const MeasurementWeights& w) {
  PoseGraph scaled = Scaled(graph, w);
  for (size_t q = 0; q < scaled.landmark_measurements.size(); ++q) {
    scaled.landmark_measurements[q].nu *= w[internal::LandmarkTerm(graph, q)];
  }
  for (size_t q = 0; q < scaled.priors.size(); ++q) {
    scaled.priors[q].kappa *= w[internal::PriorTerm(graph, q)];
    scaled.priors[q].tau *= w[internal::PriorTerm(graph, q)];
  }
  return scaled;
}

// The terms of weight 1 alone (weights in {0, 1}).
PoseGraph InlierTerms(const PoseGraph& graph, const MeasurementWeights& w) {
  PoseGraph inliers = Inliers(graph, w);
  inliers.landmark_measurements.clear();
  inliers.priors.clear();
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    if (w[internal::LandmarkTerm(graph, q)] == 1) {
      inliers.landmark_measurements.push_back(graph.landmark_measurements[q]);
    }
  }
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    if (w[internal::PriorTerm(graph, q)] == 1) {
      inliers.priors.push_back(graph.priors[q]);
    }
  }
  return inliers;
}

// Weights reach the landmark measurements and the priors: the matrices,
// objective and bound are bitwise those of the graph with those precisions
// scaled.
TEST(MeasurementWeights, LandmarkAndPriorTermsAreWeighted) {
  std::mt19937_64 rng(9);
  for (int d : {2, 3}) {
    WeightedCase c = MakeLandmarkCase(d, 3, false);
    for (size_t k = c.graph.measurements.size(); k < c.weights.size(); ++k) {
      c.weights[k] = std::max(c.weights[k], 0.125);
    }
    ASSERT_EQ(c.weights.size(), internal::NumWeightedTerms(c.graph));
    ASSERT_TRUE(internal::CheckMeasurementWeights(c.graph, c.weights, nullptr));
    const PoseGraph scaled = ScaledAll(c.graph, c.weights);
    ASSERT_TRUE(ValidatePoseGraph(scaled, nullptr));
    const SESyncProblem weighted(c.graph, 1, c.weights);
    const SESyncProblem reference(scaled);
    ASSERT_TRUE(weighted.ok() && reference.ok());
    EXPECT_EQ(Dense(weighted.D()), Dense(reference.D()));
    EXPECT_EQ(Dense(weighted.Vbar()), Dense(reference.Vbar()));
    EXPECT_EQ(Dense(weighted.Lbar()), Dense(reference.Lbar()));
    // ... and differ from the unweighted problem's (the weights are used).
    EXPECT_NE(Dense(weighted.Lbar()), Dense(SESyncProblem(c.graph).Lbar()));

    Solution x{test_util::RandomPoses(d, c.graph.num_poses, 2.0, &rng), {}};
    std::normal_distribution<double> normal;
    for (int l = 0; l < c.graph.num_landmarks; ++l) {
      x.landmarks.push_back(Eigen::VectorXd::NullaryExpr(
          d, [&](Eigen::Index) { return 3 * normal(rng); }));
    }
    EXPECT_EQ(
        internal::WeightedObjective(c.graph, c.weights, x.poses, x.landmarks),
        EvaluateObjective(scaled, x));
    EXPECT_EQ(
        internal::ObjectiveUpperBound(c.graph, x.poses, x.landmarks, c.weights),
        internal::ObjectiveUpperBound(scaled, x.poses, x.landmarks));
    EXPECT_EQ(internal::TotalPrecision(c.graph, c.weights),
              internal::TotalPrecision(scaled));
  }
}

// Weights in {0, 1} on a landmark graph with priors: the weighted
// staircase, built at once and re-weighted from all-one weights, reaches
// the certified optimum of the graph of the weight-1 terms.
TEST(MeasurementWeights, BinaryLandmarkAndPriorWeightsGiveTheInlierOptimum) {
  for (int d : {2, 3}) {
    WeightedCase c = MakeLandmarkCase(d, 5, /*binary=*/true);
    for (size_t q = 0; q < c.graph.priors.size(); q += 2) {  // Some GPS ones.
      if (!c.graph.priors[q].has_rotation()) {
        c.weights[internal::PriorTerm(c.graph, q)] = 0;
      }
    }
    const PoseGraph inliers = InlierTerms(c.graph, c.weights);
    ASSERT_LT(inliers.landmark_measurements.size(),
              c.graph.landmark_measurements.size());
    ASSERT_LT(inliers.priors.size(), c.graph.priors.size());
    ASSERT_TRUE(ValidatePoseGraph(inliers, nullptr));
    SolverOptions options;
    options.num_threads = 1;
    SolverSummary reference;
    Solution optimum;
    Solve(inliers, options, &optimum, &reference);
    ASSERT_TRUE(reference.certified()) << reference.FullReport();

    SolverSummary summary;
    internal::Staircase staircase(c.graph, options, &summary);
    ASSERT_TRUE(staircase.ok());
    ASSERT_TRUE(staircase.Reweight(c.weights));
    EXPECT_EQ(summary.num_landmark_measurements,
              static_cast<int>(inliers.landmark_measurements.size()));
    EXPECT_EQ(summary.num_priors, static_cast<int>(inliers.priors.size()));
    Eigen::MatrixXd Y;
    ASSERT_TRUE(staircase.Initialize(nullptr, &Y));
    staircase.Run(&Y);
    const Solution x = staircase.Round(Y);
    staircase.Report(Y, x);
    EXPECT_TRUE(summary.certified()) << summary.FullReport();
    EXPECT_NEAR(summary.objective, reference.objective,
                1e-9 * reference.objective);
    EXPECT_NEAR(summary.lower_bound, reference.lower_bound,
                1e-8 * reference.objective);
    EXPECT_NEAR(EvaluateObjective(inliers, x), reference.objective,
                1e-9 * reference.objective);
    // With priors the frame is the world's: the poses themselves agree.
    for (int i = 0; i < c.graph.num_poses; ++i) {
      EXPECT_LT((x.poses[i].t - optimum.poses[i].t).norm(), 1e-6) << i;
      EXPECT_LT((x.poses[i].R - optimum.poses[i].R).norm(), 1e-6) << i;
    }
  }
}

// Zero weights on every observation of a landmark, or on every prior,
// disconnect the problem: rejected with a message naming what is cut off.
TEST(MeasurementWeights, CutOffLandmarkOrWorldIsRejected) {
  const WeightedCase c = MakeLandmarkCase(2, 7, /*binary=*/true);
  const PoseGraph& g = c.graph;
  MeasurementWeights w(internal::NumWeightedTerms(g), 1.0);
  const int l = g.landmark_measurements[0].l;
  for (size_t q = 0; q < g.landmark_measurements.size(); ++q) {
    if (g.landmark_measurements[q].l == l) w[internal::LandmarkTerm(g, q)] = 0;
  }
  std::string error;
  EXPECT_FALSE(internal::CheckMeasurementWeights(g, w, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("landmark " +
                                          std::to_string(g.landmark_ids[l])));
  w.assign(w.size(), 1.0);
  for (size_t q = 0; q < g.priors.size(); ++q) {
    w[internal::PriorTerm(g, q)] = 0;
  }
  EXPECT_FALSE(internal::CheckMeasurementWeights(g, w, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("world frame"));
  // The start prior alone (a full pose prior: its position term keeps the
  // world's translation node connected once every GPS prior is rejected):
  // connected.
  for (size_t q = 0; q < g.priors.size(); ++q) {
    w[internal::PriorTerm(g, q)] = g.priors[q].has_rotation() ? 1 : 0;
  }
  EXPECT_TRUE(internal::CheckMeasurementWeights(g, w, &error)) << error;
  SolverOptions options;  // The Staircase keeps a reference.
  options.num_threads = 1;
  SolverSummary summary;
  internal::Staircase staircase(g, options, &summary,
                                internal::Staircase::Clock::now(), w);
  EXPECT_TRUE(staircase.ok()) << summary.message;
  w.pop_back();
  EXPECT_FALSE(internal::CheckMeasurementWeights(g, w, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("terms"));
}

}  // namespace
}  // namespace ceres_sesync
