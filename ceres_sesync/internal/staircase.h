// The stages of Solve(), callable on their own:
//
//   problem -> initialize -> staircase -> (verify per level) -> round -> report
//
// so that outer loops (a robust GNC solve re-weighting the same graph), other
// problem contents (landmarks, priors) and the bindings reuse one staircase
// instead of copies of it. Solve() is exactly
//
//   Staircase staircase(graph, options, summary);   // problem (validates)
//   if (!staircase.ok()) return {};
//   Eigen::MatrixXd Y;
//   if (!staircase.Initialize(initial, &Y)) return {};
//   staircase.Run(&Y);                               // optimize / verify /
//                                                    // escape, level by level
//   Solution x = staircase.Round(Y);                 // Algorithm 2 + eq. (21)
//   staircase.Continue(&Y, &x);                      // the bound x needs
//   staircase.Report(Y, x);                          // objective, bounds,
//                                                    // status
//
// Graphs with landmarks and priors run the same stages on the extended
// problem of sesync_problem.h (landmarks among the eliminated translations,
// priors as edges from a world pose); Round() expresses the answer in the
// world frame.
//
// Every stage records what it did in the SolverSummary given at
// construction (times, levels, counts).
//
// Weighted problems (measurement_weights.h; the GNC loop of robust_solver.cc)
// reuse one Staircase: Reweight() changes the data matrices' values in place
// (keeping every symbolic analysis) and starts a new solve, which Run()
// warm-starts from the previous Y:
//
//   staircase.Reweight(weights);   // a new solve of the weighted problem
//   staircase.Run(&Y);             // from the previous factor
//   Solution x = staircase.Round(Y);
//   staircase.Report(Y, x);        // F, bounds: of the weighted problem

#ifndef CERES_SESYNC_INTERNAL_STAIRCASE_H_
#define CERES_SESYNC_INTERNAL_STAIRCASE_H_

#include <chrono>
#include <future>
#include <limits>
#include <memory>

#include "Eigen/Core"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"

namespace ceres_sesync::internal {

class Staircase {
 public:
  using Clock = std::chrono::steady_clock;

  // Stage "problem": validates `graph`, `options` and `weights`
  // (measurement_weights.h; empty: all 1) and builds the data matrices of
  // the (weighted) problem, the certificate matrix's symbolic analysis and
  // the preconditioner. `graph`, `options` and `summary` must outlive this
  // object (options are read at every stage); `summary` is reset. Time
  // limits count from `start`.
  Staircase(const PoseGraph& graph, const SolverOptions& options,
            SolverSummary* summary, Clock::time_point start = Clock::now(),
            MeasurementWeights weights = {});
  ~Staircase();

  // False if validation or the data matrices failed (summary has the status
  // and message).
  bool ok() const { return ok_; }
  // A single pose without landmarks and priors: it is the gauge; the
  // summary is complete and Trivial() returns the solution.
  bool trivial() const { return trivial_; }
  Solution Trivial() const;

  // Starts a new solve of the problem with these measurement weights
  // (empty: all 1; one per term, measurement_weights.h): the data
  // matrices, the certificate matrix and the preconditioner get the new
  // values (same patterns: the symbolic analyses are kept), the summary is
  // reset as by the constructor (num_measurements: those of positive weight;
  // data_time_s: this update) and time limits count from `start`. Returns
  // false, with the summary's status kInvalidInput and a message, if the
  // weights fail CheckMeasurementWeights (e.g. the positively weighted
  // measurements leave the graph disconnected); ok() is then false until a
  // successful Reweight(). Not for trivial problems.
  bool Reweight(MeasurementWeights weights,
                Clock::time_point start = Clock::now());

  // Stage "initialize": Y (r0 x dn, n = problem().num_rotations()) from
  // `initial` (its rotations projected to SO(d); with priors they are in the
  // world frame, and R_w starts at I) or, if null, from
  // options.initialization. False (summary has the status) if the requested
  // initialization is unavailable.
  bool Initialize(const Poses* initial, Eigen::MatrixXd* Y);

  // Stage "staircase": from Y (any rank >= d + 1), optimize, verify, and
  // escape saddles rank by rank until certified or stopped (the summary's
  // status). On return Y is the final factor and the cost is evaluated there.
  // With verify_at_max_rank false, a level at options.max_rank ends with
  // kMaxRankReached without its certificate test, nor tests during its
  // optimization (no bound, nothing to escape to): for callers that use
  // only Y, such as GNC's weighted steps.
  void Run(Eigen::MatrixXd* Y, bool verify_at_max_rank = true);

  // Stage "verify", for the current point Y of the cost (Lambda at Y) with
  // F(Y) = sdp_value: proves S + eta I positive semidefinite for the smallest
  // eta it can, within the options' certification targets (the goal raised
  // to the rounding gap of Y when that is larger).
  VerificationResult Verify(const Eigen::MatrixXd& Y, double sdp_value);

  // Stage "round": Algorithm 2 on Y, the optional refinement on SO(d)^n, the
  // optimal translations and landmark positions (eq. 21), in the documented
  // gauge (ToSolutionInGauge). When the last level is certified (or the time
  // limit stopped Run()) and a level escaped from rounds to a lower
  // objective (escaped_rounding_), the refinement starts from that rounding
  // instead; if the result is then not within the tolerance of the proven
  // bound, Y's rounding is refined as well and the lower of the two kept.
  Solution Round(const Eigen::MatrixXd& Y);

  // Stage "continue", after round: where the relaxation was certified but
  // the rounded `solution` is not within the tolerance of the proven bound,
  // and a bound the relaxation can still give would bring it within (F(Y),
  // which bounds the relaxation's optimum from above, is above the lower
  // bound the solution needs: the proof's slack eta d n, not the
  // relaxation's gap, is what misses), the staircase goes on from Y with
  // that lower bound as its target: Y's verification again at the shift it
  // allows, then escapes and levels as in Run() (their certificate tests
  // aim at it too). True iff it proved that bound; *solution is then the
  // lower-objective of it and the new Y's rounding. Otherwise Y, the
  // verification and the status are restored (the levels it ran stay in
  // the summary) and false is returned; also where there was nothing to do.
  bool Continue(Eigen::MatrixXd* Y, Solution* solution);

  // Stage "report": objective, lower bound, suboptimality bounds, rounding
  // gap, final status and total time for the returned `solution` (rounded
  // from Y). When the relaxation proved not exact and double precision left
  // the solution's bound above the tolerance, the proof is tightened in
  // double-double first (the only case Verify() defers it).
  void Report(const Eigen::MatrixXd& Y, const Solution& solution);

  const SESyncProblem& problem() const { return *problem_; }
  SESyncCost& cost() {
    AwaitSetup();
    return *cost_;
  }
  // The last level's verification (after Run()).
  const VerificationResult& verification() const { return verification_; }
  // F(Y) at the end of Run().
  double sdp_value() const { return sdp_value_; }

 private:
  double Elapsed() const;
  // Calls options.progress (if set) with the current elapsed time.
  void Progress(const char* stage, int rank = 0, int iteration = 0,
                double objective = 0, double gradient_norm = 0) const;
  // scale_ and zero_objective_ from the problem's current data.
  void SetScales();
  // Waits for the set-up run concurrently with Initialize() (see the
  // constructor: certificate_, preconditioner_ and cost_), if it is still
  // running.
  void AwaitSetup();
  // Seconds left of options.max_time_s (at least 1 ms), or 0 for no limit.
  double RemainingTime() const;
  // start + max_time_s, or time_point::max() for no limit.
  Clock::time_point Deadline() const;
  // One level's local optimization (RTR or Ceres LBFGS) from Y. A level
  // whose certificate is tested after it (`tested`) tests it on the way:
  // entered by an escape, on the schedule of
  // SolverOptions::test_certificate_after_escape; else, from a rank-d
  // point, near convergence (SolverOptions::
  // test_certificate_near_convergence).
  void Optimize(int rank, bool escaped, bool tested, Eigen::MatrixXd* Y,
                SolverSummary::Level* level);
  // The shift of a relative bound on the objective: relative_bound *
  // sdp_value / (d n), at least min_relative_eta's floor.
  double Shift(double relative_bound, double sdp_value) const;
  // The shift a certificate at F(Y) = sdp_value may have, scaled by
  // `fraction`: that of the tolerance (certification_max_relative_bound),
  // and while Continue() runs at most `fraction` of the shift that proves
  // required_lower_bound_ (not positive where F(Y) is not above it).
  double MaxShift(double fraction, double sdp_value) const;
  // Run()'s levels from Y; with `verify_first`, the first level (Y's own)
  // is verified again without optimizing (Continue()).
  void Climb(Eigen::MatrixXd* Y, bool verify_at_max_rank, bool verify_first);
  // One certificate test at the current point of the cost: tries to prove
  // S + eta I >= 0 (not started if predicted to end after the time limit).
  // Adds its factorizations to `level`; true iff it proved it. A passed
  // test is recorded for the level's verification (passed_test_*), which
  // may tighten its proof iff `tighten`.
  bool TestCertificate(double eta, ProofPrecision precision, bool tighten,
                       SolverSummary::Level* level);
  // The test near convergence (SolverOptions::
  // test_certificate_near_convergence) at the rank-d point Y with objective
  // f: the first proof of the level's verification, at its shift eta, where
  // that is in double-double (VerifyCertificate's step 1, with the
  // translation spread of Y's rounding; none where it is in double). True iff
  // it proved a shift within the goal's.
  bool TestNearConvergence(const Eigen::MatrixXd& Y, double f, double eta,
                           SolverSummary::Level* level);
  // F of `solution` for the problem's measurement weights (all 1 if none).
  double Objective(const Solution& solution) const;
  // The deferred double-double proof (see Report()).
  void TightenProof(const Eigen::MatrixXd& Y, double objective);
  // Keeps the last verified level's rounding (verified_rounding_) as
  // escaped_rounding_ if its objective is the lower.
  void KeepRounding();
  // Escapes the saddle at rank r along the verification's direction; false
  // if no descent was found.
  bool Escape(const Eigen::MatrixXd& Y, Eigen::MatrixXd* Y_plus);

  const PoseGraph& graph_;
  const SolverOptions& options_;
  SolverSummary* summary_;
  Clock::time_point start_;
  bool ok_ = false;
  bool trivial_ = false;
  int d_ = 0, n_ = 0, r0_ = 0;
  // The first level runs on the Newton system from its start (2D; see the
  // constructor), which Initialize() builds while the set-up finishes.
  bool newton_from_start_ = false;
  double scale_ = 0;           // max diag(D)
  double zero_objective_ = 0;  // F below this is zero up to round-off.
  std::unique_ptr<SESyncProblem> problem_;
  std::unique_ptr<CertificateMatrix> certificate_;
  std::unique_ptr<SESyncPreconditioner> preconditioner_;
  std::unique_ptr<SESyncCost> cost_;
  // Builds certificate_, preconditioner_ and cost_ on another thread
  // (declared after what it uses, so that it is joined before they are
  // destroyed).
  std::future<void> setup_pending_;
  VerificationResult verification_;
  // The lowest-objective rounding of the levels Run() escaped from, and its
  // objective (+infinity: none). At a lifted saddle (Y of numerical rank d)
  // it is a critical point of the rank-d problem, and often the final
  // answer: on a 10^6-pose city the rank-5 descent after the rank-4 saddle
  // only raised the lower bound, and its rounding refined back to the same
  // poses (33 s of refinement).
  Eigen::MatrixXd escaped_rounding_;
  // Verify()'s rounding of its Y and that rounding's objective (NaN when
  // Verify() did not need it).
  Eigen::MatrixXd verified_rounding_;
  double verified_rounding_value_ = std::numeric_limits<double>::quiet_NaN();
  double escaped_rounding_value_ = std::numeric_limits<double>::infinity();
  double sdp_value_ = 0;
  double lower_bound_ = 0;  // Proven at the last verification.
  // The lower bound Continue() aims at (0: none, the tolerance alone).
  double required_lower_bound_ = 0;
  // The last verification skipped double-double (not exact: see Verify()).
  bool extended_deferred_ = false;
  // The last verification's translation offsets (VerificationOptions), for
  // the certificate tests' choice of arithmetic.
  Eigen::MatrixXd translation_offsets_;
  // A certificate test that passed (the optimization stopped there): its
  // Lambda, proven shift and arithmetic, for the level's verification.
  Eigen::MatrixXd passed_test_lambda_;
  double passed_test_shift_ = 0;
  ProofPrecision passed_test_precision_ = ProofPrecision::kDouble;
  // The c of its double factor, still held (0: none; a double-double test).
  double passed_test_factor_ = 0;
  // Whether the level's verification may tighten that proof (not after a
  // test near convergence: it was the verification's own first proof).
  bool passed_test_tighten_ = true;
};

// A certificate test during the descent of a level entered by an escape
// (SolverOptions::test_certificate_after_escape): its shift, its arithmetic
// and its price in double factorizations for the tests' schedule
// (Staircase::Optimize). At half the tolerance's shift (`half_shift`, that
// of certification_max_relative_bound / 2), in double (price 1) where
// double can prove it (`double_reach`, 1.5 times the double floor of the
// last verification: see VerifyCertificate), else in double-double (price
// 1.5). Where double cannot prove half the tolerance's shift but can prove
// `three_quarters_shift`, the test is in double at double_reach instead:
// a double-double factorization costs ~4.6 double ones (10^6-pose city: 45-49
// s against ~10 s; its reach is at 0.64 of the tolerance's shift), and the
// bound keeps a quarter of the tolerance to spare. That test keeps the
// double-double test's schedule (price 1.5). `run` is false where the
// arithmetic allows no test (kDouble beyond double's reach).
struct DescentTestPlan {
  bool run = true;
  double eta = 0;
  ProofPrecision precision = ProofPrecision::kDouble;
  double price = 1;
};
DescentTestPlan PlanDescentTest(double half_shift, double three_quarters_shift,
                                double double_reach,
                                SolverOptions::ProofArithmetic arithmetic);

// The solution from rotations R (d x dn) and translations T (d x N) in the
// index sets of ProblemLayout, expressed in the documented gauge. With priors:
// in the world frame, i.e. every pose and landmark moved by the rigid motion
// that takes the world pose (R_w, t_w) to (I, 0) (with rotation-only priors
// t_w does not exist: the translations are then placed as without priors).
// Without priors: the FIX pose (else pose 0) sits at its initial value (else
// at the identity).
Solution ToSolutionInGauge(const PoseGraph& graph, const Eigen::MatrixXd& R,
                           const Eigen::MatrixXd& T);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_STAIRCASE_H_
