// Degenerate pose graphs: what ReadG2o, Solve and Certify do with them. Each
// case states the defined behaviour it checks:
//
//  - One pose, no edges: not a valid g2o file (ReadG2o: "no EDGE lines"), but a
//    valid PoseGraph (ValidatePoseGraph accepts it: one pose is connected).
//    Solve returns that pose in the gauge (its initial pose, else the
//    identity) as a certified optimum with F = 0.
//  - Two poses, one edge: F = 0 is attained (x_j = x_i * x~_ij); certified.
//  - Two poses, two parallel edges i -> j: closed-form optimum (see
//    ParallelEdgesOptimum); Solve attains it and certifies it.
//  - A tree (no loop closures): F = 0 up to round-off; certified.
//  - Duplicate identical edges: legal (parallel edges are allowed); the
//    objective is that of one edge with the weights added.
//  - A disconnected graph, or vertices without edges: ReadG2o fails with a
//    message naming the number of components and a stray vertex; Solve
//    returns kInvalidInput; Certify returns false.
//  - kappa and tau scaled by 1e-8 .. 1e8 (jointly or separately): a clean
//    status (certified, or a non-certified status other than kInvalidInput),
//    never NaN; under a joint scaling s the optimum scales by s.
//  - Noiseless data: F ~ 0 and certified.
//
// Tolerances: objectives that are zero in exact arithmetic are compared with
// kRoundOff * W, where W = sum over edges of kappa (2d) + tau (1 + |t~|^2) is
// the size of the objective's terms at unit-scale errors; 1e-10 leaves room
// for the solver's gradient tolerance (relative 1e-6 on sqrt(F), so F itself
// to ~1e-12 of W) and round-off in sparse factorizations.

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "Eigen/SVD"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

// Certify is declared in certification.h; its implementation is being
// written. Until ceres_sesync/certification.cc exists, the Certify checks are
// skipped (loudly) so that the suite still links. NOTE: __has_include is
// evaluated when this file is compiled; touch this file (or rebuild from
// scratch) after certification.cc lands.
#if __has_include("ceres_sesync/certification.cc")
#define CERES_SESYNC_HAVE_CERTIFY 1
#else
#define CERES_SESYNC_HAVE_CERTIFY 0
#endif

namespace ceres_sesync {
namespace {

using Status = SolverSummary::Status;
using ::testing::HasSubstr;

constexpr double kRoundOff = 1e-10;

// KNOWN ISSUE (reported to the solver/certification owners): when the optimal
// value is 0 (exact data: one edge, trees, noiseless graphs), Solve ends with
// kEigenImprecision and Certify with "not certified", because the lower bound
// F(Y) - eta d n is slightly negative (~ -1e-13) and the relative
// suboptimality bound (F - LB) / LB is then +inf. The absolute bound is tiny,
// so these optima should be certified. The tests assert the CURRENT behaviour
// through this flag; flip it to true once zero optima are certified.
constexpr bool kZeroOptimumIsCertified = true;

Eigen::MatrixXd Rotation(int d, double angle, const Eigen::Vector3d& axis) {
  if (d == 2) return Eigen::Rotation2Dd(angle).toRotationMatrix();
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

Eigen::MatrixXd RandomRotation(int d, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  if (d == 2) {
    return Rotation(2,
                    std::uniform_real_distribution<double>(-M_PI, M_PI)(*rng),
                    Eigen::Vector3d::UnitZ());
  }
  Eigen::Quaterniond q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  return q.normalized().toRotationMatrix();
}

Eigen::VectorXd RandomVector(int d, double sigma, std::mt19937_64* rng) {
  std::normal_distribution<double> normal(0, sigma);
  Eigen::VectorXd v(d);
  for (int k = 0; k < d; ++k) v(k) = normal(*rng);
  return v;
}

PoseGraph EmptyGraph(int d, int n) {
  PoseGraph g;
  g.dimension = d;
  for (int k = 0; k < n; ++k) g.AddVertex(k);
  return g;
}

void AddEdge(PoseGraph* g, int i, int j, const Eigen::MatrixXd& R,
             const Eigen::VectorXd& t, double kappa, double tau) {
  RelativePoseMeasurement m;
  m.i = i;
  m.j = j;
  m.R = R;
  m.t = t;
  m.kappa = kappa;
  m.tau = tau;
  g->measurements.push_back(m);
}

// The exact relative pose x_i^-1 x_j.
void AddExactEdge(PoseGraph* g, const Poses& x, int i, int j, double kappa,
                  double tau) {
  AddEdge(g, i, j, x[i].R.transpose() * x[j].R,
          x[i].R.transpose() * (x[j].t - x[i].t), kappa, tau);
}

Poses RandomPoses(int d, int n, std::mt19937_64* rng) {
  Poses x(n);
  for (int k = 0; k < n; ++k) {
    x[k].R = RandomRotation(d, rng);
    x[k].t = RandomVector(d, 2.0, rng);
  }
  return x;
}

// Scale of the objective's terms (see the top of the file).
double TermScale(const PoseGraph& g) {
  double w = 0;
  for (const auto& m : g.measurements) {
    w += m.kappa * 2 * g.dimension + m.tau * (1 + m.t.squaredNorm());
  }
  return w;
}

// Checks that every returned pose is a finite pose in SE(d).
void ExpectFinitePoses(const PoseGraph& g, const Poses& x) {
  ASSERT_EQ(static_cast<int>(x.size()), g.num_poses);
  const int d = g.dimension;
  for (const Pose& p : x) {
    ASSERT_EQ(p.R.rows(), d);
    ASSERT_EQ(p.t.size(), d);
    EXPECT_TRUE(p.R.allFinite() && p.t.allFinite());
    EXPECT_LT((p.R.transpose() * p.R - Eigen::MatrixXd::Identity(d, d)).norm(),
              1e-9);
    EXPECT_NEAR(p.R.determinant(), 1, 1e-9);
  }
}

// Solves with default options and checks the invariants every result must
// satisfy: finite numbers, objective == F(poses), lower bound <= objective.
Poses SolveAndCheck(const PoseGraph& g, SolverSummary* s) {
  const Poses x = Solve(g, SolverOptions(), s);
  EXPECT_NE(s->status, Status::kInvalidInput) << s->message;
  if (s->status == Status::kInvalidInput) return x;
  ExpectFinitePoses(g, x);
  if (x.size() != static_cast<size_t>(g.num_poses)) return x;
  EXPECT_TRUE(std::isfinite(s->objective)) << s->FullReport();
  EXPECT_FALSE(std::isnan(s->lower_bound)) << s->FullReport();
  EXPECT_FALSE(std::isnan(s->sdp_value)) << s->FullReport();
  // The reported objective is F at the returned poses (same formula; only
  // summation order may differ).
  const double f = EvaluateObjective(g, x);
  EXPECT_NEAR(s->objective, f, 1e-12 * TermScale(g) + 1e-12 * f);
  // A lower bound (-inf when not certified) never exceeds the objective.
  EXPECT_LE(s->lower_bound, s->objective + 1e-12 * std::abs(s->objective) +
                                kRoundOff * 1e-3 * TermScale(g))
      << s->FullReport();
  return x;
}

#if CERES_SESYNC_HAVE_CERTIFY
// Certifies `x`, checks Certify's invariants and that it certifies iff
// `expected`.
void CertifyAndCheck(const PoseGraph& g, const Poses& x, bool expected) {
  Certificate c;
  std::string error;
  ASSERT_TRUE(Certify(g, x, CertifyOptions(), &c, &error)) << error;
  EXPECT_TRUE(std::isfinite(c.objective));
  EXPECT_FALSE(std::isnan(c.lower_bound));
  EXPECT_FALSE(std::isnan(c.relative_suboptimality_bound));
  EXPECT_NEAR(c.objective, EvaluateObjective(g, x),
              1e-12 * TermScale(g) + 1e-12 * c.objective);
  EXPECT_LE(c.lower_bound, c.objective + 1e-12 * std::abs(c.objective) +
                               kRoundOff * 1e-3 * TermScale(g))
      << c.FullReport();
  EXPECT_EQ(c.certified, expected) << c.FullReport();
}
#define CERTIFY_EXPECT(g, x, expected) CertifyAndCheck(g, x, expected)
#else
// Recorded in the test XML output; the solver checks still run.
#define CERTIFY_EXPECT(g, x, expected)                                      \
  ::testing::Test::RecordProperty("certify",                                \
                                  "skipped: ceres_sesync/certification.cc " \
                                  "not implemented yet")
#endif

bool Read(const std::string& text, PoseGraph* g, std::string* error) {
  std::istringstream in(text);
  return ReadG2o(in, "test.g2o", G2oReadOptions(), g, error);
}

// ---- n = 1 -----------------------------------------------------------------

TEST(DegenerateGraphs, SingleVertexFileIsRejectedByTheReader) {
  PoseGraph g;
  std::string error;
  EXPECT_FALSE(Read("VERTEX_SE2 0 1 2 0.5\n", &g, &error));
  EXPECT_THAT(error, HasSubstr("no EDGE lines"));
  EXPECT_FALSE(Read("VERTEX_SE3:QUAT 7 0 0 0 0 0 0 1\n", &g, &error));
  EXPECT_THAT(error, HasSubstr("no EDGE lines"));
}

TEST(DegenerateGraphs, SingleVertexGraphIsSolvedAsItsGauge) {
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    PoseGraph g = EmptyGraph(d, 1);
    std::string error;
    ASSERT_TRUE(ValidatePoseGraph(g, &error)) << error;

    // Without initial poses: the identity.
    SolverSummary s;
    Poses x = SolveAndCheck(g, &s);
    EXPECT_EQ(s.status, Status::kCertifiedOptimum);
    ASSERT_EQ(x.size(), 1u);
    EXPECT_EQ(x[0].R, Eigen::MatrixXd::Identity(d, d));
    EXPECT_EQ(x[0].t, Eigen::VectorXd::Zero(d));
    EXPECT_EQ(s.objective, 0.0);
    CERTIFY_EXPECT(g, x, true);

    // With an initial pose: that pose (the gauge keeps it).
    std::mt19937_64 rng(1);
    g.initial_poses = RandomPoses(d, 1, &rng);
    x = SolveAndCheck(g, &s);
    EXPECT_EQ(s.status, Status::kCertifiedOptimum);
    ASSERT_EQ(x.size(), 1u);
    EXPECT_LT((x[0].R - g.initial_poses[0].R).norm(), 1e-12);
    EXPECT_LT((x[0].t - g.initial_poses[0].t).norm(), 1e-12);
  }
}

// ---- n = 2 -----------------------------------------------------------------

TEST(DegenerateGraphs, TwoPosesOneEdgeIsExact) {
  std::mt19937_64 rng(2);
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    PoseGraph g = EmptyGraph(d, 2);
    AddEdge(&g, 0, 1, RandomRotation(d, &rng), RandomVector(d, 3, &rng), 7.5,
            0.3);
    SolverSummary s;
    const Poses x = SolveAndCheck(g, &s);
    ASSERT_EQ(x.size(), 2u);
    EXPECT_EQ(s.certified(), kZeroOptimumIsCertified) << s.FullReport();
    EXPECT_LE(s.objective, kRoundOff * TermScale(g));
    // x_1 = x_0 * x~_01, to round-off.
    const auto& m = g.measurements[0];
    EXPECT_LT((x[0].R.transpose() * x[1].R - m.R).norm(), 1e-8);
    EXPECT_LT((x[0].R.transpose() * (x[1].t - x[0].t) - m.t).norm(), 1e-8);
    CERTIFY_EXPECT(g, x, kZeroOptimumIsCertified);
  }
}

// Optimal value of F for two edges (R1, t1, k1, tau1) and (R2, t2, k2, tau2),
// both from pose 0 to pose 1. By gauge symmetry take x_0 = (I, 0), x_1 = (R,
// t). Then the translation terms tau_k |t - t_k|^2 do not involve R: their
// minimum is tau1 tau2 / (tau1 + tau2) |t1 - t2|^2 at the weighted mean. The
// rotation terms are sum k_k |R - R_k|_F^2 = 2 d (k1 + k2) - 2 tr(R^T M) with
// M = k1 R1 + k2 R2, and max over SO(d) of tr(R^T M) is s_1 + ... + s_{d-1} +
// sign(det M) s_d (singular values s of M, descending).
double ParallelEdgesOptimum(const PoseGraph& g) {
  const int d = g.dimension;
  const auto& a = g.measurements[0];
  const auto& b = g.measurements[1];
  const Eigen::MatrixXd M = a.kappa * a.R + b.kappa * b.R;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(M);
  const Eigen::VectorXd sv = svd.singularValues();
  double trace_max = sv.head(d - 1).sum();
  trace_max += (M.determinant() < 0 ? -1 : 1) * sv(d - 1);
  return 2 * d * (a.kappa + b.kappa) - 2 * trace_max +
         a.tau * b.tau / (a.tau + b.tau) * (a.t - b.t).squaredNorm();
}

TEST(DegenerateGraphs, TwoPosesTwoParallelEdgesReachTheClosedFormOptimum) {
  std::mt19937_64 rng(3);
  for (int d : {2, 3}) {
    // Rotation disagreements from small to nearly opposite (170 degrees).
    for (double angle : {0.05, 1.0, 2.5, 170 * M_PI / 180}) {
      SCOPED_TRACE(::testing::Message() << "d=" << d << " angle=" << angle);
      PoseGraph g = EmptyGraph(d, 2);
      const Eigen::MatrixXd R = RandomRotation(d, &rng);
      const Eigen::Vector3d axis = RandomVector(3, 1, &rng);
      AddEdge(&g, 0, 1, R, RandomVector(d, 1, &rng), 4.0, 10.0);
      AddEdge(&g, 0, 1, R * Rotation(d, angle, axis), RandomVector(d, 1, &rng),
              1.5, 0.5);
      const double optimum = ParallelEdgesOptimum(g);
      ASSERT_GT(optimum, 0);
      SolverSummary s;
      const Poses x = SolveAndCheck(g, &s);
      ASSERT_EQ(x.size(), 2u);
      EXPECT_EQ(s.status, Status::kCertifiedOptimum) << s.FullReport();
      // The global optimum cannot be beaten, and a converged solve attains
      // it (F is quadratic near the optimum, so a gradient tolerance of 1e-6
      // relative leaves ~1e-12 relative in F; 1e-8 is generous).
      EXPECT_GE(s.objective, optimum * (1 - 1e-12));
      EXPECT_LE(s.objective, optimum * (1 + 1e-8));
      // The lower bound is a true lower bound.
      EXPECT_LE(s.lower_bound, optimum * (1 + 1e-12));
      CERTIFY_EXPECT(g, x, true);
    }
  }
}

// ---- trees, duplicates -----------------------------------------------------

TEST(DegenerateGraphs, TreeHasZeroObjective) {
  std::mt19937_64 rng(4);
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    const int n = 25;
    PoseGraph g = EmptyGraph(d, n);
    // Random tree: each pose hangs off a random earlier pose; measurements
    // are arbitrary (inconsistent data cannot exist without loops).
    std::uniform_real_distribution<double> log_weight(-2, 2);
    for (int j = 1; j < n; ++j) {
      const int i = std::uniform_int_distribution<int>(0, j - 1)(rng);
      const bool forward = j % 2 == 0;  // Mix edge orientations.
      AddEdge(&g, forward ? i : j, forward ? j : i, RandomRotation(d, &rng),
              RandomVector(d, 2, &rng), std::pow(10, log_weight(rng)),
              std::pow(10, log_weight(rng)));
    }
    SolverSummary s;
    const Poses x = SolveAndCheck(g, &s);
    ASSERT_EQ(static_cast<int>(x.size()), n);
    EXPECT_EQ(s.certified(), kZeroOptimumIsCertified) << s.FullReport();
    EXPECT_LE(s.objective, kRoundOff * TermScale(g)) << s.FullReport();
    CERTIFY_EXPECT(g, x, kZeroOptimumIsCertified);
  }
}

// A noisy cycle 0 -> 1 -> ... -> n-1 -> 0 plus one chord.
PoseGraph NoisyCycle(int d, int n, double kappa, double tau,
                     std::mt19937_64* rng) {
  const Poses truth = RandomPoses(d, n, rng);
  PoseGraph g = EmptyGraph(d, n);
  for (int k = 0; k < n; ++k) AddExactEdge(&g, truth, k, (k + 1) % n, 1, 1);
  AddExactEdge(&g, truth, 0, n / 2, 1, 1);
  for (auto& m : g.measurements) {
    m.R = m.R * Rotation(d, 0.2, RandomVector(3, 1, rng));
    m.t += RandomVector(d, 0.3, rng);
    m.kappa = kappa;
    m.tau = tau;
  }
  return g;
}

TEST(DegenerateGraphs, DuplicateEdgesAddTheirWeights) {
  std::mt19937_64 rng(5);
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    const PoseGraph g = NoisyCycle(d, 7, 3.0, 2.0, &rng);
    PoseGraph duplicated = g, doubled = g;
    for (const auto& m : g.measurements) duplicated.measurements.push_back(m);
    for (auto& m : doubled.measurements) m.kappa *= 2, m.tau *= 2;

    SolverSummary s1, s2, s3;
    const Poses x1 = SolveAndCheck(g, &s1);
    const Poses x2 = SolveAndCheck(duplicated, &s2);
    const Poses x3 = SolveAndCheck(doubled, &s3);
    EXPECT_EQ(s1.status, Status::kCertifiedOptimum) << s1.FullReport();
    EXPECT_EQ(s2.status, Status::kCertifiedOptimum) << s2.FullReport();
    EXPECT_EQ(s3.status, Status::kCertifiedOptimum) << s3.FullReport();
    ASSERT_GT(s1.objective, 0);
    // Same minimizer, objective doubled. Each certified value is within its
    // relative suboptimality bound (<= 1e-6) of the optimum; they agree far
    // better in practice, 1e-7 is a safe but still sharp tolerance.
    EXPECT_NEAR(s2.objective, 2 * s1.objective, 1e-7 * s2.objective);
    EXPECT_NEAR(s3.objective, 2 * s1.objective, 1e-7 * s3.objective);
    // Duplicating the edges of a solution doubles F at it exactly (up to
    // summation round-off).
    if (x1.size() == static_cast<size_t>(g.num_poses)) {
      EXPECT_NEAR(EvaluateObjective(duplicated, x1), 2 * s1.objective,
                  1e-12 * s1.objective);
      CERTIFY_EXPECT(duplicated, x1, true);
    }
  }

  // The reader keeps identical lines as two measurements.
  PoseGraph g;
  std::string error;
  const std::string line = "EDGE_SE2 0 1 1 0 0.1 2 0 0 2 0 3\n";
  ASSERT_TRUE(Read(line + line, &g, &error)) << error;
  ASSERT_EQ(g.measurements.size(), 2u);
  EXPECT_EQ(g.measurements[0].R, g.measurements[1].R);
  EXPECT_EQ(g.measurements[0].kappa, 3.0);
  EXPECT_EQ(g.measurements[0].tau, 2.0);
  SolverSummary s;
  SolveAndCheck(g, &s);
  EXPECT_EQ(s.certified(), kZeroOptimumIsCertified);
  EXPECT_LE(s.objective, kRoundOff * TermScale(g));
}

// ---- disconnected graphs ---------------------------------------------------

TEST(DegenerateGraphs, DisconnectedGraphIsAClearError) {
  PoseGraph g;
  std::string error;
  EXPECT_FALSE(
      Read("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
           "EDGE_SE2 5 6 1 0 0 1 0 0 1 0 1\n"
           "EDGE_SE2 6 7 1 0 0 1 0 0 1 0 1\n",
           &g, &error));
  EXPECT_THAT(error, HasSubstr("disconnected"));
  EXPECT_THAT(error, HasSubstr("2 components"));
  EXPECT_THAT(error, HasSubstr("sizes 3, 2"));
  // Names a vertex of the other component and the line that introduced it.
  EXPECT_THAT(error, HasSubstr("vertex 5"));
  EXPECT_THAT(error, HasSubstr("test.g2o:2:"));

  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    std::mt19937_64 rng(6);
    const Poses truth = RandomPoses(d, 4, &rng);
    PoseGraph h = EmptyGraph(d, 4);
    AddExactEdge(&h, truth, 0, 1, 1, 1);
    AddExactEdge(&h, truth, 2, 3, 1, 1);
    ASSERT_FALSE(ValidatePoseGraph(h, &error));
    SolverSummary s;
    const Poses x = Solve(h, SolverOptions(), &s);
    EXPECT_EQ(s.status, Status::kInvalidInput);
    EXPECT_THAT(s.message, HasSubstr("disconnected"));
    EXPECT_TRUE(x.empty());
#if CERES_SESYNC_HAVE_CERTIFY
    Certificate c;
    EXPECT_FALSE(Certify(h, truth, CertifyOptions(), &c, &error));
    EXPECT_FALSE(error.empty());
#endif
  }
}

TEST(DegenerateGraphs, VerticesWithoutEdgesAreAnError) {
  PoseGraph g;
  std::string error;
  EXPECT_FALSE(
      Read("VERTEX_SE2 0 0 0 0\n"
           "VERTEX_SE2 1 1 0 0\n"
           "VERTEX_SE2 42 2 0 0\n"
           "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n",
           &g, &error));
  EXPECT_THAT(error, HasSubstr("disconnected"));
  EXPECT_THAT(error, HasSubstr("2 components"));
  EXPECT_THAT(error, HasSubstr("vertex 42"));
  EXPECT_THAT(error, HasSubstr("test.g2o:3:"));  // Its VERTEX line.

  PoseGraph h = EmptyGraph(3, 3);
  AddEdge(&h, 0, 1, Eigen::MatrixXd::Identity(3, 3), Eigen::Vector3d(1, 0, 0),
          1, 1);
  SolverSummary s;
  EXPECT_TRUE(Solve(h, SolverOptions(), &s).empty());
  EXPECT_EQ(s.status, Status::kInvalidInput);
  EXPECT_THAT(s.message, HasSubstr("disconnected"));
}

// ---- extreme weights, noiseless data ---------------------------------------

// (Was disabled while the trust-region solver could loop forever on
// rejected noise-level steps; that bug is fixed and this runs in ~30 ms.)
TEST(DegenerateGraphs, ExtremeWeightsGiveACleanStatus) {
  for (int d : {2, 3}) {
    std::mt19937_64 rng(7);
    const PoseGraph base = NoisyCycle(d, 8, 1.0, 1.0, &rng);
    SolverSummary s0;
    SolveAndCheck(base, &s0);
    ASSERT_EQ(s0.status, Status::kCertifiedOptimum) << s0.FullReport();
    for (double sk : {1e-8, 1.0, 1e8}) {
      for (double st : {1e-8, 1.0, 1e8}) {
        SCOPED_TRACE(::testing::Message() << "d=" << d << " kappa scale " << sk
                                          << " tau scale " << st);
        PoseGraph g = base;
        for (auto& m : g.measurements) m.kappa *= sk, m.tau *= st;
        SolverSummary s;
        const Poses x = SolveAndCheck(g, &s);
        EXPECT_FALSE(std::isnan(s.relative_suboptimality_bound));
        if (sk == st && s.certified()) {
          // F is homogeneous of degree 1 in the weights, so the optimum
          // scales by sk (both within the 1e-6 certified bound; 1e-7 is what
          // converged solves achieve with margin).
          EXPECT_NEAR(s.objective, sk * s0.objective, 1e-7 * s.objective);
        }
        if (s.certified() && x.size() == static_cast<size_t>(g.num_poses)) {
          CERTIFY_EXPECT(g, x, true);
        }
      }
    }
  }
}

// A chain whose translational weights differ by 1e20: Lbar = [[1 + b, -b],
// [-b, b]] (the gauge pose removed), b = 1e20, is positive definite but
// its Cholesky factorization cancels to a zero pivot in double in either
// elimination order. kInvalidInput with the message, on one thread and on
// two (Lbar then factorized in the background during the chordal
// initialization), and from a given initial guess.
TEST(DegenerateGraphs, NumericallySingularTranslationalLaplacianIsAnError) {
  for (int d : {2, 3}) {
    PoseGraph g = EmptyGraph(d, 3);
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
    AddEdge(&g, 0, 1, I, Eigen::VectorXd::Ones(d), 1.0, 1.0);
    AddEdge(&g, 1, 2, I, Eigen::VectorXd::Ones(d), 1.0, 1e20);
    std::string error;
    ASSERT_TRUE(ValidatePoseGraph(g, &error)) << error;
    for (int threads : {1, 2}) {
      for (bool initial : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "d=" << d << " threads " << threads
                                          << " initial " << initial);
        SolverOptions o;
        o.num_threads = threads;
        SolverSummary s;
        const Poses x =
            initial ? Solve(g, IdentityPoses(d, 3), o, &s) : Solve(g, o, &s);
        EXPECT_EQ(s.status, Status::kInvalidInput);
        EXPECT_EQ(s.message,
                  "the translational Laplacian is not positive definite");
        EXPECT_TRUE(x.empty());
      }
    }
  }
}

TEST(DegenerateGraphs, NoiselessDataIsSolvedExactlyAndCertified) {
  std::mt19937_64 rng(8);
  for (int d : {2, 3}) {
    SCOPED_TRACE(d);
    const int n = 12;
    const Poses truth = RandomPoses(d, n, &rng);
    PoseGraph g = EmptyGraph(d, n);
    std::uniform_real_distribution<double> log_weight(-1, 3);
    for (int k = 0; k < n; ++k) {
      for (int step : {1, 3}) {
        AddExactEdge(&g, truth, k, (k + step) % n,
                     std::pow(10, log_weight(rng)),
                     std::pow(10, log_weight(rng)));
      }
    }
    SolverSummary s;
    const Poses x = SolveAndCheck(g, &s);
    ASSERT_EQ(static_cast<int>(x.size()), n);
    EXPECT_EQ(s.certified(), kZeroOptimumIsCertified) << s.FullReport();
    EXPECT_LE(s.objective, kRoundOff * TermScale(g)) << s.FullReport();
    // The solution is the truth up to the gauge: compare relative poses.
    for (int k = 1; k < n; ++k) {
      EXPECT_LT(
          (x[0].R.transpose() * x[k].R - truth[0].R.transpose() * truth[k].R)
              .norm(),
          1e-6);
      EXPECT_LT((x[0].R.transpose() * (x[k].t - x[0].t) -
                 truth[0].R.transpose() * (truth[k].t - truth[0].t))
                    .norm(),
                1e-6);
    }
    CERTIFY_EXPECT(g, x, kZeroOptimumIsCertified);
    CERTIFY_EXPECT(g, truth, kZeroOptimumIsCertified);
  }
}

}  // namespace
}  // namespace ceres_sesync
