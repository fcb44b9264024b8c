#include "ceres_sesync/internal/staircase.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "ceres_sesync/internal/ceres_local_solver.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/objective_bound.h"
#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/internal/tangent_newton.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

constexpr char kLbarNotPositiveDefinite[] =
    "the translational Laplacian is not positive definite";

// The summary's counts of a weighted problem: its terms of positive weight.
void CountPositiveTerms(const PoseGraph& graph,
                        const MeasurementWeights& weights, SolverSummary* s) {
  auto positive = [&](size_t begin, size_t end) {
    return static_cast<int>(std::count_if(weights.begin() + begin,
                                          weights.begin() + end,
                                          [](double w) { return w > 0; }));
  };
  const size_t m = graph.measurements.size();
  const size_t landmark_end = PriorTerm(graph, 0);
  s->num_measurements = positive(0, m);
  s->num_landmark_measurements = positive(m, landmark_end);
  s->num_priors = positive(landmark_end, NumWeightedTerms(graph));
}

// Factorizations of at least this many multiply-adds (a double-double one
// ~4 s on two threads here) test a likely optimal candidate's
// near-optimality in double before its double-double proof
// (VerificationOptions::test_in_double_first). The maps that large that
// were measured ended their first level at a lifted saddle (the 10^6-pose
// city: rank-4 verification 61-65 -> 32-37 s, three pairs of runs); below it
// the kappa-100 10^5-pose city, certified at rank 4, would pay 11-23% for
// the test, while the kappa-30 ones, saddles, would gain 0-16%.
constexpr double kDoubleFirstMinFlops = 1e10;

// A level's test near convergence (SolverOptions::
// test_certificate_near_convergence) comes once the Riemannian gradient's
// norm is at most this many times the test's shift (a sixteenth of the
// goal's). Measured at the end of every iteration of the first level on the
// 12 datasets with double-double proofs at that shift: the proof held at
// every point with a ratio <= 1.15e7 and failed at every one >= 1.18e7 (an
// iteration earlier the ratios are 10-1000x larger). So just below that gap:
// a test that fails costs a factorization and ends the level's tests; one an
// iteration late saves less.
constexpr double kNearConvergenceRatio = 1e7;

PreconditionerType ToInternal(SolverOptions::Preconditioner p) {
  switch (p) {
    case SolverOptions::Preconditioner::kNone:
      return PreconditionerType::kNone;
    case SolverOptions::Preconditioner::kBlockJacobi:
      return PreconditionerType::kBlockJacobi;
    case SolverOptions::Preconditioner::kSparseCholesky:
      return PreconditionerType::kSparseCholesky;
    case SolverOptions::Preconditioner::kRegularizedQ:
      return PreconditionerType::kRegularizedQ;
    case SolverOptions::Preconditioner::kAutomatic:
      break;  // Resolved by ChoosePreconditioner.
  }
  return PreconditionerType::kRegularizedQ;
}

// SolverOptions::Preconditioner::kAutomatic: block-Jacobi (kAdaptive, with
// the switch rule below) where K_eps's factorization costs more than this
// many applications of its factor at the initial rank, else kRegularizedQ.
// Measured ratios: 2D cities 4.1 (1000 poses) to 24.7 (10^5 poses),
// city10000 5.3, cubicle and sphere2500 7.6, torus3D 11.0, smallGrid3D 3.2
// (block-Jacobi faster on all but cubicle and torus3D: 8% and 2% slower
// there); kitti_00 and the generated 3D cubes 0.5-0.8, ais2klinik and CSAIL
// 0.6, intel 1.0, parking-garage 1.7, manhattan 2.2 (block-Jacobi 2.8-25x
// slower).
constexpr double kDenseFactorSolves = 3;
// ... and block-Jacobi switches to the exact preconditioner once its
// truncated-CG iterations exceed this multiple of that ratio in all (a
// bound on what a wrong choice costs: each block-Jacobi product costs 0.25-
// 0.5 applications of the factor, so 5-10 factorizations' worth).
// Block-Jacobi's own totals on the sets above: 4.9 (10^5-pose city) to 19
// (city10000) times the ratio; cubicle's 38.
constexpr double kBlockJacobiBudget = 20;

// 2D: the Newton system from the start of the first level where its
// factorization costs at most this many solves of its factor (estimate
// below). Two threads, against the default before it: city10000 (10.5)
// 1.6x faster; 2D cities of 10^4 poses (21) the same, of 10^5 (49) 0.7x
// (one Newton factorization there costs more than block-Jacobi's ~120
// products); the other 2D datasets (1.0-4.4) 1.08x (CSAIL) to 1.46x
// (intel) faster, on one thread 0.95x (CSAIL) to 1.31x (intel).
constexpr double kNewtonFromStartSolves = 16;

// The 2D Newton system's (and K's) factorization cost in solves of its
// factor with d rows, from the vertex pattern's analysis: blocks of b = d + 1
// give b^3 times the flops and b^2 times the entries, a solve costs 4 d
// multiply-adds per entry, CHOLMOD counts 2 flops per multiply-add: b / (4 d)
// flops per entry (3/8 of it in 2D; K's measured cost at rank d: CSAIL 1.11
// against 1.23 estimated, manhattan 4.37 / 4.34, city10000 10.50 / 10.37, a
// 10^5-pose city 49.4 / 48.8).
double NewtonCostInSolves(const SESyncProblem& problem) {
  const int d = problem.dimension();
  return (d + 1.0) / (4.0 * d) * problem.vertex_flops_per_entry();
}

struct PreconditionerChoice {
  PreconditionerType type;
  PreconditionerSettings settings;
  bool exact = false;  // (Q + eps I)^-1 chosen (kAdaptive: when first used).
};

PreconditionerChoice ChoosePreconditioner(const SolverOptions& options,
                                          const CertificateMatrix& K, int r0,
                                          bool newton_from_start) {
  PreconditionerChoice choice{ToInternal(options.preconditioner), {}};
  if (options.preconditioner != SolverOptions::Preconditioner::kAutomatic) {
    return choice;
  }
  const double ratio = K.FactorizationCostInSolves(r0);
  if (!(ratio > kDenseFactorSolves)) {
    // With the Newton preconditioner at rank d from the start, K_eps is
    // factorized only where it is used: above rank d, or where Newton cannot
    // be (SESyncCost's exact fallback makes this kAdaptive exact then).
    choice.type = newton_from_start ? PreconditionerType::kAdaptive
                                    : PreconditionerType::kRegularizedQ;
    choice.exact = true;
    return choice;
  }
  choice.type = PreconditionerType::kAdaptive;
  choice.settings.switch_iterations = 0;
  choice.settings.switch_at_convergence = false;
  choice.settings.switch_total_iterations =
      static_cast<int>(std::ceil(kBlockJacobiBudget * ratio));
  return choice;
}

// SolverSummary::preconditioner.
std::string PreconditionerName(const SESyncPreconditioner& p) {
  switch (p.type()) {
    case PreconditionerType::kNone:
      return "none";
    case PreconditionerType::kBlockJacobi:
      return "block-Jacobi";
    case PreconditionerType::kSparseCholesky:
      return "sparse Cholesky of D";
    case PreconditionerType::kRegularizedQ:
      return "exact (Q + eps I)^-1";
    case PreconditionerType::kAdaptive:
      if (!p.exact()) return "block-Jacobi";
      // Made exact before block-Jacobi ran (at an escape, or standing in
      // lazily for the Newton system): the exact one alone.
      if (p.block_jacobi_iterations() == 0) return "exact (Q + eps I)^-1";
      return "exact (Q + eps I)^-1 after " +
             std::to_string(p.block_jacobi_iterations()) +
             " block-Jacobi iterations";
  }
  return "";
}

double MaxDiagonal(const SparseMatrix& A) {
  double m = 0;
  for (int k = 0; k < A.rows(); ++k) m = std::max(m, A.coeff(k, k));
  return m;
}

RiemannianTrustRegionOptions TrustRegionOptions(const SolverOptions& options) {
  RiemannianTrustRegionOptions rtr;
  rtr.max_iterations = options.max_iterations;
  rtr.max_inner_iterations = options.max_inner_iterations;
  rtr.gradient_tolerance = 0;
  rtr.relative_decrease_tolerance = options.relative_decrease_tolerance;
  return rtr;
}

}  // namespace

DescentTestPlan PlanDescentTest(double half_shift, double three_quarters_shift,
                                double double_reach,
                                SolverOptions::ProofArithmetic arithmetic) {
  using Arithmetic = SolverOptions::ProofArithmetic;
  DescentTestPlan test;
  test.eta = half_shift;
  if (arithmetic != Arithmetic::kDoubleDouble && double_reach <= half_shift) {
    return test;  // In double at half the tolerance's shift.
  }
  // Double-double's price from here on, whichever arithmetic runs.
  test.price = 1.5;
  if (arithmetic != Arithmetic::kDoubleDouble &&
      double_reach <= three_quarters_shift) {
    test.eta = double_reach;
    return test;
  }
  test.run = arithmetic != Arithmetic::kDouble;
  test.precision = ProofPrecision::kDoubleDouble;
  return test;
}

Solution ToSolutionInGauge(const PoseGraph& graph, const Eigen::MatrixXd& R,
                           const Eigen::MatrixXd& T) {
  const ProblemLayout layout(graph);
  const int d = graph.dimension, n = graph.num_poses;
  // x' = A (x - c) + b for every position, R' = A R for every rotation.
  Eigen::MatrixXd A;
  Eigen::VectorXd c, b = Eigen::VectorXd::Zero(d);
  if (layout.world_rotation) {
    A = R.middleCols(d * layout.world_rotation_block(), d).transpose();
  }
  if (layout.world_translation) {
    c = T.col(layout.world_translation_node());
  } else {
    // The FIX pose (else pose 0) at its initial value, else at the identity.
    const int g = graph.fixed_pose >= 0 ? graph.fixed_pose : 0;
    Eigen::MatrixXd RG = Eigen::MatrixXd::Identity(d, d);
    if (!graph.initial_poses.empty()) {
      RG = graph.initial_poses[g].R;
      b = graph.initial_poses[g].t;
    }
    if (!layout.world_rotation) A = RG * R.middleCols(d * g, d).transpose();
    c = T.col(g);
  }
  Solution x;
  x.poses.resize(n);
  for (int i = 0; i < n; ++i) {
    x.poses[i].R = ProjectToRotation(A * R.middleCols(d * i, d));
    x.poses[i].t = A * (T.col(i) - c) + b;
  }
  x.landmarks.resize(graph.num_landmarks);
  for (int l = 0; l < graph.num_landmarks; ++l) {
    x.landmarks[l] = A * (T.col(layout.landmark_node(l)) - c) + b;
  }
  return x;
}

Staircase::Staircase(const PoseGraph& graph, const SolverOptions& options,
                     SolverSummary* summary, Clock::time_point start,
                     MeasurementWeights weights)
    : graph_(graph), options_(options), summary_(summary), start_(start) {
  *summary_ = SolverSummary();
  SolverSummary& s = *summary_;
  s.lambda_min_estimate = std::numeric_limits<double>::quiet_NaN();
  s.dimension = graph.dimension;
  s.num_poses = graph.num_poses;
  s.num_measurements = static_cast<int>(graph.measurements.size());
  s.num_landmarks = graph.num_landmarks;
  s.num_landmark_measurements =
      static_cast<int>(graph.landmark_measurements.size());
  s.num_priors = static_cast<int>(graph.priors.size());
  if (!ValidatePoseGraph(graph, &s.message) ||
      !CheckMeasurementWeights(graph, weights, &s.message)) {
    s.status = SolverSummary::Status::kInvalidInput;
    return;
  }
  if (!weights.empty()) CountPositiveTerms(graph, weights, &s);
  const ProblemLayout layout(graph);
  d_ = graph.dimension;
  n_ = layout.num_rotations();
  r0_ = options.initial_rank > 0 ? options.initial_rank : d_ + 2;
  if (r0_ < d_ + 1 || options.max_rank < r0_) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = "initial_rank must be >= d + 1 and <= max_rank";
    return;
  }
  if (n_ == 1 && layout.num_translations() == 1) {
    // Nothing to estimate: the pose is the gauge.
    s.status = SolverSummary::Status::kCertifiedOptimum;
    s.relaxation_exact = true;
    s.final_rank = d_;
    s.total_time_s = Elapsed();
    ok_ = trivial_ = true;
    return;
  }

  Progress("data");
  const auto t = Clock::now();
  // Lbar's factorization, the certificate matrix's symbolic analysis (which
  // its double and double-double factorizations share), the
  // preconditioner's choice (from that analysis) and construction. None
  // depends on the initial point: with a second thread they run while
  // Initialize() computes the chordal one (which needs only the assembled
  // matrices and the ordering), and Initialize() waits for them (the wait is
  // counted there). On the 10^6-pose city, two threads: Lbar ~4.8 s, the
  // certificate's analysis ~6 s, the chordal initialization ~11 s.
  const int num_threads = ResolveNumThreads(options.num_threads);
  const bool parallel_window =
      num_threads > 1 &&
      options.initialization == SolverOptions::Initialization::kChordal;
  problem_ =
      std::make_unique<SESyncProblem>(graph, num_threads, std::move(weights),
                                      /*background_lbar=*/parallel_window);
  if (!parallel_window && !problem_->ok()) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = kLbarNotPositiveDefinite;
    return;
  }
  // In 2D the Newton system has K's size (3 unknowns per vertex) and, used
  // from the first solve, takes 2-4 products per rank-d solve (kitti_00 22
  // -> 4, intel 23 -> 3, city10000 100 -> 4) with a factorization or two:
  // faster than (Q + eps I)^-1, whose factorization is then skipped unless
  // a higher rank needs it, and than block-Jacobi's many cheap products
  // while its factorization costs at most kNewtonFromStartSolves solves. In
  // 3D H has 3.4x K's flops, and the switch rule below decides. (A random
  // start is not at rank d.)
  newton_from_start_ =
      options.newton_at_rank_d && d_ == 2 &&
      options.initialization != SolverOptions::Initialization::kRandom &&
      NewtonCostInSolves(*problem_) <= kNewtonFromStartSolves;
  auto prepare = [this] {
    if (!problem_->ok()) return;  // Initialize() reports it.
    certificate_ = std::make_unique<CertificateMatrix>(*problem_);
    const PreconditionerChoice choice =
        ChoosePreconditioner(options_, *certificate_, r0_, newton_from_start_);
    // kAdaptive switches in the first level (no certificate tests run
    // during its optimization) or at an escape (between levels), so
    // certificate_ is free then to serve as its workspace, as for
    // kRegularizedQ (one symbolic analysis, the factor copied out and
    // released: a workspace of its own cost the 10^6-pose city 3 GB of peak
    // memory).
    preconditioner_ = std::make_unique<SESyncPreconditioner>(
        *problem_, choice.type, options_.regularized_cholesky_max_condition,
        certificate_.get(), choice.settings);
    cost_ = std::make_unique<SESyncCost>(problem_.get(), preconditioner_.get());
    if (options_.newton_at_rank_d) {
      // 2D: from the start (above). 3D: the Newton system's factorization
      // in solves of its own factor: K's at rank d scaled to its blocks (6
      // unknowns per vertex against 4: flops x 3.4, entries x 2.25), plus
      // about one for its assembly and copy. A rank-d solve switches when
      // one of its first two truncated-CG solves takes more than twice that
      // in products (SESyncCost::EnableNewton). Measured (one thread, before
      // 2D started with it): parking-garage (26 products in its first
      // solve, threshold 11) and ais2klinik (13, 5) switched, 1.7x and 4.6x
      // faster; the other datasets' first solves took 1-10 products, under
      // their thresholds (5-69), and a switch at the first solve was slower
      // in 3D (sphere2500 0.39x, torus3D 0.29x, cubicle 0.63x) and, with a
      // refactorization at every iterate, in 2D too (kitti_00 0.83x).
      const double k_cost = certificate_->FactorizationCostInSolves(d_);
      const double cost = (d_ == 3 ? 1.5 : 1.0) * k_cost + 1;
      cost_->EnableNewton(std::max(3, static_cast<int>(std::ceil(2 * cost))),
                          newton_from_start_,
                          /*exact_fallback=*/choice.exact &&
                              choice.type == PreconditionerType::kAdaptive);
      VLOG(1) << "Newton at rank d: factorization cost " << cost
              << " solves, K's " << k_cost << ", vertex flops per entry "
              << problem_->vertex_flops_per_entry();
    }
  };
  if (parallel_window) {
    setup_pending_ = std::async(std::launch::async, prepare);
  } else {
    prepare();
  }
  SetScales();
  s.data_time_s = std::chrono::duration<double>(Clock::now() - t).count();
  ok_ = true;
}

void Staircase::AwaitSetup() {
  if (setup_pending_.valid()) setup_pending_.get();
}

void Staircase::SetScales() {
  scale_ = MaxDiagonal(problem_->D());
  // Objective values below this are zero up to round-off (F is a sum of
  // squares weighted by the precisions).
  zero_objective_ = 1e-12 * TotalPrecision(graph_, problem_->weights());
}

bool Staircase::Reweight(MeasurementWeights weights, Clock::time_point start) {
  AwaitSetup();
  CHECK(problem_ != nullptr) << "Reweight() needs a valid, non-trivial problem";
  start_ = start;
  SolverSummary& s = *summary_;
  s = SolverSummary();
  s.lambda_min_estimate = std::numeric_limits<double>::quiet_NaN();
  s.dimension = d_;
  s.num_poses = graph_.num_poses;
  s.num_measurements = static_cast<int>(graph_.measurements.size());
  s.num_landmarks = graph_.num_landmarks;
  s.num_landmark_measurements =
      static_cast<int>(graph_.landmark_measurements.size());
  s.num_priors = static_cast<int>(graph_.priors.size());
  ok_ = false;
  if (!CheckMeasurementWeights(graph_, weights, &s.message)) {
    s.status = SolverSummary::Status::kInvalidInput;
    return false;
  }
  if (!weights.empty()) CountPositiveTerms(graph_, weights, &s);
  const auto t = Clock::now();
  if (!problem_->UpdateWeights(std::move(weights))) {
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = kLbarNotPositiveDefinite;
    return false;
  }
  certificate_->Refresh();
  preconditioner_->Refresh();
  cost_->ResetNewton();
  SetScales();
  verification_ = VerificationResult();
  sdp_value_ = lower_bound_ = 0;
  extended_deferred_ = false;
  s.data_time_s = std::chrono::duration<double>(Clock::now() - t).count();
  return ok_ = true;
}

Staircase::~Staircase() = default;

double Staircase::Elapsed() const {
  return std::chrono::duration<double>(Clock::now() - start_).count();
}

void Staircase::Progress(const char* stage, int rank, int iteration,
                         double objective, double gradient_norm) const {
  if (!options_.progress) return;
  SolverProgress p;
  p.stage = stage;
  p.rank = rank;
  p.iteration = iteration;
  p.objective = objective;
  p.gradient_norm = gradient_norm;
  p.elapsed_s = Elapsed();
  options_.progress(p);
}

Staircase::Clock::time_point Staircase::Deadline() const {
  if (options_.max_time_s <= 0) return Clock::time_point::max();
  return start_ + std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(options_.max_time_s));
}

double Staircase::RemainingTime() const {
  return options_.max_time_s > 0
             ? std::max(1e-3, options_.max_time_s - Elapsed())
             : 0;
}

Solution Staircase::Trivial() const {
  return ToSolutionInGauge(graph_, Eigen::MatrixXd::Identity(d_, d_),
                           Eigen::MatrixXd::Zero(d_, 1));
}

bool Staircase::Initialize(const Poses* initial, Eigen::MatrixXd* Y) {
  SolverSummary& s = *summary_;
  Progress("initialize");
  const auto t = Clock::now();
  const int d = d_, n = n_;
  Y->setZero(r0_, d * n);
  // With priors, given rotations are in the world frame: R_w = I.
  Y->topRows(d).rightCols(d * (n - graph_.num_poses)).setIdentity();
  if (initial) {
    for (int i = 0; i < graph_.num_poses; ++i) {
      Y->block(0, d * i, d, d) = ProjectToRotation((*initial)[i].R);
    }
  } else if (options_.initialization ==
             SolverOptions::Initialization::kVertices) {
    if (graph_.initial_poses.empty()) {
      s.status = SolverSummary::Status::kInvalidInput;
      s.message =
          "initialization from vertices requested, but the graph has "
          "no initial poses";
      return false;
    }
    for (int i = 0; i < graph_.num_poses; ++i) {
      Y->block(0, d * i, d, d) = graph_.initial_poses[i].R;
    }
  } else if (options_.initialization ==
             SolverOptions::Initialization::kRandom) {
    std::mt19937_64 rng(options_.seed);
    *Y = RandomStiefelProductPoint(d, r0_, n, &rng);
  } else {
    Eigen::MatrixXd R;
    if (!ChordalRotations(*problem_, &R)) {
      s.status = SolverSummary::Status::kInvalidInput;
      s.message = "chordal initialization failed";
      return false;
    }
    Y->topRows(d) = R;
  }
  // The Newton system's symbolic analysis needs only the data matrices: on
  // this thread while the set-up finishes on the other (with one thread
  // the same work, counted here instead of in the first solve).
  std::unique_ptr<TangentNewton> newton;
  if (newton_from_start_ && problem_->num_translations() > 1) {
    newton = std::make_unique<TangentNewton>(*problem_);
  }
  AwaitSetup();
  if (!problem_->ok()) {  // Lbar's factorization ran in the background.
    s.status = SolverSummary::Status::kInvalidInput;
    s.message = kLbarNotPositiveDefinite;
    ok_ = false;
    return false;
  }
  if (newton) cost_->ProvideNewton(std::move(newton));
  s.initialization_time_s =
      std::chrono::duration<double>(Clock::now() - t).count();
  return true;
}

double Staircase::Shift(double relative_bound, double sdp_value) const {
  return std::max(options_.min_relative_eta * scale_,
                  relative_bound * sdp_value / (static_cast<double>(d_) * n_));
}

double Staircase::MaxShift(double fraction, double sdp_value) const {
  const double shift =
      Shift(fraction * options_.certification_max_relative_bound, sdp_value);
  if (!(required_lower_bound_ > 0)) return shift;
  return std::min(shift, fraction * (sdp_value - required_lower_bound_) /
                             (static_cast<double>(d_) * n_));
}

bool Staircase::TestCertificate(double eta, ProofPrecision precision,
                                bool tighten, SolverSummary::Level* level) {
  const Clock::time_point deadline = Deadline();
  if (deadline != Clock::time_point::max() &&
      Clock::now() + std::chrono::duration_cast<Clock::duration>(
                         std::chrono::duration<double>(
                             certificate_->PredictedSeconds(precision))) >
          deadline) {
    return false;
  }
  const int double_before = certificate_->double_factorizations();
  const int extended_before = certificate_->extended_factorizations();
  const double extended_time_before = certificate_->extended_time_s();
  certificate_->set_deadline(deadline);
  const bool passed = certificate_->Prove(cost_->Lambda(), eta, precision);
  if (passed) {
    passed_test_lambda_ = cost_->Lambda();
    passed_test_shift_ = certificate_->proven_shift();
    passed_test_precision_ = precision;
    passed_test_tighten_ = tighten;
    passed_test_factor_ = precision == ProofPrecision::kDouble ? eta : 0;
  }
  // A failed test's descent goes on: only the symbolic analysis is kept
  // meanwhile. A passed double test's factor is kept for the level's
  // verification, which follows at once (its Lanczos estimate).
  if (!passed || precision != ProofPrecision::kDouble) {
    certificate_->ReleaseFactor();
  }
  ++level->certificate_tests;
  level->factorizations +=
      certificate_->double_factorizations() - double_before;
  level->extended_factorizations +=
      certificate_->extended_factorizations() - extended_before;
  summary_->extended_proof_time_s +=
      certificate_->extended_time_s() - extended_time_before;
  if (options_.verbose) {
    LOG(INFO) << "rank " << level->rank << ": certificate test at eta " << eta
              << " (factorization ~"
              << certificate_->FactorizationCostInSolves(level->rank)
              << " products' solves)"
              << " (" << ProofPrecisionName(precision) << ") "
              << (passed ? "passed" : "failed");
  }
  return passed;
}

void Staircase::Optimize(int rank, bool escaped, bool tested,
                         Eigen::MatrixXd* Y_full, SolverSummary::Level* level) {
  SESyncCost& cost = *cost_;
  // Rows of Y that are exactly zero stay zero under every operation of the
  // local search (products with Q, the preconditioner, tangent projections
  // and retractions act on each row linearly, or mix only the d columns of
  // a block): the padding of a rank-d initialization, and the rows an
  // escape from such a level leaves at zero. A chordal start at rank d + 2
  // is the rank-d problem, and the level after an escape from it is of
  // rank d + 1. So the level is optimized on its other rows only: the same
  // iterates up to round-off, each product costing (d + 1) / (d + 3) ..
  // d / (d + 2) of the padded one's. The zero rows are put back after.
  std::vector<int> rows;
  for (int i = 0; i < Y_full->rows(); ++i) {
    if (!Y_full->row(i).isZero(0)) rows.push_back(i);
  }
  const bool compact = static_cast<int>(rows.size()) < Y_full->rows() &&
                       static_cast<int>(rows.size()) >= d_;
  Eigen::MatrixXd Y_compact;
  Eigen::MatrixXd* Y = Y_full;
  if (compact) {
    Y_compact.resize(rows.size(), Y_full->cols());
    for (size_t k = 0; k < rows.size(); ++k) {
      Y_compact.row(k) = Y_full->row(rows[k]);
    }
    Y = &Y_compact;
  }
  // The gradient tolerance is relative to the final F, so repeat (cheaply,
  // from the current point) if F dropped below the guess.
  double f = cost.Evaluate(*Y);
  Progress("optimize", rank, 0, f);
  const bool use_ceres =
      options_.local_solver == SolverOptions::LocalSolver::kCeresLbfgs;
  if (use_ceres) {
    CeresLocalSolverSummary ceres_summary;
    MinimizeWithCeresLbfgs(*problem_, options_.ceres_lbfgs_max_iterations,
                           options_.ceres_lbfgs_gradient_tolerance,
                           options_.relative_decrease_tolerance,
                           RemainingTime(), Y, &ceres_summary);
    level->iterations += ceres_summary.iterations;
    level->termination = ceres_summary.termination;
  }
  RiemannianTrustRegionOptions rtr = TrustRegionOptions(options_);
  // Certificate tests (options_.test_certificate_after_escape), scheduled
  // in Hessian-vector products (not in time, so that results do not depend
  // on the machine's speed or load): the level's so far and at the last
  // test; and the tests' seconds.
  const bool test_during =
      escaped && tested && options_.test_certificate_after_escape && !use_ceres;
  // One test near convergence (SolverOptions::
  // test_certificate_near_convergence), once |grad F| <=
  // kNearConvergenceRatio x a sixteenth of the goal's shift. Not where the
  // verification tests in double first (kDoubleFirstMinFlops): large maps,
  // whose first level often ends at a lifted saddle, where a failed
  // double-double proof costs minutes.
  bool test_near_convergence =
      !escaped && tested && options_.test_certificate_near_convergence &&
      !use_ceres && Y->rows() == d_ &&
      certificate_->factorization_flops() < kDoubleFirstMinFlops;
  int level_products = 0, last_test_products = 0;
  double test_seconds = 0;
  // Runs a test (its time is verification's); the level stops if it passed.
  auto run_test = [&](auto&& test) {
    const auto test_start = Clock::now();
    const bool passed = test();
    test_seconds +=
        std::chrono::duration<double>(Clock::now() - test_start).count();
    level->certificate_test_passed = passed;
    return !passed;
  };
  rtr.callback = [&](int it, double f, double g, double radius, int products) {
    if (options_.verbose) {
      LOG(INFO) << "rank " << rank << " iter " << it << " F " << f << " |grad| "
                << g << " radius " << radius << " Hv " << products;
    }
    Progress("optimize", rank, level->iterations + it, f, g);
    if (options_.callback && !options_.callback(rank, it, f, g, radius)) {
      return false;
    }
    if (test_near_convergence) {
      // The verification's first double-double shift (VerifyCertificate).
      const double eta =
          std::max(Shift(options_.certification_target_relative_bound, f),
                   Shift(options_.certification_goal_relative_bound, f) / 16);
      Eigen::MatrixXd gradient;
      cost.Gradient(&gradient);
      if (!(gradient.norm() <= kNearConvergenceRatio * eta)) return true;
      test_near_convergence = false;  // One test per level.
      return run_test([&] { return TestNearConvergence(*Y, f, eta, level); });
    }
    if (!test_during) return true;
    level_products += products;
    const double half_shift = MaxShift(0.5, f);
    // Continue(): F(Y) at or below the bound it needs, no test can prove it.
    if (!(half_shift > 0)) return true;
    const DescentTestPlan test = PlanDescentTest(
        half_shift, MaxShift(0.75, f),
        1.5 * certificate_->DoubleShiftCost(translation_offsets_),
        options_.proof_arithmetic);
    if (!test.run) return true;
    // Due when the products since the last test cost at least twice a
    // factorization (so tests cost at most about half the optimization)
    // and number at least a quarter of the level's (a long descent is
    // tested a logarithmic number of times, the products growing by 4/3 or
    // more between tests). A half (doubling) let a failed test near the
    // point where the certificate becomes provable wait for twice its
    // products: kappa-30 10^5-pose cities 349 / 1023 / 399 -> 211 / 835 /
    // 256 rank-5 products with a quarter (six other seeds unchanged), the
    // scaling bench's 10^6-pose city 492 -> 174. The price is counted, not
    // timed: the prices may not depend on the thread count (results are the
    // same for every num_threads). FactorizationCostInSolves matched CHOLMOD's
    // double factorization in time, and a double-double test is priced at 1.5
    // of it: measured 1.6-2.0x on one thread, ~0.9x on two at 10^6 poses (42-47
    // s against CHOLMOD's serial ~50 s). At 2.5 the 10^6-pose city's first test
    // came at 298 products; on that trajectory it passes from 175 on (one
    // differing in round-off failed at 175: the outcome there is marginal).
    // Double factorizations run in 1/3-1/6 of CHOLMOD's time since
    // (extended_cholesky.h), so double tests are overpriced; a price of 0.25
    // saved no product on nine kappa-30 10^5-pose cities (one went from 648 to
    // 824), the geometric rule deciding. The price is in products of the
    // level's nominal rank, as calibrated; a level run on fewer nonzero rows
    // (above) does fewer solves per product, so its tests come sooner in time
    // than the rule says.
    const double cost =
        certificate_->FactorizationCostInSolves(rank) * test.price;
    const int since = level_products - last_test_products;
    if (since < std::max(2 * cost, 0.25 * level_products)) return true;
    last_test_products = level_products;
    return run_test([&] {
      return TestCertificate(test.eta, test.precision, /*tighten=*/true, level);
    });
  };
  for (int pass = 0; pass < 3 && !use_ceres; ++pass) {
    const double floor = 1e-14 * scale_;
    rtr.preconditioned_gradient_tolerance =
        options_.relative_preconditioned_gradient_tolerance *
        std::sqrt(std::max(f, floor));
    rtr.max_time_s = RemainingTime();
    RiemannianTrustRegionSummary rtr_summary;
    cost.BeginSolve(/*allow_newton=*/true);
    MinimizeRiemannianTrustRegion(rtr, &cost, Y, &rtr_summary);
    level->iterations += rtr_summary.iterations;
    level->hessian_vector_products += rtr_summary.hessian_vector_products;
    level->gradient_norm = rtr_summary.final_gradient_norm;
    level->termination = rtr_summary.TerminationString();
    const double previous = f;
    f = rtr_summary.final_cost;
    if (rtr_summary.termination != RiemannianTrustRegionSummary::Termination::
                                       kPreconditionedGradientTolerance ||
        f >= 0.5 * previous) {
      break;
    }
  }
  if (level->certificate_test_passed) {
    level->termination = "certificate test passed";
  }
  level->verify_time_s += test_seconds;  // The tests' time is verification.
  // Back into Y_full, whose other rows are still zero.
  if (compact) {
    for (size_t k = 0; k < rows.size(); ++k) {
      Y_full->row(rows[k]) = Y_compact.row(k);
    }
    Y = Y_full;
  }
  cost.Evaluate(*Y);  // Make Y current (Lambda at Y).
  if (use_ceres) {
    Eigen::MatrixXd gradient;
    cost.Gradient(&gradient);
    level->gradient_norm = gradient.norm();
  }
}

namespace {

ProofPolicy ToPolicy(SolverOptions::ProofArithmetic arithmetic) {
  switch (arithmetic) {
    case SolverOptions::ProofArithmetic::kAutomatic:
      return ProofPolicy::kAutomatic;
    case SolverOptions::ProofArithmetic::kDouble:
      return ProofPolicy::kDouble;
    case SolverOptions::ProofArithmetic::kDoubleDouble:
      return ProofPolicy::kDoubleDouble;
  }
  return ProofPolicy::kAutomatic;
}

}  // namespace

bool Staircase::TestNearConvergence(const Eigen::MatrixXd& Y, double f,
                                    double eta, SolverSummary::Level* level) {
  // As in Verify() and VerifyCertificate's step 1.
  const double goal = Shift(options_.certification_goal_relative_bound, f);
  translation_offsets_ = certificate_->TranslationOffsets(
      problem_->RecoverTranslations(RoundSolution(Y, d_)));
  const double double_floor =
      certificate_->DoubleShiftCost(translation_offsets_);
  // Only where the verification goes to double-double at a sixteenth of the
  // goal's shift (double cannot reach the goal): there the threshold was
  // measured, and there a proof is dear. Where double reaches (small maps)
  // the first proof is in double at 1.5 floors, half a floor above what its
  // translation shift costs: on 125- and 196-pose cubes it failed at ratios
  // below kNearConvergenceRatio and held only at the converged point.
  if (ToPolicy(options_.proof_arithmetic) != ProofPolicy::kAutomatic ||
      double_floor <= goal / 4) {
    return false;
  }
  // Not tightened by the verification: it was the verification's own proof.
  const bool passed = TestCertificate(eta, ProofPrecision::kDoubleDouble,
                                      /*tighten=*/false, level) &&
                      passed_test_shift_ <= goal;
  // A proof above the goal does not stop the level; it is not kept either.
  if (!passed) passed_test_lambda_.resize(0, 0);
  return passed;
}

VerificationResult Staircase::Verify(const Eigen::MatrixXd& Y,
                                     double sdp_value) {
  AwaitSetup();
  const int d = d_, n = n_;
  VerificationOptions verification_options;
  verification_options.eta_target =
      Shift(options_.certification_target_relative_bound, sdp_value);
  verification_options.eta_max = MaxShift(1, sdp_value);
  verification_options.eta_goal =
      std::min(verification_options.eta_max,
               Shift(options_.certification_goal_relative_bound, sdp_value));
  verification_options.eta_target =
      std::min(verification_options.eta_target, verification_options.eta_goal);
  verification_options.policy = ToPolicy(options_.proof_arithmetic);
  verification_options.deadline = Deadline();
  // Below the maximum rank a failed certificate is escaped from, and the
  // next level's verification replaces its bound: only the witness counts.
  verification_options.tighten_uncertified = Y.rows() >= options_.max_rank;
  // A certificate test passed for these multipliers (the optimization
  // stopped at its point): its proof stands, and is only tightened where
  // double reaches below it (VerificationOptions::known_shift). Lambda may
  // differ from the test's Lambda_t in round-off (Y is evaluated again with
  // its zero rows, whose products take other kernels): with E = Lambda -
  // Lambda_t (symmetric d x d blocks), S(Lambda) = S(Lambda_t) - E, so the
  // proof holds with the shift raised by the largest ||E_i||_2 <= ||E_i||_F.
  // (E's entries and their norms carry a relative round-off of a few ulps;
  // the factor 1 + 1e-12 covers it.) Kept where that is at most 1% of the
  // proven shift, i.e. round-off.
  if (passed_test_lambda_.rows() == cost_->Lambda().rows() &&
      passed_test_lambda_.cols() == cost_->Lambda().cols()) {
    const Eigen::MatrixXd change = cost_->Lambda() - passed_test_lambda_;
    double largest = 0;
    for (int i = 0; i < n; ++i) {
      largest = std::max(largest, change.middleCols(d * i, d).norm());
    }
    largest *= 1 + 1e-12;
    if (largest <= 0.01 * passed_test_shift_) {
      // Rounded up: the sum's own rounding must not lower the shift (exact,
      // and as before, for the same Lambda).
      verification_options.known_shift =
          largest > 0 ? std::nextafter(passed_test_shift_ + largest,
                                       std::numeric_limits<double>::infinity())
                      : passed_test_shift_;
      verification_options.known_precision = passed_test_precision_;
      verification_options.tighten_known_shift = passed_test_tighten_;
      verification_options.known_shift_factor = passed_test_factor_;
    }
  }
  passed_test_lambda_.resize(0, 0);
  // The rounded poses cannot be proven closer to the optimum than their
  // rounding gap. When Algorithm 2 applied to Y now (an upper bound on the
  // final gap, before refinement) already misses the goal, the relaxation
  // is not exact here and a double-double proof tighter than double's
  // would mostly be wasted: it is deferred to Report(), which runs it only
  // if the tolerance needs it.
  extended_deferred_ = false;
  verified_rounding_ = RoundSolution(Y, d);
  verified_rounding_value_ = std::numeric_limits<double>::quiet_NaN();
  const Eigen::MatrixXd& R = verified_rounding_;
  if (verification_options.policy == ProofPolicy::kAutomatic && Y.rows() > d &&
      sdp_value > 0) {
    Eigen::MatrixXd RQ;
    problem_->MultiplyQ(R, &RQ);
    verified_rounding_value_ = R.cwiseProduct(RQ).sum();
    const double gap = (verified_rounding_value_ - sdp_value) / sdp_value;
    if (gap > options_.certification_goal_relative_bound) {
      verification_options.policy = ProofPolicy::kDouble;
      extended_deferred_ = true;
    } else {
      verification_options.likely_optimal = true;
      verification_options.test_in_double_first =
          certificate_->factorization_flops() >= kDoubleFirstMinFlops;
    }
  }
  translation_offsets_ =
      certificate_->TranslationOffsets(problem_->RecoverTranslations(R));
  verification_options.translation_offsets = translation_offsets_;
  VerificationResult verification = VerifyCertificate(
      *problem_, cost_->Lambda(), verification_options, certificate_.get());
  if (!verification.certified && sdp_value <= zero_objective_) {
    // F >= 0 always: a (numerically) zero value is optimal as it stands.
    verification.certified = true;
    verification.eta = 0;
  }
  return verification;
}

bool Staircase::Escape(const Eigen::MatrixXd& Y, Eigen::MatrixXd* Y_plus) {
  // Along [0; v^T] at rank r + 1, backtracking.
  const int d = d_, n = n_, r = static_cast<int>(Y.rows());
  Eigen::MatrixXd Y_up = Eigen::MatrixXd::Zero(r + 1, d * n);
  Y_up.topRows(r) = Y;
  Eigen::MatrixXd V = Eigen::MatrixXd::Zero(r + 1, d * n);
  V.row(r) = verification_.direction.transpose();
  double max_block_norm = 0;
  for (int i = 0; i < n; ++i) {
    max_block_norm = std::max(max_block_norm,
                              verification_.direction.segment(d * i, d).norm());
  }
  double alpha = 1.0 / max_block_norm;
  for (int k = 0; k < 60; ++k, alpha *= 0.5) {
    RetractStiefelProduct(Y_up, alpha * V, d, Y_plus);
    if (cost_->Evaluate(*Y_plus) < sdp_value_) return true;
  }
  return false;
}

void Staircase::Run(Eigen::MatrixXd* Y, bool verify_at_max_rank) {
  AwaitSetup();
  escaped_rounding_.resize(0, 0);
  escaped_rounding_value_ = std::numeric_limits<double>::infinity();
  Climb(Y, verify_at_max_rank, /*verify_first=*/false);
}

void Staircase::Climb(Eigen::MatrixXd* Y, bool verify_at_max_rank,
                      bool verify_first) {
  SolverSummary& s = *summary_;
  for (int r = static_cast<int>(Y->rows()), first = r;; ++r) {
    SolverSummary::Level level;
    level.rank = r;
    auto t = Clock::now();
    // Tests on the way only after an escape, and only where the level's
    // certificate is tested at all.
    const bool tested = verify_at_max_rank || r < options_.max_rank;
    if (verify_first && r == first) {
      level.termination = "verified again for the rounded poses";
      cost_->Evaluate(*Y);  // Lambda at Y (rounding moved the cost).
    } else {
      // kAutomatic's block-Jacobi ends at a saddle escape: the descent
      // after one is long and flat (hundreds of products), where the exact
      // preconditioner pays for its factorization.
      if (r > first) preconditioner_->SwitchToExact();
      Optimize(r, /*escaped=*/r > first, tested, Y, &level);
      // Without the certificate tests' time (verify_time_s so far).
      level.optimize_time_s =
          std::chrono::duration<double>(Clock::now() - t).count() -
          level.verify_time_s;
    }
    // F(Y) = tr(Q Y^T Y) = tr(Lambda): the dual objective of these multipliers.
    sdp_value_ = BlockDiagonalTrace(cost_->Lambda(), d_);
    level.sdp_value = sdp_value_;
    // F(Y) bounds the relaxation's optimum from above: at or below the
    // bound Continue() needs, no certificate of it reaches that bound.
    const bool out_of_reach =
        required_lower_bound_ > 0 && !(sdp_value_ > required_lower_bound_);

    if (tested && !out_of_reach) {
      Progress("verify", r, level.iterations, sdp_value_, level.gradient_norm);
      t = Clock::now();
      verification_ = Verify(*Y, sdp_value_);
      level.verify_time_s +=
          std::chrono::duration<double>(Clock::now() - t).count();
    } else {
      // No test: nothing proven, no factorization.
      verification_ = VerificationResult();
      verification_.eta = std::numeric_limits<double>::infinity();
      verification_.lambda_min_estimate =
          std::numeric_limits<double>::quiet_NaN();
    }
    level.certified = verification_.certified;
    level.eta = verification_.eta;
    level.lambda_min_estimate = verification_.lambda_min_estimate;
    level.factorizations += verification_.factorizations;
    level.extended_factorizations += verification_.extended_factorizations;
    // The dual bound of these multipliers (they change when rounding
    // refines the poses).
    lower_bound_ =
        std::isfinite(verification_.eta)
            ? ProvenLowerBound(cost_->Lambda(), d_, verification_.eta)
            : 0.0;
    s.factorizations += level.factorizations;
    s.extended_factorizations += level.extended_factorizations;
    s.certificate_tests += level.certificate_tests;
    s.extended_proof_time_s += verification_.extended_time_s;
    s.iterations += level.iterations;
    s.hessian_vector_products += level.hessian_vector_products;
    // What preconditioned the products: the SESyncPreconditioner where it
    // was applied, the Newton system where it was factorized.
    const std::string newton = "Newton at rank d (" +
                               std::to_string(cost_->newton_factorizations()) +
                               " factorizations)";
    if (cost_->newton_factorizations() == 0) {
      s.preconditioner = PreconditionerName(*preconditioner_);
    } else if (cost_->preconditioner_applications() == 0) {
      s.preconditioner = newton;
    } else {
      s.preconditioner = PreconditionerName(*preconditioner_) + "; " + newton;
    }
    s.optimization_time_s += level.optimize_time_s;
    s.verification_time_s += level.verify_time_s;
    s.levels.push_back(level);
    s.final_rank = r;
    if (options_.verbose) {
      LOG(INFO) << "rank " << r << ": F(Y) " << sdp_value_ << ", eta "
                << verification_.eta << ", lambda_min estimate "
                << verification_.lambda_min_estimate
                << (verification_.certified ? " (certified)" : "");
    }
    if (out_of_reach) {
      s.status = SolverSummary::Status::kBoundAboveTolerance;
      return;
    }
    if (!tested) {  // At max_rank: nothing to escape to.
      s.status = SolverSummary::Status::kMaxRankReached;
      return;
    }
    if (verification_.certified) {
      s.status = SolverSummary::Status::kCertifiedOptimum;
      return;
    }
    if (verification_.out_of_time) {
      // Stopped at max_time_s: the best bound proven by then (if any) stands.
      s.status = SolverSummary::Status::kTimeLimit;
      return;
    }
    if (verification_.eigensolver_failed) {
      // No negative curvature to climb along: either a bound was proven but
      // it is above the tolerance, or not even that.
      s.status = std::isfinite(verification_.eta)
                     ? SolverSummary::Status::kBoundAboveTolerance
                     : SolverSummary::Status::kEigenImprecision;
      return;
    }
    if (options_.max_time_s > 0 && Elapsed() >= options_.max_time_s) {
      s.status = SolverSummary::Status::kTimeLimit;
      return;
    }
    if (r >= options_.max_rank) {
      s.status = SolverSummary::Status::kMaxRankReached;
      return;
    }
    KeepRounding();
    Eigen::MatrixXd Y_plus;
    if (!Escape(*Y, &Y_plus)) {
      s.status = SolverSummary::Status::kSaddleNotEscaped;
      cost_->Evaluate(*Y);
      return;
    }
    *Y = std::move(Y_plus);
  }
}

void Staircase::KeepRounding() {
  if (std::isnan(verified_rounding_value_)) {
    Eigen::MatrixXd RQ;
    problem_->MultiplyQ(verified_rounding_, &RQ);
    verified_rounding_value_ = verified_rounding_.cwiseProduct(RQ).sum();
  }
  if (verified_rounding_value_ < escaped_rounding_value_) {
    escaped_rounding_ = std::move(verified_rounding_);  // Verify() refills it.
    escaped_rounding_value_ = verified_rounding_value_;
  }
}

Solution Staircase::Round(const Eigen::MatrixXd& Y) {
  AwaitSetup();
  SolverSummary& s = *summary_;
  Progress("round", static_cast<int>(Y.rows()));
  const auto t = Clock::now();
  Eigen::MatrixXd R = RoundSolution(Y, d_);
  if (options_.refine_rounded_solution) {
    // Local search on O(d)^n = St(d, d)^n from rounded rotations X with
    // objective `rounded` (blocks stay in SO(d) by continuity); returns the
    // objective at the result. A no-op when the relaxation is exact.
    auto refine = [&](double rounded, Eigen::MatrixXd* X) {
      if (!(rounded > sdp_value_ * (1 + 1e-12))) return rounded;
      RiemannianTrustRegionOptions rtr = TrustRegionOptions(options_);
      rtr.max_time_s = RemainingTime();
      rtr.preconditioned_gradient_tolerance =
          options_.relative_preconditioned_gradient_tolerance *
          std::sqrt(rounded);
      RiemannianTrustRegionSummary refine_summary;
      // A refinement takes a step or two: not worth the Newton system.
      cost_->BeginSolve(/*allow_newton=*/false);
      MinimizeRiemannianTrustRegion(rtr, cost_.get(), X, &refine_summary);
      s.iterations += refine_summary.iterations;
      s.hessian_vector_products += refine_summary.hessian_vector_products;
      *X = ProjectBlocksToRotations(*X, d_);
      return refine_summary.final_cost;
    };
    const double rounded = cost_->Evaluate(R);
    // A level escaped from rounds lower (escaped_rounding_). Certified: refine
    // from there, and keep the result if it is within the tolerance of the
    // proven bound (with 1% of it to spare for F's evaluation in Report());
    // else refine Y's rounding too and keep the lower objective, so that no
    // certificate is lost. Out of time: the lower rounding is the better
    // answer (the refinement has no time left). Otherwise (no bound) Y's
    // rounding as always.
    const bool time_limit = s.status == SolverSummary::Status::kTimeLimit;
    if (escaped_rounding_value_ < rounded &&
        (verification_.certified || time_limit)) {
      Eigen::MatrixXd from_escape = escaped_rounding_;
      const double value = refine(escaped_rounding_value_, &from_escape);
      const double tolerance = options_.certification_max_relative_bound;
      const bool within =
          verification_.certified && lower_bound_ > 0 &&
          value - lower_bound_ <= 0.99 * tolerance * lower_bound_;
      if (within || time_limit || value < refine(rounded, &R)) {
        R = std::move(from_escape);
      }
      if (options_.verbose) {
        LOG(INFO) << "rounding: an escaped level's rounding, F "
                  << escaped_rounding_value_ << " (Y's " << rounded
                  << "), refined to " << value
                  << (within ? ", within the tolerance" : "");
      }
    } else {
      refine(rounded, &R);
    }
  }
  const Eigen::MatrixXd T = problem_->RecoverTranslations(R);
  Solution solution = ToSolutionInGauge(graph_, R, T);
  s.rounding_time_s = std::chrono::duration<double>(Clock::now() - t).count();
  return solution;
}

double Staircase::Objective(const Solution& solution) const {
  return WeightedObjective(graph_, problem_->weights(), solution.poses,
                           solution.landmarks);
}

bool Staircase::Continue(Eigen::MatrixXd* Y, Solution* solution) {
  AwaitSetup();
  SolverSummary& s = *summary_;
  if (s.status != SolverSummary::Status::kCertifiedOptimum ||
      !(lower_bound_ > 0) ||
      (options_.max_time_s > 0 && Elapsed() >= options_.max_time_s)) {
    return false;
  }
  const double tol = options_.certification_max_relative_bound;
  const double upper =
      ObjectiveUpperBound(graph_, *solution, problem_->weights());
  if (upper - lower_bound_ <= tol * lower_bound_) return false;
  // The lower bound that puts the solution within the tolerance, with 1% of
  // it to spare (Report() evaluates F again). F(Y) is an upper bound on
  // the relaxation's optimum: at or below it, the relaxation's own gap
  // misses the tolerance.
  const double needed = upper / (1 + 0.99 * tol);
  if (!(needed < sdp_value_)) return false;
  // What Report() reads, restored if the bound is not reached.
  const Eigen::MatrixXd Y_before = *Y;
  const VerificationResult verification_before = verification_;
  const double sdp_value_before = sdp_value_, lower_bound_before = lower_bound_;
  const bool extended_deferred_before = extended_deferred_;
  const int final_rank_before = s.final_rank;
  if (options_.verbose) {
    LOG(INFO) << "continuing: F(x) " << upper << " needs a lower bound of "
              << needed << " (proven " << lower_bound_ << ", F(Y) "
              << sdp_value_ << ")";
  }
  required_lower_bound_ = needed;
  Climb(Y, /*verify_at_max_rank=*/true, /*verify_first=*/true);
  required_lower_bound_ = 0;
  if (s.status == SolverSummary::Status::kCertifiedOptimum &&
      lower_bound_ >= needed) {
    const double first_rounding_s = s.rounding_time_s;
    Solution again = Round(*Y);
    s.rounding_time_s += first_rounding_s;
    if (Objective(again) < Objective(*solution)) *solution = std::move(again);
    return true;
  }
  *Y = Y_before;
  verification_ = verification_before;
  sdp_value_ = sdp_value_before;
  lower_bound_ = lower_bound_before;
  extended_deferred_ = extended_deferred_before;
  s.final_rank = final_rank_before;
  s.status = SolverSummary::Status::kCertifiedOptimum;
  cost_->Evaluate(*Y);
  return false;
}

void Staircase::TightenProof(const Eigen::MatrixXd& Y, double objective) {
  SolverSummary& s = *summary_;
  const int dn = d_ * n_;
  const double tol = options_.certification_max_relative_bound;
  // Certified iff lower bound >= F(x) / (1 + tol), i.e. eta <= eta_max:
  const double eta_max = (sdp_value_ - objective / (1 + tol)) / dn;
  if (!(eta_max > 0) || verification_.eta <= eta_max) return;
  Progress("prove", s.final_rank, s.iterations, sdp_value_);
  const auto t = Clock::now();
  cost_->Evaluate(Y);  // Lambda at Y again (rounding moved the cost).
  VerificationOptions o;
  o.eta_target =
      Shift(options_.certification_target_relative_bound, sdp_value_);
  o.eta_max = eta_max;
  o.eta_goal = eta_max / 4;
  o.policy = ProofPolicy::kDoubleDouble;
  o.deadline = Deadline();
  const VerificationResult v =
      VerifyCertificate(*problem_, cost_->Lambda(), o, certificate_.get());
  s.factorizations += v.factorizations;
  s.extended_factorizations += v.extended_factorizations;
  s.extended_proof_time_s += v.extended_time_s;
  s.verification_time_s +=
      std::chrono::duration<double>(Clock::now() - t).count();
  if (v.eta < verification_.eta) {
    verification_.eta = v.eta;
    verification_.precision = v.precision;
    lower_bound_ = ProvenLowerBound(cost_->Lambda(), d_, v.eta);
  }
}

void Staircase::Report(const Eigen::MatrixXd& Y, const Solution& solution) {
  AwaitSetup();
  SolverSummary& s = *summary_;
  s.objective = Objective(solution);
  if (extended_deferred_ && verification_.certified) {
    TightenProof(Y, s.objective);
  }
  s.sdp_value = sdp_value_;
  s.eta = verification_.eta;
  s.lambda_min_estimate = verification_.lambda_min_estimate;
  s.proof_precision = std::isfinite(s.eta)
                          ? ProofPrecisionName(verification_.precision)
                          : "none";
  s.rounding_gap = (s.objective - sdp_value_) / std::max(sdp_value_, 1e-300);
  // tr(Lambda) - eta d n bounds the optimum whenever S + eta I was proven
  // PSD, certified or not; F >= 0 always.
  s.lower_bound = std::max(0.0, lower_bound_);
  // The attained objective bounds the optimum too (guards F(Y) round-off).
  s.lower_bound = std::min(s.lower_bound, s.objective);
  // F(x) rounded up: the bound must not rest on round-off in F.
  s.suboptimality_bound =
      std::max(0.0, ObjectiveUpperBound(graph_, solution, problem_->weights()) -
                        s.lower_bound);
  // A numerically zero F is optimal by F >= 0 (no ratio to a zero bound).
  s.relative_suboptimality_bound =
      s.objective <= zero_objective_ ? 0
      : s.lower_bound > 0            ? s.suboptimality_bound / s.lower_bound
                                     : std::numeric_limits<double>::infinity();
  s.relaxation_exact =
      verification_.certified &&
      (s.rounding_gap <= options_.certification_max_rounding_gap ||
       s.objective <= zero_objective_);
  if (s.status == SolverSummary::Status::kCertifiedOptimum &&
      !(s.relative_suboptimality_bound <=
        options_.certification_max_relative_bound)) {
    // Y is optimal for the SDP, but the rounded poses are not provably
    // within the tolerance (the relaxation is not exact here).
    s.status = SolverSummary::Status::kBoundAboveTolerance;
  }
  if (s.status == SolverSummary::Status::kBoundAboveTolerance) {
    char message[160];
    std::snprintf(message, sizeof(message),
                  "the proven relative suboptimality bound %.3e is above the "
                  "tolerance %.3e",
                  s.relative_suboptimality_bound,
                  options_.certification_max_relative_bound);
    s.message = message;
  }
  s.total_time_s = Elapsed();
  Progress("done", s.final_rank, s.iterations, s.objective);
}

}  // namespace ceres_sesync::internal
