// Outlier-robust pose-graph optimization: graduated non-convexity (GNC) with
// the truncated-least-squares (TLS) cost around the SE-Sync staircase (Yang,
// Antonante, Tzoumas, Carlone, "Graduated Non-Convexity for Robust Spatial
// Perception: From Non-Minimal Solvers to Global Outlier Rejection", RA-L
// 2020; there with SE-Sync as the non-minimal solver for pose graphs).
//
//   ceres_sesync::RobustSolverOptions options;
//   ceres_sesync::RobustSolverSummary summary;
//   ceres_sesync::Poses poses = ceres_sesync::SolveRobust(graph, options,
//                                                         &summary);
//   std::cout << summary.FullReport() << "\n";
//   for (int k : summary.outlier_edges) { ... measurement k was rejected ... }
//   if (summary.certified()) { ... the inlier problem's optimum ... }
//
// The TLS problem: with f_k(x) the term of measurement k in eq. (12),
//
//   f_k(x) = kappa_k ||R_j - R_i R~_k||_F^2 + tau_k ||t_j - t_i - R_i t~_k||^2,
//
// minimize sum_k min(f_k(x), c^2). Under the isotropic noise model of the
// measurement's own precisions (Langevin rotations, Gaussian translations;
// Rosen et al. 2019, eq. 10) f_k is approximately chi^2 distributed with
// d(d+1)/2 degrees of freedom (d(d-1)/2 rotational, d translational), so c^2
// is a quantile of that distribution. GNC minimizes the surrogate
//
//   rho_mu(r^2) = r^2                                 r^2 <= mu/(mu+1) c^2
//               = 2 c |r| sqrt(mu (mu+1)) - mu (c^2 + r^2)   in between
//               = c^2                                 r^2 >= (mu+1)/mu c^2,
//
// convex for mu -> 0 and TLS for mu -> inf, by alternating (Black-Rangarajan
// duality) a weighted least-squares solve and the closed-form weights
//
//   w_k = 1, c sqrt(mu (mu+1)) / |r_k| - mu, or 0   (the same three cases).
//
// Each weighted solve is a weighted SE-Sync problem (weights multiply kappa
// and tau: internal/measurement_weights.h) run by the same staircase as
// Solve() (its local searches stopped at gnc_relative_gradient_tolerance
// or gnc_relative_decrease_tolerance, its climb at gnc_max_rank, its
// rounded poses not refined: gnc_refine_rounded_solution),
// warm-started from the previous factor Y (its negligible directions
// dropped), its data matrices re-weighted in place (same sparsity, symbolic
// analyses reused) or, once measurements have weight 0, rebuilt without them
// (their fill is the dominant cost). The first solve (all weights 1, at the
// initial rank: initial_max_rank) seeds mu_0 = g^2 / (2 max_k f_k - g^2)
// with its residuals (g^2: GNC's threshold), then mu <- mu_step * mu after
// every weight update. If every f_k of the first solve is within c^2 (its
// staircase then continues to max_rank) and it is certified, it is the
// answer (nothing rejected); uncertified (a wrong closure can bend a
// small map until it fits, leaving the relaxation inexact), GNC runs at
// each threshold g^2 below the largest f_k (above it every weight stays 1).
// GNC stops when the weights are binary (each within weight_tolerance of 0
// or 1) or the surrogate cost stalls. Then the weights are rounded (inlier
// iff w > 1/2), the problem restricted to the accepted measurements is
// solved and certified, and the accepted set is made consistent with c^2
// at that optimum (max_consistency_rounds), after which a few rejected
// measurements are re-admitted where that lowers the TLS cost and they fit
// at the accepted residuals' noise level (max_readmission_trials,
// readmission_min_scale), and a few accepted ones, the worst fits, are
// removed where the accepted set without them, made consistent again, has a
// lower TLS cost (max_removal_trials). GNC runs once per schedule of
// gnc_threshold_fractions (g^2 = fraction * c^2), the runs at once when
// solver_options.num_threads allows; the result with the lowest TLS cost is
// returned.
//
// Landmarks and priors (pose_graph.h): every term is a measurement of its
// own here, with its own weight, verdict and threshold: a landmark
// measurement (a wrong data association) has f_k = nu ||p_l - t_i - R_i
// z||^2, chi^2 with d degrees of freedom, and a prior (e.g. a GPS fix off
// by multipath) kappa ||R_i - R~||_F^2 + tau ||t_i - g||^2 with d(d-1)/2
// for its rotation plus d for its position; the default c_k^2 is the same
// inlier_probability quantile of its own distribution. GNC, the
// consistency rounds and re-admission treat all terms alike in units of
// their c_k^2 (the surrogate is homogeneous in (f_k, c_k^2)), with two
// rules for landmarks: when every observation of a landmark would get
// weight 0 (or be rejected), the one with the smallest f_k is kept (one
// observation alone is fit exactly and, a leaf, changes nothing else: TLS
// keeps one at no cost); and the consistency rounds place each landmark
// alone at the TLS-best of its current position and the positions its
// observations imply before accepting those within c_k^2 (GNC can leave a
// landmark seen by few poses at one of its wrong associations). A landmark
// that one pose alone observes truly is fit as well by one wrong
// association: the data cannot tell them apart. GNC starts from the
// least-squares fit of every term, which wrong associations can fold
// beyond its reach; so a graph with landmarks gets one more run (in
// RobustSolverSummary::runs after the GNC runs, competing by TLS cost like
// them; one after another, it is the last, and a time limit can leave it
// out) that starts elsewhere: the graph without its landmarks is solved
// robustly, each landmark is placed where most of its observations agree
// at those poses, and the terms accepted so are refined by the consistency
// rounds and re-admission trials. Rejecting every prior
// disconnects the world frame (kInlierGraphDisconnected). Measured
// (bench/results/landmark_outliers/, 2D and 3D maps with GPS priors, 10-50%
// wrong associations and false fixes, 81 runs): false fixes alone rejected
// exactly; the map right in 79 runs with the consensus run, 64 without
// (2D maps at 30-50%: folded by GNC, at a TLS cost above the truth's).
//
// What is certified, and what is not: the final SolverSummary certifies the
// optimum of the problem restricted to the accepted edges (weights in {0, 1}
// make the weighted problem exactly that problem; every round-off is
// accounted for as in Solve()). It does NOT say that the TLS problem is
// solved globally: which measurements are accepted is GNC's decision, a
// heuristic that can fail (e.g. with mutually consistent outliers that
// outnumber the inliers locally).

#ifndef CERES_SESYNC_ROBUST_SOLVER_H_
#define CERES_SESYNC_ROBUST_SOLVER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"

namespace ceres_sesync {

struct RobustSolverOptions {
  // Options of every weighted SE-Sync solve and of the final inlier
  // problem's (initialization, ranks, certification tolerances, threads).
  // Its max_time_s (0: none) limits each solve.
  SolverOptions solver_options;

  // Wall-clock limit of the whole robust solve in seconds (0: none). Every
  // solve gets the time left (or solver_options.max_time_s if smaller).
  // When it runs out during GNC, GNC stops there (status kTimeLimit: the
  // last step's poses and its weights rounded at 1/2; nothing certified);
  // after GNC, the consistency rounds and re-admission trials stop and the
  // last solved accepted set stands (certified if its solve was). A GNC run
  // cut short is selected only if no run finished. Building a re-weighted
  // problem's data matrices is not interrupted.
  double max_time_s = 0;

  // TLS threshold c^2 on f_k (see the top of this file), in the units of
  // eq. (12). <= 0 (default): the inlier_probability quantile of chi^2 with
  // d(d+1)/2 degrees of freedom (2D: 3, 3D: 6), and for landmark
  // measurements and priors the quantile of their own degrees of freedom.
  // > 0: c^2 of every term.
  double inlier_threshold = 0;
  // The probability that an inlier's f_k is below c^2 under the noise model,
  // in (0, 1). 1 - 1e-6 gives c^2 = 30.66 (2D) and 38.26 (3D). Real
  // datasets' precisions are only roughly calibrated: at the clean optimum
  // of cubicle the largest f_k is 26.3 (the 3D 0.999-quantile is 22.5), and
  // manhattan's rotation terms reach 27 with heavy tails, so that its TLS
  // optimum at this threshold rejects true closures (bench/README.md: it
  // needs inlier_threshold ~ 100).
  double inlier_probability = 0.999999;

  // GNC schedules, by their threshold as a fraction of c^2 (each in (0,
  // 1]): GNC is run once per entry from the first solve, each run followed
  // by its inlier problem and the consistency rounds at c^2 itself, and the
  // run with the lowest TLS cost sum_k min(f_k, c^2) at its result wins
  // (GNC is a heuristic; the TLS cost is what it heuristically minimizes,
  // and it can be evaluated). A strict GNC threshold rejects outliers
  // reliably but rejects inliers too where the precisions are loose, which
  // the consistency rounds then re-admit from a clean estimate; a
  // permissive one keeps inliers but can bend the map to fit wrong
  // closures. Measured (30% random outliers, default c^2): on intel GNC at
  // c^2 accepted 2, 3 and 8 wrong closures (3 seeds) and GNC at 0.1 c^2
  // none; on manhattan (c^2 = 100) GNC at c^2 recovered the truth and 0.1
  // c^2 rejected 14 true closures. {1}: plain GNC-TLS, half the time.
  // With solver_options.num_threads T >= 2 (0: all cores) the runs go at
  // once, min(T, runs) at a time with ~T / min(T, runs) threads each, each on
  // a problem of its own (its data matrices and factors: more memory while
  // they run; city10000 + 10%: peak RSS 283 -> 500 MB, 25.7 -> 16.8 s at T =
  // 2); the result is the same, bitwise, as with T = 1.
  std::vector<double> gnc_threshold_fractions = {1.0, 0.1};

  // Largest staircase rank of the first solve (all weights 1), at least
  // the initial rank r0 (d + 2 unless solver_options.initial_rank) and at
  // most solver_options.max_rank. Its fit to every measurement, outliers
  // included, only seeds mu_0 and the first weights; with outliers its
  // relaxation is rarely exact, and climbing the staircase there costs most
  // of the robust solve on large maps without helping GNC. Default 0: r0,
  // no climbing; solver_options.max_rank: the first solve is Solve()
  // itself. Without outliers the first solve is the inlier problem, and it
  // continues to solver_options.max_rank if it needs to (the result is then
  // Solve()'s). Measured (bench/results/outliers_gnc_effort.md, random
  // outliers at 10/30/50%, 3 seeds, GNC steps at 1e-3): intel and kitti_00
  // 17 of 18 runs exact with either first solve, 1.24x (intel) and 1.25x
  // (kitti_00) faster at r0; 154 noisy 3x3x3/4x4x4 cubes: 90 exact outlier
  // sets at r0, 91 with the full first solve; cubicle + 10% outliers: 397
  // -> 217 s (both changes).
  int initial_max_rank = 0;

  // Relative preconditioned gradient tolerance of the local searches of the
  // GNC steps' weighted solves (SolverOptions::
  // relative_preconditioned_gradient_tolerance); 0: solver_options'. Each
  // step's problem is replaced by the next one, so solving it as tightly as
  // the final one is wasted: the first solve and every solve after GNC (the
  // inlier problem, the consistency rounds and re-admission trials) use
  // solver_options' tolerance (the inlier problem is always solved again
  // after the last GNC step, from its factor). Measured (same
  // runs as above, full first solve): 1e-3 instead of 1e-6 left the
  // results unchanged (one intel run at 50% became exact) and took 18%
  // (intel) and 25% (kitti_00) less time; the cubes: 91 exact either way.
  double gnc_relative_gradient_tolerance = 1e-3;

  // Relative decrease tolerance of the GNC steps' local searches
  // (SolverOptions::relative_decrease_tolerance: a level ends at the first
  // accepted step that lowers F by less than this fraction of F); 0:
  // solver_options'. Like the gradient tolerance above, it applies to the
  // GNC steps only. Their first steps (every weight still positive,
  // relaxations not exact) otherwise crawl: on city10000 + 10% random
  // outliers step 1 took 159 trust-region iterations over ranks 4-6 (62
  // at this tolerance), many of them lowering F by 1e-4 of it. Measured
  // (bench/results/gnc_decrease/, against the caller's 1e-12): city10000 +
  // 10% 53.3 / 67.2 -> 24.4 / 26.0 s and cubicle + 10% 59.8 -> 36.6 s (CLI,
  // two threads), the same verdicts; the same verdicts on sphere2500,
  // torus3D, parking-garage and manhattan runs and on 154 noisy cubes;
  // intel, whose GNC is sensitive to any change, 9 -> 11 of 18 runs exact
  // (30/50%, seeds 1-9), clustered outliers 21 -> 20 of 36. 1e-2 lost
  // intel 30% seed 3; 3e-4 saved less (city10000 1.5x).
  double gnc_relative_decrease_tolerance = 1e-3;

  // Whether the GNC steps refine their rounded poses by a local search on
  // SO(d)^n (SolverOptions::refine_rounded_solution) before the next
  // weights are computed from them. The first solve, the inlier problem,
  // the consistency rounds and the re-admission trials keep solver_options'.
  // The refinement matters where a step's relaxation is not exact (often
  // so in the early steps, wrong closures still weighted): it descends from
  // the rounding to a local minimum of that weighted problem, whose weights
  // still include wrong closures. Off, GNC's weights come from the
  // relaxation's rounded solution. Measured (bench/results/gnc_refinement/,
  // both with the decrease tolerance above): intel, kitti_00, smallGrid3D at
  // 30/50% random outliers, seeds 1-9: 45 -> 49 of 54 runs exact (intel 11 ->
  // 15 of 18); five datasets at 10/30/50%, seeds 1-3: 43 -> 44 of 45;
  // clustered outliers on four datasets: 20 -> 25 of 36; 154 noisy cubes:
  // 90 -> 88; every verdict the same on ten larger runs (city10000 at two
  // thresholds, cubicle, sphere2500 at 10 and 30%, torus3D,
  // parking-garage, manhattan at 10/30/50%); ais2klinik + 10%, a failure
  // either way, rejects 6 true closures instead of 3.
  bool gnc_refine_rounded_solution = false;

  // Largest staircase rank of the GNC steps' weighted solves, at least r0
  // and at most solver_options.max_rank; 0 (default): r0 + 2. A step that
  // reaches it ends there without a certificate test (GNC uses only the
  // step's poses, and at the top rank there is nothing to escape to). The
  // first solve, the inlier problem, the consistency rounds and the
  // re-admission trials keep solver_options.max_rank. Climbing matters to
  // GNC: capped at r0 (with the first solve at r0 as well) kitti_00 with
  // random outliers kept wrong closures in 8 of 9 runs. But the first GNC
  // steps, whose relaxations are not exact (every weight still positive),
  // otherwise climb to rank 10 with the wrong closures' fill in every
  // factorization, most of a large map's robust solve. Measured (random
  // outliers, seed 1, one thread; previous default max_rank 10, same
  // session): city10000 + 10% 463.5 -> 155.8 s and cubicle + 10% 295.8 ->
  // 156.7 s (the same verdicts); intel and kitti_00 at 10/30/50% x 3
  // seeds 87.2 -> 52.1 s (8 -> 9 of 9 exact) and 47.1 -> 44.0 s (9 of 9);
  // 154 noisy cubes 90 exact either way (r0 + 1 with the test: 88).
  int gnc_max_rank = 0;

  // GNC schedule (Yang et al. 2020): mu_0 = g^2 / (2 max f_k - g^2) from the
  // residuals of the all-inlier solve (g^2: the run's GNC threshold), then
  // mu <- mu_step mu after each weight update.
  double mu_step = 1.4;
  // Largest number of weight updates (each followed by a weighted solve).
  int max_iterations = 100;
  // Stop when every weight is within this distance of 0 or 1 (GTSAM's
  // GncOptimizer default).
  double weight_tolerance = 1e-4;
  // Or when the surrogate cost sum_k rho_mu(f_k) changes by less than this
  // fraction between two solves (GTSAM's default).
  double relative_cost_tolerance = 1e-5;

  // After GNC (not part of Yang et al.'s method): while the accepted set
  // differs from {k : f_k <= c_k^2} at the certified optimum of the
  // accepted set's problem (landmark measurements: with their landmark
  // placed by the consensus rule at the top of this file), replace it and
  // solve again, at most this many times (0: off). Every round lowers the TLS
  // cost, so the result is a fixed point whenever fewer rounds suffice (then
  // num_rejected_within_threshold and num_accepted_beyond_threshold are 0).
  // Measured: GNC at c^2 = 100 rejected 3 true closures of manhattan (30%
  // random outliers) whose f_k at its result were below c^2; one round
  // re-admitted them.
  int max_consistency_rounds = 10;

  // After the consistency rounds (not part of Yang et al.'s method either):
  // a rejected measurement can lower the TLS cost once the map is
  // re-optimized with it although its f_k at the accepted set's optimum is
  // above c^2 (a true closure that a weakly constrained map bends away from
  // without it). The rejected measurements with the smallest f_k, each
  // with f_k <= readmission_max_cost c^2, at most max_readmission_trials of
  // them (0: off), are tried one at a time: the accepted set plus the
  // measurement is solved, and kept iff the TLS cost at its optimum is
  // lower and the rise it causes is small (readmission_min_scale; then
  // the consistency rounds run again). A trial costs one solve (from the
  // current factor); one more restores the accepted set's optimum if the
  // last trial was not kept. Measured: tinyGrid3D with one wrong closure
  // (`generate outliers --fraction 0.3 --seed 1`) rejected it and one true
  // closure (f_k = 3.6 c^2 at that optimum; TLS cost 83.9); re-admitting
  // the true closure gives the clean optimum plus c^2 (56.8).
  int max_readmission_trials = 5;
  double readmission_max_cost = 10;
  // A trial is kept iff it lowers the TLS cost and dF, the rise of the
  // accepted terms (the measurement's own f_k included), is below s c^2:
  // s = sigma0^2 clamped to [readmission_min_scale, 1], sigma0^2 = F_A /
  // (d(d+1)/2 (|A| - n + 1)) the a-posteriori variance factor of the
  // accepted set A at its optimum (its cost over its redundancy); 1: the
  // bare TLS rule (dF < c^2). A re-admission overrides GNC's rejection, so
  // where the accepted residuals show the precisions to be conservative
  // (sigma0^2 at the clean optimum: intel 0.022, city10000 0.020, kitti_00
  // 0.31, smallGrid3D 0.99) it asks for a closer fit, down to dF <
  // c^2 / 2 (2D 15.3, 3D 19.1 at the default c^2), which a true closure's
  // dF (chi^2 with 3 or 6 degrees of freedom under the noise model)
  // exceeds with probability 1.6e-3 (2D) or 3.9e-3 (3D). Measured (random
  // outliers): intel 50% (seed 1): the bare rule re-admitted two wrong
  // closures that bent the map to fit (dF 0.95 and 0.55 c^2; clean gap
  // 0.57), 0.5 none (exact). kitti_00 50% (seed 1) and 30% (seed 3): 0
  // (pure scaling) refused a true closure that 0.5 re-admits (exact).
  // smallGrid3D 50% (seed 1): exact at 0, 0.5 and 1. On 156 noisy 3x3x3
  // and 4x4x4 cubes with 30% and 50% outliers (seeds 1-40) exactly the
  // wrong closures were rejected on 62 without re-admission, 80 at 1, 93
  // at 0.5, 95 at 0.
  double readmission_min_scale = 0.5;

  // After the re-admission trials (not part of Yang et al.'s method either):
  // a wrong measurement that fits within its c^2 once the map is bent to it
  // stays accepted through the consistency rounds, and the true ones it
  // bends the map away from stay rejected. The accepted measurements (known
  // inliers excepted) with the largest f_k / c_k^2, at most this many
  // (0: off), are tried one at a time: the accepted set without it is
  // solved and, if that lets a rejected term other than it fit within its
  // c_k^2, made consistent (the consistency rounds above); the result is
  // kept iff its TLS cost is lower, the terms the rounds admitted fit as a
  // re-admission must (the accepted cost rises by less than s sum c_k^2
  // over them, s as above), and its optimum is certified. A trial costs a
  // solve from the current factor (plus its rounds and a report where it
  // admits something); a removal that would disconnect the accepted graph
  // is skipped. Measured
  // (bench/results/removal_trials/): cubicle with 50% random outliers (seed
  // 1) ended with one wrong closure accepted (the largest f_k / c^2 of the
  // accepted set, 12.1 of 38.3) and 18 true ones rejected, uncertified, at
  // a TLS cost of 293,478 against 292,284 at the true split; without it the
  // rounds re-admit 15 of them: certified, TLS 292,221, the clean graph's
  // own TLS optimum. 154 noisy cubes: 88 exact, the same 88 (without the
  // admission check 87, and without the certification condition as well
  // 82: a true closure dropped, the map bent until a wrong one fit, the
  // relaxation no longer exact). The same verdicts on 46 runs of
  // tinyGrid3D, smallGrid3D, intel, kitti_00, manhattan and ais2klinik and
  // 54 of intel, kitti_00 and CSAIL. A 3x10^4-pose city + 10%: 80.9 s
  // before, 107.9 s with rounds in every trial, 75.2 s with the check.
  int max_removal_trials = 3;

  enum class KnownInliers {
    kNone,  // Every measurement's weight is estimated.
    // Odometry, i.e. measurements between consecutive poses (|i - j| = 1 in
    // dense order: the order of the VERTEX lines, or of first appearance),
    // keep weight 1. A SLAM front end's odometry is rarely wrong, and it
    // keeps the accepted graph connected.
    kOdometry,
  };
  KnownInliers known_inliers = KnownInliers::kOdometry;
};

struct RobustSolverSummary {
  enum class Status {
    // GNC ended with binary weights or a stalled surrogate cost, and the
    // inlier problem was solved (inlier_summary: certified or not).
    kConverged,
    // max_iterations weight updates without convergence; the weights were
    // rounded at 1/2 and the inlier problem solved as for kConverged.
    kMaxIterations,
    // The measurements of positive weight (at some GNC step, or the
    // accepted ones) leave the graph disconnected, so the relative placement
    // of its parts is undetermined: no inlier problem was solved. The
    // returned poses are the last connected step's; see message.
    kInlierGraphDisconnected,
    // max_time_s ran out before GNC ended (see max_time_s): the poses of
    // the last step (its rounding, refined only with
    // gnc_refine_rounded_solution), verdicts from its weights; not
    // certified.
    kTimeLimit,
    // The graph or the options failed validation; see message.
    kInvalidInput,
  };
  // One measurement's verdict, at the returned poses.
  struct Edge {
    // The term: a relative pose measurement, a landmark measurement or a
    // prior, and its index into graph.measurements,
    // graph.landmark_measurements or graph.priors.
    enum class Kind { kMeasurement, kLandmark, kPrior };
    Kind kind = Kind::kMeasurement;
    // "measurement", "landmark" or "prior" (reports, JSON, CSV, Python).
    const char* KindString() const;
    int index = 0;
    // The original vertex ids (PoseGraph::vertex_ids) of the measured poses;
    // for a landmark measurement the observing pose's and the landmark's
    // (PoseGraph::landmark_ids), for a prior its pose's (both).
    int64_t vertex_i = 0, vertex_j = 0;
    // Final GNC weight in [0, 1] before rounding (1 for known inliers).
    double weight = 1;
    // Accepted: part of the inlier problem (weight > 1/2, unless a
    // consistency round changed it).
    bool inlier = true;
    // Weight held at 1 by known_inliers.
    bool known_inlier = false;
    // Angle of R~_k^T R_i^T R_j, in degrees (a prior: of R~^T R_i; 0
    // without a rotation term).
    double rotation_residual_deg = 0;
    // ||t_j - t_i - R_i t~_k||, in the graph's length unit (a landmark
    // measurement: ||p_l - t_i - R_i z||; a prior: ||t_i - g||).
    double translation_residual = 0;
    // f_k: the term of pose_graph.h's F (compare to threshold).
    double cost = 0;
    // Its TLS threshold c_k^2 (inlier_threshold for measurements).
    double threshold = 0;
  };
  // One GNC step: the weighted solve that followed a weight update.
  struct Iteration {
    double mu = 0;              // Of the weights this solve used.
    double surrogate_cost = 0;  // sum_k rho_mu(f_k) at its result.
    int num_zero_weights = 0;   // w = 0.
    int num_unit_weights = 0;   // w = 1.
    SolverSummary::Status status = SolverSummary::Status::kInvalidInput;
    int rank = 0;               // Final staircase rank.
    int solver_iterations = 0;  // Local-solver iterations, all levels.
    // Seconds: local optimization, certificate tests (both of all levels),
    // and the whole step (re-weighting + solve + rounding).
    double optimization_time_s = 0, verification_time_s = 0, time_s = 0;
  };

  Status status = Status::kInvalidInput;
  // Why the input was invalid, the graph disconnected or the time ran out
  // (also when the limit only stopped the consistency rounds or
  // re-admission trials after GNC: status kConverged); else empty.
  std::string message;
  int dimension = 0, num_poses = 0, num_measurements = 0;
  int num_landmark_measurements = 0, num_priors = 0;
  // c^2 of the relative pose measurements (options.inlier_threshold or the
  // chi-square quantile), and the selected GNC run's threshold on them.
  double inlier_threshold = 0;
  double gnc_threshold = 0;
  // One GNC schedule (RobustSolverOptions::gnc_threshold_fractions), and
  // for graphs with landmarks the consensus run after them (see the top of
  // this file), whose gnc_threshold is 0.
  struct Run {
    double gnc_threshold = 0;
    Status status = Status::kConverged;
    int iterations = 0, consistency_rounds = 0, num_outliers = 0;
    // Re-admission trials made and measurements re-admitted.
    int readmission_trials = 0, readmissions = 0;
    // Removal trials made and measurements removed.
    int removal_trials = 0, removals = 0;
    // sum_k min(f_k, c^2) (known inliers: f_k) at the run's result.
    double tls_cost = 0;
    bool certified = false;  // Its inlier problem's certificate.
    double time_s = 0;       // Wall clock (concurrent runs overlap).
  };
  std::vector<Run> runs;
  // Index of the run whose result is returned (lowest TLS cost).
  int selected_run = -1;
  // mu_0 of the selected run (0 if no update was needed: every f_k <= c^2
  // at the first solve).
  double initial_mu = 0;
  // The selected run's weight updates (0: the all-inlier solve already
  // fit) and their steps.
  int iterations = 0;
  std::vector<Iteration> history;
  // Whether the selected run's final weights were binary to
  // weight_tolerance.
  bool weights_binary = false;
  // One verdict per term: the measurements in the graph's order, then the
  // landmark measurements, then the priors.
  std::vector<Edge> edges;
  // Terms accepted and rejected (all kinds).
  int num_inliers = 0, num_outliers = 0;
  // Indices (into graph.measurements: for g2o files, the 0-based order of
  // the pose-pose EDGE lines) of the rejected measurements, ascending.
  std::vector<int> outlier_edges;
  // The same for the rejected landmark measurements
  // (graph.landmark_measurements) and priors (graph.priors).
  std::vector<int> outlier_landmark_measurements, outlier_priors;
  // Diagnostics at the returned poses: rejected terms with f_k <= c_k^2,
  // accepted ones (known inliers excepted) with f_k > c_k^2. Both 0 at a
  // TLS-consistent split.
  int num_rejected_within_threshold = 0;
  int num_accepted_beyond_threshold = 0;
  // The first solve's summary (all weights 1: Solve() up to
  // initial_max_rank; the complete Solve() when every measurement fits).
  SolverSummary initial_summary;
  // The final solve's: the problem restricted to the accepted measurements.
  // Its objective, bounds and certificate are of that problem. (kTimeLimit:
  // the last GNC step's weighted problem, or the first solve's.)
  SolverSummary inlier_summary;
  // Consistency rounds made after GNC (see max_consistency_rounds).
  int consistency_rounds = 0;
  // Measurements the selected run re-admitted (see max_readmission_trials).
  int readmissions = 0;
  // Removal trials the selected run kept (see max_removal_trials).
  int removals = 0;
  // Times the weighted problem was rebuilt on the subgraph of positive
  // weights (to shed the fill of rejected measurements).
  int pattern_rebuilds = 0;
  // GNC runs that went at once (1: one after another).
  int concurrent_runs = 1;
  // Seconds: the first solve; the GNC runs (each with its inlier problem;
  // wall clock); of the selected run, what followed its GNC steps (the
  // inlier problem, consistency rounds and re-admission trials); total.
  double initial_time_s = 0, gnc_time_s = 0, inlier_time_s = 0,
         total_time_s = 0;

  // The optimum of the problem restricted to the accepted measurements is
  // certified (inlier_summary.certified(); never for kTimeLimit). Never a
  // statement about the TLS problem's global optimum.
  bool certified() const;
  std::string StatusString() const;
  std::string BriefReport() const;
  // Includes the per-edge verdicts of the rejected measurements (all of
  // them with `all_edges`).
  std::string FullReport(bool all_edges = false) const;
};

// Whether a measurement counts as odometry for KnownInliers::kOdometry:
// between consecutive poses in dense order (|i - j| = 1).
bool IsOdometry(const RelativePoseMeasurement& measurement);

// The TLS threshold c^2 the options give for dimension d (see
// RobustSolverOptions::inlier_threshold); NaN for invalid options.
double InlierThreshold(const RobustSolverOptions& options, int dimension);

// f_k of every term at `solution` (pose_graph.h's terms, unweighted: the
// TLS residuals), in the order of RobustSolverSummary::edges: the
// measurements, then the landmark measurements, then the priors (a prior's
// rotation and position parts together).
std::vector<double> TermCosts(const PoseGraph& graph, const Solution& solution);

// The TLS threshold c_k^2 of every term, in the same order (see
// inlier_threshold); empty for invalid options.
std::vector<double> TermThresholds(const RobustSolverOptions& options,
                                   const PoseGraph& graph);

// Solves the pose graph robustly (see the top of this file). Returns the
// poses of the final inlier problem (in Solve()'s gauge), or those of the
// last connected GNC step for kInlierGraphDisconnected, or {} for
// kInvalidInput. Deterministic for given options (including num_threads).
Poses SolveRobust(const PoseGraph& graph, const RobustSolverOptions& options,
                  RobustSolverSummary* summary);
// The same with the landmark positions too (as Solve()'s Solution
// overload): *solution gets the poses and one position per landmark.
void SolveRobust(const PoseGraph& graph, const RobustSolverOptions& options,
                 Solution* solution, RobustSolverSummary* summary);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_ROBUST_SOLVER_H_
