// Property tests for Solve and Certify on random small pose graphs.
//
// Instances: d = 2, 3; topologies tree, cycle, dense (Erdos-Renyi on top of a
// spanning path) and parallel edges (a cycle with repeated, independently
// noisy edges); per-edge kappa and tau log-uniform over 1e-3 .. 1e3 (six
// orders of magnitude); noise levels: noiseless, moderate, and very noisy
// (rotation noise near uniform, translation noise larger than the poses'
// spacing). The weights are drawn independently of the noise, so they are
// arbitrary positive weights, not the true precisions.
//
// Invariants checked on every instance:
//  1. No crash, no NaN: the status is not kInvalidInput; objective, lower
//     bound and poses are finite (the lower bound may be -inf when not
//     certified), the poses are in SE(d).
//  2. lower_bound <= objective.
//  3. best = min(F) over SE-Sync from 3 random starts and Ceres LM from the
//     chordal initialization; every certified result (of Solve or of Certify)
//     has objective <= best * (1 + 1e-8), and every proven lower bound is
//     <= best (a lower bound on the optimum is below every feasible value),
//     i.e. best >= lower_bound * (1 - 1e-12).
//  4. Determinism: the same call twice gives bit-identical poses and
//     summaries (chordal and seeded random initializations, Certify).
//
// Tolerances: 1e-8 and 1e-12 are relative (as asked of the solver: a
// certified solution is optimal far below the 1e-6 certification threshold
// once converged). Values that are zero in exact arithmetic (noiseless data,
// trees) are compared with an absolute allowance of 1e-10 * W, W = sum of
// kappa (2d) + tau (1 + |t~|^2) over the edges (the scale of the objective's
// terms), for round-off in the sparse factorizations.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gtest/gtest.h"

// Certify's implementation is being written; until
// ceres_sesync/certification.cc exists the Certify properties are skipped so
// that the suite links (re-run cmake/touch this file once it lands).
#if __has_include("ceres_sesync/certification.cc")
#define CERES_SESYNC_HAVE_CERTIFY 1
#else
#define CERES_SESYNC_HAVE_CERTIFY 0
#endif

namespace ceres_sesync {
namespace {

using Status = SolverSummary::Status;

enum class Topology { kTree, kCycle, kDense, kParallel };
enum class Noise { kNone, kModerate, kVeryNoisy };

const char* Name(Topology t) {
  switch (t) {
    case Topology::kTree:
      return "tree";
    case Topology::kCycle:
      return "cycle";
    case Topology::kDense:
      return "dense";
    case Topology::kParallel:
      return "parallel";
  }
  return "?";
}

const char* Name(Noise n) {
  switch (n) {
    case Noise::kNone:
      return "noiseless";
    case Noise::kModerate:
      return "moderate";
    case Noise::kVeryNoisy:
      return "very noisy";
  }
  return "?";
}

Eigen::MatrixXd UniformRotation(int d, std::mt19937_64* rng) {
  return SampleIsotropicLangevin(d, 0.0, rng);  // kappa = 0: uniform angle.
}

Eigen::VectorXd Gaussian(int d, double sigma, std::mt19937_64* rng) {
  Eigen::VectorXd v(d);
  for (int k = 0; k < d; ++k) v(k) = sigma * SampleStandardNormal(rng);
  return v;
}

// A random graph with `n` poses; see the top of the file.
PoseGraph RandomGraph(int d, int n, Topology topology, Noise noise,
                      std::mt19937_64* rng) {
  PoseGraph g;
  g.dimension = d;
  for (int k = 0; k < n; ++k) g.AddVertex(100 + 3 * k);
  Poses truth(n);
  for (int k = 0; k < n; ++k) {
    truth[k].R = UniformRotation(d, rng);
    truth[k].t = Gaussian(d, 3.0, rng);
  }
  std::vector<std::pair<int, int>> edges;
  auto uniform_int = [&](int lo, int hi) {
    return lo + static_cast<int>(SampleUniform01(rng) * (hi - lo + 1));
  };
  switch (topology) {
    case Topology::kTree:
      for (int j = 1; j < n; ++j) edges.emplace_back(uniform_int(0, j - 1), j);
      break;
    case Topology::kCycle:
      for (int k = 0; k < n; ++k) edges.emplace_back(k, (k + 1) % n);
      break;
    case Topology::kDense:
      for (int k = 0; k + 1 < n; ++k) edges.emplace_back(k, k + 1);
      for (int i = 0; i < n; ++i) {
        for (int j = i + 2; j < n; ++j) {
          if (SampleUniform01(rng) < 0.5) edges.emplace_back(i, j);
        }
      }
      break;
    case Topology::kParallel:
      for (int k = 0; k < n; ++k) {
        const int copies = uniform_int(1, 3);
        for (int c = 0; c < copies; ++c) edges.emplace_back(k, (k + 1) % n);
      }
      break;
  }
  for (auto [i, j] : edges) {
    if (SampleUniform01(rng) < 0.3) std::swap(i, j);  // Mixed orientations.
    RelativePoseMeasurement m;
    m.i = i;
    m.j = j;
    m.R = truth[i].R.transpose() * truth[j].R;
    m.t = truth[i].R.transpose() * (truth[j].t - truth[i].t);
    if (noise == Noise::kModerate) {
      m.R = m.R * SampleIsotropicLangevin(d, 20.0, rng);
      m.t += Gaussian(d, 0.2, rng);
    } else if (noise == Noise::kVeryNoisy) {
      m.R = m.R * SampleIsotropicLangevin(d, 0.3, rng);
      m.t += Gaussian(d, 5.0, rng);
    }
    m.kappa = std::pow(10.0, -3 + 6 * SampleUniform01(rng));
    m.tau = std::pow(10.0, -3 + 6 * SampleUniform01(rng));
    g.measurements.push_back(m);
  }
  return g;
}

double TermScale(const PoseGraph& g) {
  double w = 0;
  for (const auto& m : g.measurements) {
    w += m.kappa * 2 * g.dimension + m.tau * (1 + m.t.squaredNorm());
  }
  return w;
}

bool FinitePosesInSE(const PoseGraph& g, const Poses& x) {
  const int d = g.dimension;
  if (static_cast<int>(x.size()) != g.num_poses) return false;
  for (const Pose& p : x) {
    if (p.R.rows() != d || p.R.cols() != d || p.t.size() != d ||
        !p.R.allFinite() || !p.t.allFinite()) {
      return false;
    }
    if ((p.R.transpose() * p.R - Eigen::MatrixXd::Identity(d, d)).norm() >
            1e-9 ||
        std::abs(p.R.determinant() - 1) > 1e-9) {
      return false;
    }
  }
  return true;
}

bool BitIdentical(const Poses& a, const Poses& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k) {
    if (a[k].R != b[k].R || a[k].t != b[k].t) return false;
  }
  return true;
}

// Bitwise equality of doubles (NaN == NaN, -0 != +0 does not matter here).
bool Same(double a, double b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

void CheckSummary(const PoseGraph& g, const Poses& x, const SolverSummary& s) {
  ASSERT_NE(s.status, Status::kInvalidInput) << s.message;
  EXPECT_TRUE(FinitePosesInSE(g, x));
  EXPECT_TRUE(std::isfinite(s.objective)) << s.FullReport();
  EXPECT_FALSE(std::isnan(s.lower_bound)) << s.FullReport();
  EXPECT_FALSE(std::isnan(s.sdp_value)) << s.FullReport();
  EXPECT_FALSE(std::isnan(s.relative_suboptimality_bound)) << s.FullReport();
  if (s.certified()) {
    EXPECT_TRUE(std::isfinite(s.lower_bound));
  }
  // Invariant 2.
  EXPECT_LE(s.lower_bound, s.objective * (1 + 1e-12) + 1e-13 * TermScale(g))
      << s.FullReport();
}

struct Case {
  int d;
  int n;
  Topology topology;
  Noise noise;
  uint64_t seed;
};

class SolverProperties : public ::testing::TestWithParam<Case> {};

TEST_P(SolverProperties, Invariants) {
  const Case c = GetParam();
  std::mt19937_64 rng(c.seed);
  const PoseGraph g = RandomGraph(c.d, c.n, c.topology, c.noise, &rng);
  std::string error;
  ASSERT_TRUE(ValidatePoseGraph(g, &error)) << error;
  const double slack = 1e-10 * TermScale(g);

  // SE-Sync from the chordal initialization, twice (determinism).
  SolverOptions options;
  SolverSummary s, s_again;
  const Poses x = Solve(g, options, &s);
  CheckSummary(g, x, s);
  const Poses x_again = Solve(g, options, &s_again);
  EXPECT_TRUE(BitIdentical(x, x_again));
  EXPECT_EQ(s.status, s_again.status);
  EXPECT_TRUE(Same(s.objective, s_again.objective));
  EXPECT_TRUE(Same(s.lower_bound, s_again.lower_bound));
  EXPECT_EQ(s.iterations, s_again.iterations);

  // SE-Sync from 3 random starts (each deterministic for its seed).
  double best = s.objective;
  double max_lower_bound = s.lower_bound;
  std::vector<std::pair<Poses, SolverSummary>> certified_results;
  if (s.certified()) certified_results.emplace_back(x, s);
  for (uint64_t seed : {1, 2, 3}) {
    SolverOptions random = options;
    random.initialization = SolverOptions::Initialization::kRandom;
    random.seed = seed;
    SolverSummary r, r_again;
    const Poses y = Solve(g, random, &r);
    CheckSummary(g, y, r);
    if (seed == 1) {
      const Poses y_again = Solve(g, random, &r_again);
      EXPECT_TRUE(BitIdentical(y, y_again));
      EXPECT_TRUE(Same(r.objective, r_again.objective));
    }
    best = std::min(best, r.objective);
    max_lower_bound = std::max(max_lower_bound, r.lower_bound);
    if (r.certified()) certified_results.emplace_back(y, r);
  }

  // Ceres Levenberg-Marquardt from the chordal initialization.
  Poses chordal;
  ASSERT_TRUE(ChordalInitialization(g, &chordal, &error)) << error;
  CeresBaselineOptions lm_options;
  lm_options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
  lm_options.function_tolerance = 1e-12;
  Poses lm;
  CeresBaselineSummary lm_summary;
  ASSERT_TRUE(SolveWithCeres(g, chordal, lm_options, &lm, &lm_summary, &error))
      << error;
  EXPECT_TRUE(FinitePosesInSE(g, lm));
  const double f_lm = EvaluateObjective(g, lm);
  EXPECT_TRUE(std::isfinite(f_lm));
  best = std::min(best, f_lm);

  // Invariant 3.
  for (const auto& [y, r] : certified_results) {
    EXPECT_LE(r.objective, best * (1 + 1e-8) + slack) << r.FullReport();
  }
  EXPECT_GE(best, max_lower_bound * (1 - 1e-12) - slack);

#if CERES_SESYNC_HAVE_CERTIFY
  // Certify the SE-Sync and the LM solutions.
  const Poses* const candidates[] = {&x, &lm};
  for (const Poses* candidate : candidates) {
    Certificate cert, cert_again;
    ASSERT_TRUE(Certify(g, *candidate, CertifyOptions(), &cert, &error))
        << error;
    ASSERT_TRUE(Certify(g, *candidate, CertifyOptions(), &cert_again, &error))
        << error;
    EXPECT_EQ(cert.certified, cert_again.certified);
    EXPECT_TRUE(Same(cert.lower_bound, cert_again.lower_bound));
    EXPECT_TRUE(Same(cert.eta, cert_again.eta));
    EXPECT_TRUE(std::isfinite(cert.objective));
    EXPECT_FALSE(std::isnan(cert.lower_bound));
    EXPECT_NEAR(cert.objective, EvaluateObjective(g, *candidate),
                1e-12 * cert.objective + 1e-3 * slack);
    EXPECT_LE(cert.lower_bound, cert.objective * (1 + 1e-12) + slack);
    EXPECT_GE(best, cert.lower_bound * (1 - 1e-12) - slack)
        << cert.FullReport();
    if (cert.certified) {
      EXPECT_LE(cert.objective, best * (1 + 1e-8) + slack) << cert.FullReport();
    }
  }
  // A solution SE-Sync certified is certified by Certify too.
  if (s.certified()) {
    Certificate cert;
    ASSERT_TRUE(Certify(g, x, CertifyOptions(), &cert, &error)) << error;
    EXPECT_TRUE(cert.certified) << cert.FullReport();
  }
#endif
}

std::vector<Case> AllCases() {
  std::vector<Case> cases;
  uint64_t seed = 1000;
  for (int d : {2, 3}) {
    for (Topology t : {Topology::kTree, Topology::kCycle, Topology::kDense,
                       Topology::kParallel}) {
      for (Noise noise : {Noise::kNone, Noise::kModerate, Noise::kVeryNoisy}) {
        const int n = t == Topology::kDense ? 8 : 12;
        cases.push_back({d, n, t, noise, seed++});
      }
    }
  }
  return cases;
}

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = std::string("d") + std::to_string(info.param.d) + "_" +
                     Name(info.param.topology) + "_" + Name(info.param.noise);
  std::replace(name.begin(), name.end(), ' ', '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(RandomGraphs, SolverProperties,
                         ::testing::ValuesIn(AllCases()), CaseName);

}  // namespace
}  // namespace ceres_sesync
