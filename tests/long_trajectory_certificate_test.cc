// Certificates on long trajectories, where the poses are far from pose 0
// (kilometers of corridor) and double precision cannot resolve the
// certificate: the proven shift must bound the true lambda_min(S), computed
// independently in binary128 (__float128) arithmetic from the measurements,
// and the proof must still be tight (relative bound <= 1e-6).
//
// Reference: by Haynsworth's inertia additivity the number of negative
// eigenvalues of S + cI equals that of K_c = [Lbar -Vbar; -Vbar^T
// D - Lambda + cI] (Lbar is positive definite), i.e. the number of negative
// pivots of an LDL^T factorization of K_c. Ordered pose by pose (t_i, R_i),
// K_c of a corridor is banded, so a banded LDL^T in binary128 (assembled
// here from the measurements, independently of the library's matrices) gives
// the inertia at any shift, and bisection gives lambda_min(S).

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "ceres_sesync/certification.h"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/sesync_solver.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

using Quad = __float128;

// A corridor: n poses `step` meters apart along a gently curving path
// (heading h_i = 0.3 sin(i / 40)), odometry plus closures (i, i + k) for
// k = 2..span with probability 0.5, noise from the generative model.
PoseGraph Corridor(int d, int n, double step, int span, uint64_t seed) {
  std::mt19937_64 rng(seed);
  Poses truth(n);
  for (int i = 0; i < n; ++i) {
    const double h = 0.3 * std::sin(i / 40.0);
    Eigen::MatrixXd R = Eigen::MatrixXd::Identity(d, d);
    R(0, 0) = R(1, 1) = std::cos(h);
    R(1, 0) = std::sin(h);
    R(0, 1) = -std::sin(h);
    truth[i].R = R;
    truth[i].t = Eigen::VectorXd::Zero(d);
    if (i > 0) {
      truth[i].t = truth[i - 1].t + truth[i - 1].R.col(0) * step;
      if (d == 3) truth[i].t(2) = std::sin(i / 25.0);
    }
  }
  PoseGraph graph;
  graph.dimension = d;
  for (int i = 0; i < n; ++i) graph.AddVertex(i);
  const double kappa = 200, tau = 50;
  auto add = [&](int i, int j) {
    RelativePoseMeasurement m;
    m.i = i;
    m.j = j;
    m.kappa = kappa;
    m.tau = tau;
    m.R = truth[i].R.transpose() * truth[j].R *
          SampleIsotropicLangevin(d, kappa, &rng);
    m.t = truth[i].R.transpose() * (truth[j].t - truth[i].t);
    for (int a = 0; a < d; ++a) {
      m.t(a) += SampleStandardNormal(&rng) / std::sqrt(tau);
    }
    graph.measurements.push_back(m);
  };
  for (int i = 0; i + 1 < n; ++i) {
    add(i, i + 1);
    for (int k = 2; k <= span && i + k < n; ++k) {
      if (SampleUniform01(&rng) < 0.5) add(i, i + k);
    }
  }
  return graph;
}

// K_c in binary128, banded, unknowns ordered pose by pose: pose i owns
// [t_i (absent for i = 0: the gauge), R_i rows 0..d-1].
class BandedCertificateMatrix {
 public:
  BandedCertificateMatrix(const PoseGraph& graph, int span)
      : d_(graph.dimension), n_(graph.num_poses) {
    offset_.resize(n_ + 1);
    for (int i = 0; i < n_; ++i) offset_[i + 1] = offset_[i] + d_ + (i > 0);
    size_ = offset_[n_];
    band_ = (span + 1) * (d_ + 1);
    base_.assign(static_cast<size_t>(size_) * (band_ + 1), 0);
    // tr(X M X^T) for the residuals of eq. (12), term by term.
    for (const RelativePoseMeasurement& e : graph.measurements) {
      const Quad kappa = e.kappa, tau = e.tau;
      for (int a = 0; a < d_; ++a) {
        // kappa ||R_j - R_i R~||^2 = kappa sum_a ||R_j^a - R_i R~^a||^2 in
        // the rows of R: per row of X, the coefficient vector of the
        // rotation columns: +1 at (j, a), -R~(b, a) at (i, b).
        std::vector<std::pair<int, Quad>> r;
        r.emplace_back(Rotation(e.j, a), 1);
        for (int b = 0; b < d_; ++b) {
          r.emplace_back(Rotation(e.i, b), -Quad(e.R(b, a)));
        }
        AddOuter(r, kappa);
      }
      // tau ||t_j - t_i - R_i t~||^2: coefficients +1 at t_j, -1 at t_i,
      // -t~(b) at (i, b).
      std::vector<std::pair<int, Quad>> t;
      if (e.j > 0) t.emplace_back(Translation(e.j), 1);
      if (e.i > 0) t.emplace_back(Translation(e.i), -1);
      for (int b = 0; b < d_; ++b) {
        t.emplace_back(Rotation(e.i, b), -Quad(e.t(b)));
      }
      AddOuter(t, tau);
    }
  }

  // Negative pivots of LDL^T(K_c) for the multipliers Lambda (d x dn).
  int NegativePivots(const Eigen::MatrixXd& Lambda, double c) const {
    std::vector<Quad> a = base_;
    for (int i = 0; i < n_; ++i) {
      for (int p = 0; p < d_; ++p) {
        for (int q = 0; q <= p; ++q) {
          At(&a, Rotation(i, p), Rotation(i, q)) -= Lambda(p, d_ * i + q);
        }
        At(&a, Rotation(i, p), Rotation(i, p)) += c;
      }
    }
    // In-place banded LDL^T: a(k, k) -> D_k, a(i, k) -> L_ik D_k (i > k).
    int negative = 0;
    for (int k = 0; k < size_; ++k) {
      const int end = std::min(size_, k + band_ + 1);
      const Quad dk = At(&a, k, k);
      if (dk < 0) ++negative;
      if (dk == 0) return size_;  // Singular: treat as indefinite.
      for (int i = k + 1; i < end; ++i) {
        const Quad lik = At(&a, i, k) / dk;
        for (int j = k + 1; j <= i; ++j) At(&a, i, j) -= lik * At(&a, j, k);
      }
    }
    return negative;
  }

 private:
  int Translation(int i) const { return offset_[i]; }
  int Rotation(int i, int a) const { return offset_[i] + (i > 0) + a; }
  // Lower band storage: entry (i >= j, i - j <= band) at j * (band + 1) +
  // (i - j).
  Quad& At(std::vector<Quad>* a, int i, int j) const {
    if (i < j) std::swap(i, j);
    return (*a)[static_cast<size_t>(j) * (band_ + 1) + (i - j)];
  }
  void AddOuter(const std::vector<std::pair<int, Quad>>& v, Quad w) {
    for (const auto& [i, x] : v) {
      for (const auto& [j, y] : v) {
        if (i >= j) {
          ASSERT_LE(i - j, band_);
          At(&base_, i, j) += w * x * y;
        }
      }
    }
  }

  int d_, n_, size_ = 0, band_ = 0;
  std::vector<int> offset_;
  std::vector<Quad> base_;
};

// The smallest shift c with S + cI positive semidefinite (-lambda_min(S)),
// to a relative 1e-3, below `upper` (where S + upper I must be PSD).
double ReferenceShift(const BandedCertificateMatrix& K,
                      const Eigen::MatrixXd& Lambda, double upper) {
  if (K.NegativePivots(Lambda, 0) == 0) return 0;
  double lo = upper * 1e-12, hi = upper;
  if (K.NegativePivots(Lambda, lo) == 0) return lo;
  while (hi / lo > 1 + 1e-3) {
    const double mid = std::sqrt(lo * hi);
    (K.NegativePivots(Lambda, mid) == 0 ? hi : lo) = mid;
  }
  return hi;
}

struct Case {
  int d, n;
  double step;
};

class LongTrajectoryCertificate : public ::testing::TestWithParam<Case> {};

// Solve, then test the proof machinery at the solution's multipliers
// against the binary128 reference: sound, tight, and able to refuse.
TEST_P(LongTrajectoryCertificate, ProvenShiftBoundsTheTrueLambdaMin) {
  const Case c = GetParam();
  const int span = 4;
  const PoseGraph graph = Corridor(c.d, c.n, c.step, span, 11);
  SolverSummary summary;
  const Poses x = Solve(graph, SolverOptions(), &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  EXPECT_LE(summary.relative_suboptimality_bound, 1e-6) << summary.FullReport();
  EXPECT_TRUE(summary.relaxation_exact);

  // Multipliers at the solution's rotations, as Certify computes them.
  internal::SESyncProblem problem(graph);
  ASSERT_TRUE(problem.ok());
  internal::SESyncPreconditioner none(problem,
                                      internal::PreconditionerType::kNone, 1e6);
  internal::SESyncCost cost(&problem, &none);
  const double f = cost.Evaluate(test_util::StackRotations(x));
  const Eigen::MatrixXd Lambda = cost.Lambda();
  const int dn = c.d * c.n;
  internal::VerificationOptions options;
  options.eta_target = 1e-9 * f / dn;
  options.eta_goal = 1e-6 * f / dn;
  options.eta_max = 1e-3 * f / dn;
  internal::CertificateMatrix matrix(problem);
  const internal::VerificationResult v =
      internal::VerifyCertificate(problem, Lambda, options, &matrix);
  ASSERT_TRUE(v.certified);
  EXPECT_LE(v.eta, options.eta_goal);

  const BandedCertificateMatrix reference(graph, span);
  EXPECT_EQ(reference.NegativePivots(Lambda, v.eta), 0)
      << "FALSE CERTIFICATE: S + eta I is indefinite (eta " << v.eta << ")";
  const double true_shift = ReferenceShift(reference, Lambda, v.eta);
  EXPECT_GE(v.eta, true_shift);
  std::printf(
      "d %d n %d (%.0f m from pose 0): proven eta %.3e (%s), "
      "-lambda_min(S) %.3e (binary128), goal %.3e\n",
      c.d, c.n, c.step * c.n, v.eta, internal::ProofPrecisionName(v.precision),
      true_shift, options.eta_goal);

  // As the staircase calls it: with the candidate's translations from pose
  // 0's (those optimal for its rotations) and the hint that it is probably
  // optimal. Double cannot reach the goal here, and the one double-double
  // factorization is all it takes (no double one); the proven shift is as
  // sound and as tight.
  internal::VerificationOptions hinted = options;
  hinted.translation_offsets = matrix.TranslationOffsets(
      problem.RecoverTranslations(test_util::StackRotations(x)));
  hinted.likely_optimal = true;
  // What the translation shifts a fresh matrix's first double proof starts
  // with cost.
  const double first_floor =
      internal::CertificateMatrix(problem).DoubleShiftCost(
          hinted.translation_offsets);
  // The premise (corridors kilometres long): double's floor is above the
  // goal.
  EXPECT_GT(first_floor, options.eta_goal / 4);
  // The verification with `o`: certified within the goal, sound, not below
  // the true shift, by one double-double proof after `factorizations`
  // double ones.
  auto check_hinted = [&](const internal::VerificationOptions& o,
                          int factorizations) {
    internal::CertificateMatrix fresh(problem);
    const internal::VerificationResult u =
        internal::VerifyCertificate(problem, Lambda, o, &fresh);
    ASSERT_TRUE(u.certified);
    EXPECT_LE(u.eta, options.eta_goal);
    EXPECT_EQ(reference.NegativePivots(Lambda, u.eta), 0)
        << "FALSE CERTIFICATE: S + eta I is indefinite (eta " << u.eta << ")";
    EXPECT_GE(u.eta, true_shift);
    EXPECT_EQ(u.factorizations, factorizations);
    EXPECT_EQ(u.extended_factorizations, 1);
    EXPECT_EQ(u.precision, internal::ProofPrecision::kDoubleDouble);
  };
  check_hinted(hinted, 0);
  // The same with the near-optimality test in double first (as the
  // staircase asks on large maps: test_in_double_first): one double
  // factorization at eta_max more, the same double-double proof.
  internal::VerificationOptions hinted_first = hinted;
  hinted_first.test_in_double_first = true;
  check_hinted(hinted_first, 1);

  // Teeth: multipliers raised by delta make lambda_min(S') =
  // lambda_min(S) - delta. Within the goal (delta = goal / 2) the proof must
  // still certify (tightness); beyond it (4 goal) it must not (soundness);
  // and every shift it proves must make S' + eta I PSD in binary128.
  // Lambda + delta I, block by block.
  auto raise = [&](double delta) {
    Eigen::MatrixXd raised = Lambda;
    for (int i = 0; i < c.n; ++i) {
      raised.middleCols(c.d * i, c.d) +=
          delta * Eigen::MatrixXd::Identity(c.d, c.d);
    }
    return raised;
  };
  for (double factor : {0.5, 4.0}) {
    const Eigen::MatrixXd raised =
        raise(factor * options.eta_goal + true_shift);
    internal::VerificationOptions limit = options;
    limit.eta_max = limit.eta_goal = options.eta_goal;
    const internal::VerificationResult w =
        internal::VerifyCertificate(problem, raised, limit, &matrix);
    SCOPED_TRACE("delta = " + std::to_string(factor) + " goal");
    EXPECT_EQ(w.certified, factor < 1) << "eta " << w.eta;
    EXPECT_EQ(reference.NegativePivots(raised, options.eta_goal) > 0,
              factor > 1);
    if (std::isfinite(w.eta)) {
      EXPECT_EQ(reference.NegativePivots(raised, w.eta), 0)
          << "FALSE CERTIFICATE at eta " << w.eta;
    }
    // A wrong hint (not near-optimal at 4 goal) changes the cost, not the
    // verdict.
    internal::VerificationOptions hinted_limit = limit;
    hinted_limit.translation_offsets = hinted.translation_offsets;
    hinted_limit.likely_optimal = true;
    const internal::VerificationResult h =
        internal::VerifyCertificate(problem, raised, hinted_limit, &matrix);
    EXPECT_EQ(h.certified, factor < 1) << "eta " << h.eta;
    if (std::isfinite(h.eta)) {
      EXPECT_EQ(reference.NegativePivots(raised, h.eta), 0)
          << "FALSE CERTIFICATE at eta " << h.eta;
    }
  }

  // A lifted saddle behind the hint, as the staircase meets them on large
  // maps (a 10^6-pose city: lambda_min(S) = -3 eta_max, eta_max above
  // double's floor): multipliers raised to lambda_min(S') = -4 eta_max.
  // After the failed double-double proof the witness comes from the
  // ladder's first shift (64 eta_max, or 16 where 64 is at or above the
  // vacuous shift tr(Lambda) / dn), proven in double with no
  // near-optimality test (a factorization at eta_max) and no poor-candidate
  // test (one at tr(Lambda) / dn) before it; then one proof just above the
  // Lanczos estimate (tighten_uncertified). Those two tests would be two
  // factorizations more.
  internal::CertificateMatrix saddle_matrix(problem);
  internal::VerificationOptions saddle = hinted;
  saddle.eta_max = std::max(options.eta_max, 8 * first_floor);
  const Eigen::MatrixXd raised = raise(4 * saddle.eta_max + true_shift);
  const internal::VerificationResult s =
      internal::VerifyCertificate(problem, raised, saddle, &saddle_matrix);
  EXPECT_FALSE(s.certified);
  EXPECT_FALSE(s.vacuous_bound);
  EXPECT_LT(s.direction_curvature, -saddle.eta_max);
  EXPECT_EQ(s.extended_factorizations, 1);
  EXPECT_EQ(s.factorizations, 2);
  ASSERT_TRUE(std::isfinite(s.eta));
  EXPECT_EQ(reference.NegativePivots(raised, s.eta), 0)
      << "FALSE CERTIFICATE at eta " << s.eta;
  EXPECT_LT(s.eta, 16 * saddle.eta_max);  // Tightened below the witness's.

  // A deeper saddle, lambda_min(S') = -40 eta_max (a 10^6-pose city:
  // -26 eta_max): the ladder's first shift, 64 eta_max, proves, before the
  // poor-candidate test; then the tightening: two factorizations (three
  // with a first shift of 16 eta_max, which fails, then 256; four with the
  // poor-candidate test first).
  // Its tolerance half of double's floor (large maps' is below the floor
  // too), so that the ladder's shifts are above the floor and 256 eta_max
  // below tr(Lambda') / dn, where the poor-candidate test factorizes.
  internal::CertificateMatrix deep_matrix(problem);
  internal::VerificationOptions deeper = hinted;
  deeper.eta_max = std::max(options.eta_max, 0.5 * first_floor);
  const double deep_delta = 40 * deeper.eta_max + true_shift;
  const Eigen::MatrixXd deep = raise(deep_delta);
  ASSERT_LT(256 * deeper.eta_max,
            internal::BlockDiagonalTrace(deep, c.d) / deep.cols());
  // lambda_min(S') = lambda_min(S) - deep_delta, to ReferenceShift's 1e-3.
  const double deep_lambda_min = -(true_shift + deep_delta);
  // The deep saddle's verification with `o`: not certified, `extended` and
  // `factorizations` factorizations, a sound proof tightened below the
  // witness's shift, the witness's curvature at lambda_min(S').
  auto check_deep_saddle = [&](const internal::VerificationOptions& o,
                               int extended, int factorizations) {
    internal::CertificateMatrix m(problem);
    const internal::VerificationResult t =
        internal::VerifyCertificate(problem, deep, o, &m);
    EXPECT_FALSE(t.certified);
    EXPECT_FALSE(t.vacuous_bound);
    EXPECT_EQ(t.extended_factorizations, extended);
    EXPECT_EQ(t.factorizations, factorizations);
    ASSERT_TRUE(std::isfinite(t.eta));
    EXPECT_EQ(reference.NegativePivots(deep, t.eta), 0)
        << "FALSE CERTIFICATE at eta " << t.eta;
    EXPECT_LT(t.eta, 64 * deeper.eta_max);  // Tightened below the witness's.
    EXPECT_LE(t.direction_curvature, 0.99 * deep_lambda_min);
    EXPECT_GE(t.direction_curvature, 1.001 * deep_lambda_min);
  };
  check_deep_saddle(deeper, 1, 2);
  // The same saddle with the near-optimality test in double first: the
  // failed double-double proof becomes a failed double factorization at
  // eta_max, and the candidate is taken for a saddle as after it (the
  // ladder's first shift, the witness, the tightening as above).
  internal::VerificationOptions deeper_first = deeper;
  deeper_first.test_in_double_first = true;
  check_deep_saddle(deeper_first, 0, 3);

  // As the staircase calls it below its top rank (tighten_uncertified
  // false): the witness alone, from a looser Lanczos tolerance, one
  // factorization in double; its curvature (a Rayleigh quotient, >= lambda_min)
  // is still within 5% of lambda_min(S') (measured: 0.2% with the tight
  // tolerance, 2.5% with the loose one, on the 2D corridor).
  internal::VerificationOptions escape = deeper;
  escape.tighten_uncertified = false;
  internal::CertificateMatrix escape_matrix(problem);
  const internal::VerificationResult e =
      internal::VerifyCertificate(problem, deep, escape, &escape_matrix);
  EXPECT_FALSE(e.certified);
  EXPECT_EQ(e.factorizations, 1);
  EXPECT_EQ(e.extended_factorizations, 1);
  EXPECT_EQ(e.direction.size(), c.d * c.n);
  EXPECT_LE(e.direction_curvature, 0.95 * deep_lambda_min);
  EXPECT_GE(e.direction_curvature, 1.001 * deep_lambda_min);
  ASSERT_TRUE(std::isfinite(e.eta));
  EXPECT_EQ(reference.NegativePivots(deep, e.eta), 0)
      << "FALSE CERTIFICATE at eta " << e.eta;

  // The tightening of a shift proven already (a certificate test during
  // the descent after an escape passed: known_shift), in double as the
  // staircase runs it when the relaxation is not exact. lambda_min(S') =
  // -2 double floors: a factor at the known shift, the Lanczos estimate,
  // and one proof at the first shift of the ladder, which must allow for
  // what the proofs' translation shift costs (about one floor): two
  // factorizations, and a shift within 2x of -lambda_min. Starting 10%
  // above the estimate (2.2 floors) failed there, and the ladder's next
  // shift, 8x higher, was the result (three factorizations).
  const double floor = first_floor;
  const double known_delta = 2 * floor + true_shift;
  const Eigen::MatrixXd near = raise(known_delta);
  internal::VerificationOptions known = hinted;
  known.policy = internal::ProofPolicy::kDouble;
  known.likely_optimal = false;
  known.eta_max = 128 * floor;
  // The verification of `near` with S' + shift I proven (a fresh matrix).
  auto verify_known = [&](double shift) {
    known.known_shift = shift;
    EXPECT_EQ(reference.NegativePivots(near, shift), 0) << "not proven";
    internal::CertificateMatrix matrix(problem);
    return internal::VerifyCertificate(problem, near, known, &matrix);
  };
  const internal::VerificationResult k = verify_known(64 * floor);
  EXPECT_TRUE(k.certified);
  EXPECT_EQ(k.factorizations, 2);
  EXPECT_EQ(k.extended_factorizations, 0);
  EXPECT_NEAR(k.lambda_min_estimate, -known_delta, 1e-3 * known_delta);
  EXPECT_LT(k.eta, 2 * known_delta);
  EXPECT_EQ(reference.NegativePivots(near, k.eta), 0)
      << "FALSE CERTIFICATE at eta " << k.eta;

  // The same with the test's double factor still held (the staircase keeps
  // a passed double test's factor: known_shift_factor). Its Lanczos
  // estimate is of S'_M, the test's translation shifts M costing about a
  // floor: where lambda_min(S') is far below that (-40 floors), the
  // estimate is used and the factorization at the known shift saved, with
  // the same kind of tightened shift; near it (-2 floors, as above) the
  // estimate would start the proofs too high, and a factor at the known
  // shift is made after all (as many factorizations, as tight a shift).
  auto verify_held = [&](const Eigen::MatrixXd& lambda, double delta,
                         internal::VerificationResult* fresh) {
    internal::VerificationOptions o = known;
    o.known_shift = 64 * delta;
    {
      internal::CertificateMatrix matrix(problem);
      *fresh = internal::VerifyCertificate(problem, lambda, o, &matrix);
    }
    internal::CertificateMatrix matrix(problem);
    EXPECT_TRUE(
        matrix.Prove(lambda, o.known_shift, internal::ProofPrecision::kDouble));
    o.known_shift_factor = o.known_shift;
    o.known_shift = matrix.proven_shift();
    return internal::VerifyCertificate(problem, lambda, o, &matrix);
  };
  for (const double delta : {40 * floor + true_shift, known_delta}) {
    SCOPED_TRACE("lambda_min(S') = -" + std::to_string(delta / floor) +
                 " floors");
    const Eigen::MatrixXd lambda = raise(delta);
    internal::VerificationResult fresh;
    const internal::VerificationResult h = verify_held(lambda, delta, &fresh);
    EXPECT_TRUE(fresh.certified);
    EXPECT_TRUE(h.certified);
    EXPECT_EQ(h.factorizations,
              fresh.factorizations - (delta > 10 * floor ? 1 : 0));
    EXPECT_EQ(h.extended_factorizations, 0);
    EXPECT_NEAR(h.lambda_min_estimate, -delta, 0.05 * delta);
    EXPECT_LE(h.lambda_min_estimate, fresh.lambda_min_estimate + 1e-3 * delta);
    EXPECT_LT(h.eta, 2 * delta);
    EXPECT_EQ(reference.NegativePivots(lambda, h.eta), 0)
        << "FALSE CERTIFICATE at eta " << h.eta;
  }

  // A known shift within 2x of what double reaches (1.5 floors; a descent's
  // test proven at double's reach, internal::PlanDescentTest) is not
  // tightened: the factor and the Lanczos estimate would cost about three
  // factorizations for less than a 2x tighter bound. Just above 2x the
  // tightening runs (a factor at the known shift and the estimate; here its
  // ladder's first shift, above -lambda_min by what the translation shift
  // costs, is not below the known one, so nothing tighter is proven).
  const double reach = 1.5 * floor;
  const internal::VerificationResult r = verify_known(1.9 * reach);
  EXPECT_TRUE(r.certified);
  EXPECT_EQ(r.factorizations, 0);
  EXPECT_EQ(r.extended_factorizations, 0);
  EXPECT_EQ(r.eta, 1.9 * reach);
  const internal::VerificationResult a = verify_known(2.1 * reach);
  EXPECT_TRUE(a.certified);
  EXPECT_GE(a.factorizations, 1);
  EXPECT_LE(a.eta, 2.1 * reach);
  EXPECT_EQ(reference.NegativePivots(near, a.eta), 0)
      << "FALSE CERTIFICATE at eta " << a.eta;
}

INSTANTIATE_TEST_SUITE_P(Corridors, LongTrajectoryCertificate,
                         ::testing::Values(Case{2, 2000, 5.0},
                                           Case{3, 600, 10.0}),
                         [](const auto& info) {
                           return "d" + std::to_string(info.param.d) + "n" +
                                  std::to_string(info.param.n);
                         });

// Certify on the same kind of graph: the optimum certifies tightly, a tiny
// perturbation of it (1e-7 rad, far below the noise) still certifies, and a
// clearly suboptimal candidate (one pose turned by 0.1 rad) never does.
TEST(LongTrajectoryCertificate, CertifyIsTightAndDiscriminating) {
  const PoseGraph graph = Corridor(2, 3000, 5.0, 4, 12);
  SolverSummary summary;
  const Poses optimum = Solve(graph, SolverOptions(), &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  auto turned = [](const Poses& poses, int i, double angle) {
    Poses out = poses;
    Eigen::Matrix2d G;
    G << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    out[i].R = out[i].R * G;
    return out;
  };
  std::string error;
  Certificate exact, tiny, clear;
  ASSERT_TRUE(Certify(graph, optimum, {}, &exact, &error)) << error;
  EXPECT_TRUE(exact.certified) << exact.FullReport();
  EXPECT_LE(exact.relative_suboptimality_bound, 1e-6) << exact.FullReport();
  Poses slightly = optimum;
  for (int i = 0; i < graph.num_poses; i += 7)
    slightly = turned(slightly, i, 1e-7);
  ASSERT_TRUE(Certify(graph, slightly, {}, &tiny, &error)) << error;
  EXPECT_TRUE(tiny.certified) << tiny.FullReport();
  EXPECT_LE(tiny.relative_suboptimality_bound, 1e-6) << tiny.FullReport();
  ASSERT_TRUE(Certify(graph, turned(optimum, 1500, 0.1), {}, &clear, &error))
      << error;
  EXPECT_FALSE(clear.certified) << clear.FullReport();
  EXPECT_LE(clear.lower_bound, summary.objective);
}

}  // namespace
}  // namespace ceres_sesync
