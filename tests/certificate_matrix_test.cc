// Independent tests of the sparse certificate test (internal/
// certificate_matrix.h) and of VerifyCertificate (internal/verification.h)
// against a DENSE eigendecomposition of S = Q - Lambda, with Q built densely
// from first principles in the test (tests/util/test_graphs.h).
//
// Multipliers come from (a) the SE-Sync optimum of the graph (Lambda =
// SymBlockDiag(Q R^T R) at the solver's rotations), (b) a perturbation of it
// (every rotation turned by a random angle), and (c) a random point of
// St(d, d + 2)^n. The central property is SOUNDNESS: a successful
// factorization must never happen when S + cI is clearly indefinite, and a
// certified result must really have lambda_min(S) >= -eta. The graphs
// include landmarks and priors (dense S from the Schur complement of
// tests/util's DenseLandmarkDataMatrix; the proofs assemble K from the
// landmark and prior terms through the same paths as the edges).

#include "ceres_sesync/internal/certificate_matrix.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/sesync_solver.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using internal::CertificateMatrix;
using internal::PreconditionerType;
using internal::SESyncCost;
using internal::SESyncPreconditioner;
using internal::SESyncProblem;
using internal::VerificationResult;
using test_util::RandomGraphOptions;

struct Instance {
  std::string name;
  int d = 0, n = 0;
  MatrixXd Lambda;  // d x dn.
  MatrixXd S;       // Dense Q - Lambda.
  double lambda_min = 0;
  double scale = 0;  // ||S||_2.
  double f = 0;      // F at the point Lambda came from.
};

// A test graph; `dense` marks the one meant to get a supernodal factor.
struct GraphCase {
  std::string name;
  PoseGraph graph;
  bool dense = false;
};

class CertificateTest : public ::testing::Test {
 protected:
  // Builds the three kinds of multipliers for one graph.
  void Build(const GraphCase& c) {
    graph_ = c.graph;
    problem_ = std::make_unique<SESyncProblem>(graph_);
    ASSERT_TRUE(problem_->ok());
    Q_ = graph_.has_landmarks_or_priors() ? test_util::DenseLandmarkQ(graph_)
                                          : test_util::DenseQ(graph_);
    const int d = graph_.dimension, n = problem_->num_rotations();
    ASSERT_EQ(Q_.rows(), d * n);
    const uint64_t seed = 1000 + graph_.num_poses + graph_.num_landmarks;
    SESyncPreconditioner none(*problem_, PreconditionerType::kNone, 1e6);
    SESyncCost cost(problem_.get(), &none);
    auto add = [&](const std::string& name, const MatrixXd& Y) {
      Instance in;
      in.name = name;
      in.d = d;
      in.n = n;
      in.f = cost.Evaluate(Y);
      in.Lambda = cost.Lambda();
      in.S = Q_ - test_util::BlockDiagonalToDense(in.Lambda, d);
      Eigen::SelfAdjointEigenSolver<MatrixXd> eig(in.S);
      in.lambda_min = eig.eigenvalues()(0);
      in.scale = eig.eigenvalues().cwiseAbs().maxCoeff();
      instances_.push_back(in);
    };
    SolverSummary summary;
    const Poses x = Solve(graph_, SolverOptions(), &summary);
    ASSERT_TRUE(summary.certified()) << summary.FullReport();
    // In the world frame with priors: R_w = I.
    const MatrixXd R = test_util::StackSolverRotations(graph_, x);
    add("optimum", R);
    std::mt19937_64 rng(seed);
    MatrixXd perturbed = R;
    std::normal_distribution<double> normal;
    for (int i = 0; i < n; ++i) {
      MatrixXd W = MatrixXd::Zero(d, d);
      for (int a = 0; a < d; ++a) {
        for (int b = a + 1; b < d; ++b) {
          W(a, b) = 0.3 * normal(rng);
          W(b, a) = -W(a, b);
        }
      }
      // Cayley transform of the skew W: a rotation of angle ~|W|.
      const MatrixXd I = MatrixXd::Identity(d, d);
      perturbed.middleCols(d * i, d) =
          R.middleCols(d * i, d) * (I - 0.5 * W).inverse() * (I + 0.5 * W);
    }
    add("perturbed", perturbed);
    add("random", RandomStiefelProductPoint(d, d + 2, n, &rng));
  }

  PoseGraph graph_;
  std::unique_ptr<SESyncProblem> problem_;
  MatrixXd Q_;
  std::vector<Instance> instances_;
};

std::vector<GraphCase> Graphs() {
  std::vector<GraphCase> graphs;
  uint64_t seed = 40;
  for (int d : {2, 3}) {
    for (int n : {10, 60}) {
      RandomGraphOptions o;
      o.dimension = d;
      o.num_poses = n;
      o.num_loop_closures = n;
      o.kappa = 50;
      o.tau = 20;
      o.seed = seed++;
      graphs.push_back(
          {"random d " + std::to_string(d) + " n " + std::to_string(n),
           test_util::RandomPoseGraph(o, nullptr)});
    }
  }
  // A long chain (poorly conditioned translational Laplacian: the coupling
  // ||Lbar^{-1} Vbar|| is large) with few loop closures.
  RandomGraphOptions chain;
  chain.dimension = 3;
  chain.num_poses = 150;
  chain.num_loop_closures = 3;
  chain.chain = true;
  chain.kappa = 50;
  chain.tau = 20;
  chain.seed = 77;
  graphs.push_back({"chain", test_util::RandomPoseGraph(chain, nullptr)});
  // Dense loop closures: a supernodal-class factor (flops / nnz(L) above
  // kSupernodalSwitch), and verification
  // takes the Lanczos-on-S path for clearly negative curvature.
  RandomGraphOptions dense;
  dense.dimension = 3;
  dense.num_poses = 250;
  dense.num_loop_closures = 2500;
  dense.kappa = 50;
  dense.tau = 20;
  dense.seed = 78;
  graphs.push_back(
      {"dense", test_util::RandomPoseGraph(dense, nullptr), /*dense=*/true});
  // Landmarks (the eliminated translations grow) with and without priors
  // (the world block R_w, and t_w as the gauge node), 2D and 3D; sparse
  // odometry so that the landmarks carry much of the structure.
  for (int d : {2, 3}) {
    for (int priors : {0, 1}) {
      test_util::RandomLandmarkGraphOptions l;
      l.poses.dimension = d;
      l.poses.num_poses = 40;
      l.poses.num_loop_closures = 4;
      l.poses.kappa = 50;
      l.poses.tau = 20;
      l.poses.seed = seed++;
      l.num_landmarks = 60;
      l.observations_per_landmark = 3;
      l.nu = 10;
      l.num_position_priors = 3 * priors;
      l.num_rotation_priors = priors;
      l.num_pose_priors = priors;
      graphs.push_back(
          {"landmarks d " + std::to_string(d) + (priors ? " priors" : ""),
           test_util::RandomLandmarkGraph(l, nullptr)});
    }
  }
  return graphs;
}

// MultiplyCertificate(v) = S v.
TEST_F(CertificateTest, MultiplyCertificateMatchesDense) {
  std::mt19937_64 rng(3);
  for (const GraphCase& o : Graphs()) {
    SCOPED_TRACE(o.name);
    instances_.clear();
    Build(o);
    for (const Instance& in : instances_) {
      VectorXd v(in.d * in.n);
      std::normal_distribution<double> normal;
      for (int k = 0; k < v.size(); ++k) v(k) = normal(rng);
      const VectorXd Sv =
          internal::MultiplyCertificate(*problem_, in.Lambda, v);
      EXPECT_LT((Sv - in.S * v).norm(), 1e-10 * in.scale * v.norm()) << in.name;
    }
  }
}

// Factorize(Lambda, c) (no proof) succeeds iff lambda_min(S) > -c, for
// shifts whose distance from -lambda_min(S) is far above round-off. Prove()
// in either arithmetic never succeeds when S + cI is clearly indefinite, and
// whenever it succeeds lambda_min(S) >= -proven_shift() (the documented
// guarantee); double-double proofs succeed as soon as lambda_min(S + cI) is
// above ~1e-25 ||S||, double proofs once it covers their round-off.
TEST_F(CertificateTest, ProofsAgreeWithDenseEigenvalues) {
  for (const GraphCase& o : Graphs()) {
    SCOPED_TRACE(o.name);
    instances_.clear();
    Build(o);
    CertificateMatrix matrix(*problem_);
    EXPECT_EQ(matrix.dimension(),
              o.graph.dimension * problem_->num_rotations());
    for (const Instance& in : instances_) {
      const double lmin = in.lambda_min, s = in.scale;
      struct Shift {
        double c;
        bool positive_definite;
      };
      std::vector<Shift> shifts = {
          {-lmin + 1e-3 * s, true},   // lambda_min(S + cI) = 1e-3 ||S||.
          {-lmin - 1e-3 * s, false},  // lambda_min(S + cI) = -1e-3 ||S||.
          {-lmin + 1e-6 * s, true},
          {-lmin - 1e-6 * s, false}};
      if (lmin < -1e-6 * s) {
        // Straddle -lambda_min by a factor 2 both ways; the "fail" case is
        // lambda_min(S) = -2c: SOUNDNESS.
        shifts.push_back({-2 * lmin, true});
        shifts.push_back({-0.5 * lmin, false});
        shifts.push_back({-1.1 * lmin, true});
        shifts.push_back({-0.9 * lmin, false});
      }
      for (const Shift& sh : shifts) {
        SCOPED_TRACE(in.name + ": d " + std::to_string(in.d) + " n " +
                     std::to_string(in.n) + " lambda_min(S) " +
                     std::to_string(lmin) + " c " + std::to_string(sh.c));
        EXPECT_EQ(matrix.Factorize(in.Lambda, sh.c), sh.positive_definite);
        for (auto precision : {internal::ProofPrecision::kDouble,
                               internal::ProofPrecision::kDoubleDouble}) {
          const bool ok = matrix.Prove(in.Lambda, sh.c, precision);
          if (!sh.positive_definite) {
            EXPECT_FALSE(ok);
          }
          if (precision == internal::ProofPrecision::kDoubleDouble ||
              sh.c + lmin >= 1e-3 * s) {
            EXPECT_EQ(ok, sh.positive_definite);
          }
          if (ok) {
            EXPECT_GE(matrix.proven_shift(), sh.c);
            EXPECT_GE(lmin, -matrix.proven_shift() - 1e-13 * s);
            if (precision == internal::ProofPrecision::kDoubleDouble) {
              // Double-double: the allowance is ~1e-30 of the matrix scale.
              EXPECT_LT(matrix.proven_shift() - sh.c, 1e-20 * s);
            }
          }
        }
      }
    }
  }
}

// The soundness test at the resolution the solver works at: S is shifted so
// that lambda_min(S) = -2c exactly (dense), for c from 1e-6 ||S|| down to
// 1e-11 ||S|| (the solver's eta is ~1e-9 F / (d n)). A successful proof at c
// would be a false certificate unless proven_shift() covers the gap.
TEST_F(CertificateTest, NoFalseCertificateAtSmallShifts) {
  for (const GraphCase& o : Graphs()) {
    SCOPED_TRACE(o.name);
    instances_.clear();
    Build(o);
    CertificateMatrix matrix(*problem_);
    const Instance& in = instances_[0];  // The optimum: lambda_min ~ 0.
    const int d = in.d;
    const double s = in.scale;
    for (double relative : {1e-6, 1e-8, 1e-9, 1e-10, 1e-11}) {
      const double c = relative * s;
      // Lambda' = Lambda + mu I: lambda_min(Q - Lambda') = lambda_min - mu.
      const double mu = in.lambda_min + 2 * c;
      MatrixXd shifted = in.Lambda;
      for (int i = 0; i < in.n; ++i) {
        shifted.middleCols(d * i, d) += mu * MatrixXd::Identity(d, d);
      }
      for (auto precision : {internal::ProofPrecision::kDouble,
                             internal::ProofPrecision::kDoubleDouble}) {
        if (matrix.Prove(shifted, c, precision)) {
          // Only acceptable if the proven shift accounts for the gap.
          EXPECT_GE(matrix.proven_shift(), 2 * c * (1 - 1e-6))
              << "FALSE CERTIFICATE: lambda_min(S) = " << -2 * c
              << " but K_c factorized with proven_shift "
              << matrix.proven_shift() << " (c = " << c << ", ||S|| = " << s
              << ", d " << d << " n " << in.n << ", "
              << internal::ProofPrecisionName(precision) << ")";
        }
      }
    }
  }
}

// (S + cI)^{-1} y by the sparse factor equals the dense solve.
TEST_F(CertificateTest, SolveShiftedMatchesDenseSolve) {
  std::mt19937_64 rng(5);
  for (const GraphCase& o : Graphs()) {
    SCOPED_TRACE(o.name);
    instances_.clear();
    Build(o);
    // Lbar, Vbar and D in the solver's index sets (gauge node dropped).
    const test_util::DenseLandmarkProblem blocks =
        test_util::BuildDenseLandmarkProblem(graph_);
    for (bool proof : {false, true}) {
      CertificateMatrix matrix(*problem_);
      if (o.dense) {
        EXPECT_TRUE(matrix.supernodal());  // The case meant to exercise it.
      }
      for (const Instance& in : instances_) {
        const int dn = in.d * in.n;
        // lambda_min(S + cI) = 1e-3 ||S||: condition number <= ~1e3.
        const double c = -in.lambda_min + 1e-3 * in.scale;
        ASSERT_TRUE(proof ? matrix.Prove(in.Lambda, c,
                                         internal::ProofPrecision::kDouble)
                          : matrix.Factorize(in.Lambda, c));
        // The factor is of K_c with the translation block Lbar - mu I: its
        // Schur complement S_mu + cI, computed densely here.
        // Lbar - diag(mu_j), mu_j > 0 (one per translation row) after a
        // proof, none after Factorize().
        const std::vector<double>& mu = matrix.translation_shifts();
        const int n1 = static_cast<int>(blocks.Lbar.rows());
        ASSERT_EQ(static_cast<int>(mu.size()), proof ? n1 : 0);
        VectorXd shift = VectorXd::Zero(n1);
        for (int j = 0; j < static_cast<int>(mu.size()); ++j) {
          EXPECT_GT(mu[j], 0);
          shift(j) = mu[j];
        }
        const MatrixXd Lbar = blocks.Lbar - MatrixXd(shift.asDiagonal());
        const MatrixXd& V = blocks.Vbar;
        const MatrixXd S_mu = blocks.D - V.transpose() * Lbar.llt().solve(V) -
                              test_util::BlockDiagonalToDense(in.Lambda, in.d);
        const MatrixXd shifted = S_mu + c * MatrixXd::Identity(dn, dn);
        // S_mu <= S, and for mu at round-off level nearly equal.
        EXPECT_LT((S_mu - in.S).norm(), 1e-6 * in.scale) << in.name;
        std::normal_distribution<double> normal;
        MatrixXd Y(dn, 3);
        for (int k = 0; k < Y.size(); ++k) Y.data()[k] = normal(rng);
        const MatrixXd expected = shifted.ldlt().solve(Y);
        MatrixXd X;
        matrix.SolveShifted(Y, &X);
        EXPECT_LT((X - expected).norm(), 1e-9 * expected.norm()) << in.name;
        VectorXd x;
        matrix.SolveShifted(VectorXd(Y.col(1)), &x);
        EXPECT_LT((x - expected.col(1)).norm(), 1e-9 * expected.col(1).norm());
      }
    }
  }
}

// VerifyCertificate against the dense spectrum, with the solver's thresholds
// (eta ~ 1e-9 F / (d n) target, 1e-6 F / (d n) max) and with a loose eta_max.
TEST_F(CertificateTest, VerifyCertificateAgreesWithDenseSpectrum) {
  int vacuous = 0;
  for (const GraphCase& o : Graphs()) {
    SCOPED_TRACE(o.name);
    instances_.clear();
    Build(o);
    for (auto policy :
         {internal::ProofPolicy::kAutomatic, internal::ProofPolicy::kDouble,
          internal::ProofPolicy::kDoubleDouble}) {
      CertificateMatrix matrix(*problem_);
      if (o.dense) {
        EXPECT_TRUE(matrix.supernodal());  // The case meant to exercise it.
      }
      for (const Instance& in : instances_) {
        const int dn = in.d * in.n;
        internal::VerificationOptions options;
        options.eta_target = 1e-9 * in.f / dn;
        options.eta_goal = 1e-7 * in.f / dn;
        options.eta_max = 1e-6 * in.f / dn;
        options.policy = policy;
        const double eta_max = options.eta_max;
        const VerificationResult v =
            internal::VerifyCertificate(*problem_, in.Lambda, options, &matrix);
        SCOPED_TRACE(in.name + " d " + std::to_string(in.d) + " n " +
                     std::to_string(in.n) + " dense lambda_min " +
                     std::to_string(in.lambda_min));
        EXPECT_GE(v.factorizations + v.extended_factorizations, 1);
        if (policy == internal::ProofPolicy::kDouble) {
          EXPECT_EQ(v.extended_factorizations, 0);
        }
        if (in.name == "optimum") {
          EXPECT_TRUE(v.certified) << "eta " << v.eta;
          if (policy != internal::ProofPolicy::kDouble) {
            EXPECT_LE(v.eta, options.eta_goal);  // Tight, in double-double.
          }
        } else {
          // Far from optimal: lambda_min(S) is O(1) negative.
          EXPECT_LT(in.lambda_min, -eta_max);
          EXPECT_FALSE(v.certified);
        }
        // The poor-candidate shortcut: only when S + (tr(Lambda) / dn) I is
        // really indefinite (tr(Lambda) = F at the point), and then every
        // proven shift is above tr(Lambda) / dn.
        if (v.vacuous_bound) {
          ++vacuous;
          EXPECT_FALSE(v.certified);
          EXPECT_LT(in.lambda_min, -in.f / dn * (1 - 1e-9));
          EXPECT_GE(v.eta, in.f / dn);
        }
        // Whatever the outcome, the proven shift must be sound.
        if (std::isfinite(v.eta)) {
          EXPECT_GE(in.lambda_min, -v.eta * (1 + 1e-9) - 1e-13 * in.scale)
              << "eta " << v.eta;
        }
        if (v.certified) {
          EXPECT_LE(v.eta, eta_max);
        } else {
          EXPECT_FALSE(v.eigensolver_failed);
          ASSERT_EQ(v.direction.size(), dn);
          EXPECT_NEAR(v.direction.norm(), 1.0, 1e-10);
          const double curvature = v.direction.dot(in.S * v.direction);
          EXPECT_LT(curvature, 0.0);
          EXPECT_NEAR(v.direction_curvature, curvature, 1e-9 * in.scale);
          // Simplicial: Lanczos on (S + cI)^{-1} with tolerance 1e-8, c within
          // 16x of -lambda_min: 1e-6 relative. Supernodal: the Rayleigh
          // quotient of a Lanczos-on-S Ritz vector (tolerance 1e-3), an upper
          // bound on lambda_min.
          // Lanczos on S (tolerance 1e-3): supernodal factors and the
          // poor-candidate shortcut (eta = +inf).
          const double accuracy =
              matrix.supernodal() || std::isinf(v.eta) ? 1e-2 : 1e-6;
          EXPECT_NEAR(v.lambda_min_estimate, in.lambda_min,
                      accuracy * std::abs(in.lambda_min));
          EXPECT_GE(v.lambda_min_estimate,
                    in.lambda_min - 1e-9 * std::abs(in.lambda_min));
        }

        // With a generous eta_max every instance is certified with a sound
        // eta in [-lambda_min, eta_max].
        internal::VerificationOptions loose = options;
        loose.eta_max = loose.eta_goal =
            4 * std::abs(in.lambda_min) + 1e-6 * in.scale;
        const double generous = loose.eta_max;
        const VerificationResult w =
            internal::VerifyCertificate(*problem_, in.Lambda, loose, &matrix);
        EXPECT_TRUE(w.certified);
        EXPECT_LE(w.eta, generous);
        EXPECT_GE(in.lambda_min, -w.eta * (1 + 1e-9) - 1e-13 * in.scale);
      }
    }
  }
  EXPECT_GT(vacuous, 0);  // The random points exercise the shortcut.
}

// A deadline that has passed stops the verification before any
// factorization: nothing is proven (eta = +inf), out_of_time says why, and
// no certificate is claimed.
TEST_F(CertificateTest, VerificationStopsAtItsDeadline) {
  Build(Graphs()[0]);
  CertificateMatrix matrix(*problem_);
  const Instance& in = instances_[0];  // The optimum.
  internal::VerificationOptions options;
  options.eta_target = 1e-9 * in.f / (in.d * in.n);
  options.eta_goal = 1e-6 * in.f / (in.d * in.n);
  options.eta_max = 1e-3 * in.f / (in.d * in.n);
  options.deadline = std::chrono::steady_clock::now();
  const VerificationResult late =
      internal::VerifyCertificate(*problem_, in.Lambda, options, &matrix);
  EXPECT_TRUE(late.out_of_time);
  EXPECT_FALSE(late.certified);
  EXPECT_TRUE(std::isinf(late.eta));
  EXPECT_EQ(late.factorizations + late.extended_factorizations, 0);
  // Without the deadline the same verification certifies.
  options.deadline = std::chrono::steady_clock::time_point::max();
  const VerificationResult on_time =
      internal::VerifyCertificate(*problem_, in.Lambda, options, &matrix);
  EXPECT_FALSE(on_time.out_of_time);
  EXPECT_TRUE(on_time.certified);
}

// A square grid (pose 0 at a corner, `side` poses a side, kappa = tau =
// `precision`) solved to its certified optimum, and the multipliers at the
// solution's rotations, as Certify computes them.
struct SolvedGrid {
  PoseGraph graph;
  std::unique_ptr<SESyncProblem> problem;
  MatrixXd R, Lambda;
  double f = 0;
};
void SolveGrid(int side, double precision, uint64_t seed, double p_lc,
               SolvedGrid* grid) {
  CubeOptions o;
  o.dimension = 2;
  o.side = side;
  o.kappa = o.tau = precision;
  o.seed = seed;
  o.loop_closure_probability = p_lc;
  std::string error;
  ASSERT_TRUE(GenerateCube(o, &grid->graph, nullptr, &error)) << error;
  SolverOptions options;
  options.num_threads = 1;
  SolverSummary summary;
  const Poses x = Solve(grid->graph, options, &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  grid->problem = std::make_unique<SESyncProblem>(grid->graph);
  ASSERT_TRUE(grid->problem->ok());
  SESyncPreconditioner none(*grid->problem, PreconditionerType::kNone, 1e6);
  SESyncCost cost(grid->problem.get(), &none);
  grid->R = test_util::StackRotations(x);
  grid->f = cost.Evaluate(grid->R);
  grid->Lambda = cost.Lambda();
}

// DoubleShiftCost is the first-order change of lambda_min(S) that the
// double proofs' translation shifts cause. At a square grid's certified
// optimum (S >= 0, its null space the rows of R), Lbar lowered by sigma
// diag(mu), mu the shifts the next proof starts with, lowers lambda_min(S)
// by sigma DoubleShiftCost to first order. Pose 0 is a corner of the grid:
// the offsets' coordinates are correlated, and the cost (the largest
// eigenvalue of sum_j mu_j o_j o_j^T / n) is well above either coordinate's
// sum alone.
TEST(CertificateMatrixShifts, DoubleShiftCostIsTheFirstOrderChange) {
  SolvedGrid grid;
  SolveGrid(8, 100, 3, 0.3, &grid);
  CertificateMatrix matrix(*grid.problem);
  const MatrixXd offsets =
      matrix.TranslationOffsets(grid.problem->RecoverTranslations(grid.R));
  const double model = matrix.DoubleShiftCost(offsets);
  const std::vector<double>& mu = matrix.next_double_shifts();
  const int n1 = static_cast<int>(offsets.cols()), n = grid.graph.num_poses;
  ASSERT_EQ(static_cast<int>(mu.size()), n1);
  VectorXd shift(n1);
  double largest_coordinate = 0;
  for (int j = 0; j < n1; ++j) shift(j) = mu[j];
  for (int a = 0; a < 2; ++a) {
    largest_coordinate =
        std::max(largest_coordinate,
                 shift.dot(offsets.row(a).transpose().cwiseAbs2()) / n);
  }
  EXPECT_GT(model, 1.3 * largest_coordinate);  // The premise: a corner.

  const test_util::DenseLandmarkProblem blocks =
      test_util::BuildDenseLandmarkProblem(grid.graph);
  const MatrixXd LambdaDense = test_util::BlockDiagonalToDense(grid.Lambda, 2);
  auto lambda_min = [&](double sigma) {
    const MatrixXd Lbar = blocks.Lbar - sigma * MatrixXd(shift.asDiagonal());
    const MatrixXd S = blocks.D -
                       blocks.Vbar.transpose() * Lbar.llt().solve(blocks.Vbar) -
                       LambdaDense;
    return Eigen::SelfAdjointEigenSolver<MatrixXd>(S, Eigen::EigenvaluesOnly)
        .eigenvalues()(0);
  };
  const double scale = std::abs(lambda_min(0)) +
                       Eigen::SelfAdjointEigenSolver<MatrixXd>(
                           blocks.D - LambdaDense, Eigen::EigenvaluesOnly)
                           .eigenvalues()
                           .cwiseAbs()
                           .maxCoeff();
  // A change of 1e-6 ||S||: far above the dense eigensolver's round-off,
  // far below S's gap above its null space.
  const double sigma = 1e-6 * scale / model;
  const double change = lambda_min(0) - lambda_min(sigma);
  EXPECT_NEAR(change / (sigma * model), 1.0, 0.02)
      << "change " << change << " model " << sigma * model;
}

// A double proof covers every translation row's round-off bound with that
// row's own shift: started from shifts far too small (1e-300), the first
// attempt settles no row, the second starts each row at twice its bound and
// settles. Afterwards the next shifts (1.5 times the bounds met) are within
// 1.5 times the shifts the proof used, row by row, the shifts vary across
// rows (10-1000x on maps; here the rows near the top of the elimination
// tree carry more round-off), and a proof at the same c from the next
// shifts uses them unchanged.
TEST(CertificateMatrixShifts, EveryTranslationRowIsCoveredByItsShift) {
  SolvedGrid grid;
  SolveGrid(8, 100, 3, 0.3, &grid);
  const SESyncProblem& problem = *grid.problem;
  const MatrixXd& Lambda = grid.Lambda;
  CertificateMatrix matrix(problem);
  const int n1 = grid.graph.num_poses - 1;
  const double c = 1e-6 * grid.f;
  matrix.set_next_double_shifts(std::vector<double>(n1, 1e-300));
  const int before = matrix.double_factorizations();
  ASSERT_TRUE(matrix.Prove(Lambda, c, internal::ProofPrecision::kDouble));
  EXPECT_EQ(matrix.double_factorizations() - before, 2);
  const std::vector<double> used = matrix.translation_shifts();
  const std::vector<double> next = matrix.next_double_shifts();
  ASSERT_EQ(static_cast<int>(used.size()), n1);
  ASSERT_EQ(static_cast<int>(next.size()), n1);
  for (int j = 0; j < n1; ++j) {
    EXPECT_GT(used[j], 1e-300) << j;
    EXPECT_LE(next[j], 1.5 * used[j] * (1 + 1e-12)) << j;
  }
  const auto [smallest, largest] =
      std::minmax_element(used.begin(), used.end());
  EXPECT_GT(*largest, 10 * *smallest);
  ASSERT_TRUE(matrix.Prove(Lambda, c, internal::ProofPrecision::kDouble));
  EXPECT_EQ(matrix.double_factorizations() - before, 3);
  EXPECT_EQ(matrix.translation_shifts(), next);
}

// Where double cannot reach the goal with a fresh matrix's shifts (from
// Lbar's round-off) but the bounds of a first double proof bring it within
// reach, VerifyCertificate proves in double twice (the second proof with
// the first's bounds as shifts) instead of once in double-double, on
// factorizations of at least learned_shift_min_multiply_adds: sound against
// the dense lambda_min(S), and within half the goal. Below that size (the
// default's 1e7 here) one double-double proof, as before.
TEST(CertificateMatrixShifts, LearnedShiftsProveTheGoalInDouble) {
  SolvedGrid grid;
  SolveGrid(16, 3e3, 1, 0.1, &grid);
  const int dn = 2 * grid.graph.num_poses;
  internal::VerificationOptions options;
  options.eta_target = 1e-9 * grid.f / dn;
  options.eta_goal = 1e-6 * grid.f / dn;
  options.eta_max = 1e-3 * grid.f / dn;
  options.likely_optimal = true;
  CertificateMatrix fresh(*grid.problem);
  options.translation_offsets =
      fresh.TranslationOffsets(grid.problem->RecoverTranslations(grid.R));
  // The premise: double's floor with a fresh matrix's shifts is above a
  // quarter of the goal (no double proof first) and within the reach.
  const double floor = fresh.DoubleShiftCost(options.translation_offsets);
  ASSERT_GT(floor, options.eta_goal / 4);
  ASSERT_LE(floor, 2 * options.eta_goal);
  ASSERT_LT(fresh.factorization_flops(),
            options.learned_shift_min_multiply_adds);

  const MatrixXd S = test_util::DenseQ(grid.graph) -
                     test_util::BlockDiagonalToDense(grid.Lambda, 2);
  const double lambda_min =
      Eigen::SelfAdjointEigenSolver<MatrixXd>(S, Eigen::EigenvaluesOnly)
          .eigenvalues()(0);

  const VerificationResult small =
      internal::VerifyCertificate(*grid.problem, grid.Lambda, options, &fresh);
  ASSERT_TRUE(small.certified);
  EXPECT_EQ(small.factorizations, 0);
  EXPECT_EQ(small.extended_factorizations, 1);

  options.learned_shift_min_multiply_adds = 0;
  CertificateMatrix matrix(*grid.problem);
  const VerificationResult v =
      internal::VerifyCertificate(*grid.problem, grid.Lambda, options, &matrix);
  ASSERT_TRUE(v.certified);
  EXPECT_EQ(v.precision, internal::ProofPrecision::kDouble);
  EXPECT_EQ(v.extended_factorizations, 0);
  EXPECT_EQ(v.factorizations, 2);
  EXPECT_LE(v.eta, options.eta_goal / 2);
  EXPECT_GE(lambda_min, -v.eta) << "FALSE CERTIFICATE at eta " << v.eta;
  // The learned shifts cost 3x+ less than the first.
  EXPECT_LT(3 * matrix.DoubleShiftCost(options.translation_offsets), floor);
}

}  // namespace
}  // namespace ceres_sesync
