// SE-Sync: certifiably correct pose-graph optimization (Rosen, Carlone,
// Bandeira, Leonard, "SE-Sync: A certifiably correct algorithm for
// synchronization over the special Euclidean group", IJRR 2019).
//
//   ceres_sesync::SolverOptions options;
//   ceres_sesync::SolverSummary summary;
//   ceres_sesync::Poses poses = ceres_sesync::Solve(graph, options, &summary);
//   std::cout << summary.FullReport() << "\n";
//   if (summary.certified()) { ... poses are a global optimum ... }
//
// The solver runs the Riemannian staircase (Algorithm 1): it minimizes the
// Burer-Monteiro cost tr(Q Y^T Y) over St(d, r)^n with a truncated-Newton
// Riemannian trust-region method, checks the optimality certificate
// S = Q - Lambda with a sparse Cholesky factorization, escapes saddle points
// along negative curvature to rank r + 1, and finally rounds Y to SO(d)^n
// (Algorithm 2) and recovers the translations (eq. 21).

#ifndef CERES_SESYNC_SESYNC_SOLVER_H_
#define CERES_SESYNC_SESYNC_SOLVER_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

// What SolverOptions::progress receives: where the solve is and how it is
// doing, for progress displays of long solves (tools/progress.h prints it).
struct SolverProgress {
  // The stage that starts (or, for "optimize", the iteration just done):
  // "data" (data matrices, factorizations), "initialize", "optimize" (one
  // report when a staircase level starts, iteration 0, then one per local
  // solver iteration), "verify" (the certificate of a level), "round",
  // "prove" (a deferred double-double proof for the rounded poses, when
  // needed), "done" (objective = F(x) of the returned poses). Static
  // strings.
  const char* stage = "";
  int rank = 0;       // Staircase rank (0 before the staircase).
  int iteration = 0;  // Local-solver iteration within the level.
  // F(Y) at the current iterate (F(x) for "done"; 0 when not known yet).
  double objective = 0;
  double gradient_norm = 0;  // Riemannian gradient norm (0 if not known).
  double elapsed_s = 0;      // Wall-clock seconds since the solve started.
  // Set by SolveByComponent (component_solver.h): the component being solved
  // (0-based) and the number of components; 0 and 1 for a plain Solve.
  int component = 0;
  int num_components = 1;
};

struct SolverOptions {
  enum class Initialization {
    kChordal,   // Chordal relaxation (one sparse solve). Recommended.
    kRandom,    // A uniformly random point of St(d, r0)^n.
    kVertices,  // The graph's own initial_poses (from VERTEX lines).
  };
  enum class Preconditioner {
    kNone,
    // Inverse d x d diagonal blocks of D = L(G^rho) + Sigma~ (Q's sparse
    // part), regularized.
    kBlockJacobi,
    // Sparse Cholesky of D + eps I.
    kSparseCholesky,
    // (Q + eps I)^{-1} applied exactly through a sparse Cholesky factor of the
    // translation-augmented matrix [Lbar -Vbar; -Vbar^T D + eps I] (its Schur
    // complement is Q + eps I). Best on strongly translation-coupled graphs.
    kRegularizedQ,
    // kRegularizedQ, except where its factor is predicted to be costly:
    // where factorizing K_eps costs more than 3 applications of its factor
    // (CHOLMOD's symbolic prediction of flops and entries at the initial
    // rank; deterministic), block-Jacobi, which switches to kRegularizedQ
    // for the rest of the solve once its truncated-CG iterations exceed 20
    // times that ratio in all, or at a saddle escape (the descent after one
    // is long and flat: a 3x10^4-pose city at kappa 10, 2034 products, 1.13x
    // faster than kRegularizedQ this way, 1.06x slower without). Such factors
    // are those of well-connected maps (2D cities 4-25, sphere2500 and
    // cubicle 7.6, torus3D 11), where block-Jacobi needs 1.6-3x the
    // Hessian-vector products (cubicle 4x, torus3D 11x) but each costs 3-5x
    // less and nothing is factorized; on long trajectories (kitti_00,
    // ais2klinik, CSAIL, intel, manhattan, parking-garage: ratios 0.5-2.2) it
    // would need 10-180x the products. Measured (one thread, same results;
    // bench/results/preconditioner_auto): city10000 0.65 -> 0.39 s, sphere2500
    // 0.36 -> 0.19 s, 1000 to 10^5-pose cities 1.13-1.37x faster; cubicle 8%
    // and torus3D 2% slower; with two threads a 10^5-pose city only 4% faster.
    // SolverSummary::preconditioner says which one ran. Recommended.
    kAutomatic,
  };

  // How the staircase is started. Solve(graph, initial, ...) overrides this.
  Initialization initialization = Initialization::kChordal;
  // Seed for kRandom (results are deterministic for a seed).
  uint64_t seed = 0;
  // Initial rank r0 of the staircase; 0 means d + 2. Must be >= d + 1 if set.
  int initial_rank = 0;
  // Largest rank tried before giving up with kMaxRankReached.
  int max_rank = 10;

  // Preconditioner of the truncated CG inner solver, and the condition number
  // cap of the regularized ones: eps = lambda_max(D) / cap.
  Preconditioner preconditioner = Preconditioner::kAutomatic;
  double regularized_cholesky_max_condition = 1e6;
  // At rank d (the staircase's first level, optimized on the d nonzero rows
  // of its chordal start), every block Y_i is a d x d orthogonal matrix,
  // tangent vectors are Y_i Omega_i with Omega_i skew, and the Riemannian
  // Hessian is a sparse matrix in the coordinates of the Omega_i and the
  // translations (a Gauss-Newton-sized system of SE(d)^n, but the exact
  // Hessian). With this option that matrix's inverse preconditions the
  // first level's truncated CG (where it is not positive definite the
  // preconditioner above is used), each subproblem then taking one or two
  // products. In 2D, where its factorization costs at most 16 solves of its
  // factor (every shared 2D dataset; cities to ~10^4 poses), from the level's
  // start, its factor kept while the subproblems stay short, and kAutomatic's
  // exact preconditioner then factorized only if used: kitti_00 22 -> 4
  // products (1.28x faster), intel 23 -> 3 (1.30x), city10000 100 -> 4
  // (1.34x). Elsewhere the level switches to it (refactorized at every
  // iterate) when one of its first two truncated-CG solves takes more than
  // about twice its factorization's cost in products: parking-garage 205 ->
  // 56 (1.7x); the other 3D datasets do not switch.
  bool newton_at_rank_d = true;

  enum class LocalSolver {
    // The built-in truncated-Newton Riemannian trust region (RTR) with the
    // exact Hessian. Default: fast and reaches high precision.
    kTrustRegion,
    // ceres::GradientProblemSolver (LBFGS) on StiefelProductManifold: Ceres
    // itself as the staircase's local solver (first order; slower to reach
    // the precision certification needs).
    kCeresLbfgs,
  };
  LocalSolver local_solver = LocalSolver::kTrustRegion;
  // kCeresLbfgs: iteration limit per level and Ceres's gradient tolerance
  // (max-norm of x - Plus(x, -grad)).
  int ceres_lbfgs_max_iterations = 20000;
  double ceres_lbfgs_gradient_tolerance = 1e-9;

  // Local optimization at each rank (Riemannian trust region): the paper's
  // iteration limits.
  int max_iterations = 1000;
  int max_inner_iterations = 10000;
  // Stop when the preconditioned gradient norm sqrt(<g, P g>) falls below
  // this fraction of sqrt(F(Y)) (scale-free; F has units of the weights).
  double relative_preconditioned_gradient_tolerance = 1e-6;
  // Stop when an accepted step decreases F by less than this fraction of F.
  double relative_decrease_tolerance = 1e-12;

  // Certification (see certification.h, "What is proven"). S + eta I is
  // first tested with the shift eta_target whose bound eta d n equals
  // `certification_target_relative_bound` * F(Y); every proof accounts for
  // all floating-point round-off (of the data matrices, their assembly and
  // the factorization). The solution is certified iff the proven relative
  // suboptimality bound (F(x) - lower bound) / lower bound is at most
  // `certification_max_relative_bound` (1e-3 matches the 4 digits of the
  // paper's tables). A proof whose bound is above
  // `certification_goal_relative_bound` is tightened in double-double
  // arithmetic (proof_arithmetic kAutomatic): long trajectories and large
  // maps need it, because double resolves only ~1e-16 of the data's scale,
  // which on large maps is amplified by the squared extent of the map.
  double certification_target_relative_bound = 1e-9;
  double certification_max_relative_bound = 1e-3;
  double certification_goal_relative_bound = 1e-6;
  enum class ProofArithmetic {
    // Double, then double-double when the double proof's bound is above the
    // goal and the candidate is near-optimal. Recommended.
    kAutomatic,
    // Double only: fastest, but large maps may then be certified only
    // loosely, or not at all.
    kDouble,
    // Double-double for every proof (double still finds saddle escapes).
    kDoubleDouble,
  };
  ProofArithmetic proof_arithmetic = ProofArithmetic::kAutomatic;
  // The relaxation is reported exact (SolverSummary::relaxation_exact) when
  // the rounded poses attain the relaxation's value to this relative gap:
  // (F(x) - F(Y)) / F(Y) <= certification_max_rounding_gap. Exactness is
  // reported on its own; it never withholds a proven certificate.
  double certification_max_rounding_gap = 1e-6;
  // Absolute floor on eta relative to max diag(Q's sparse part) (matters for
  // noiseless data where F(Y) = 0).
  double min_relative_eta = 1e-16;

  // After rounding (Algorithm 2), run the local solver on SO(d)^n from the
  // rounded rotations. No-op when the relaxation is exact; otherwise it
  // lowers F(x) (and the suboptimality bound).
  bool refine_rounded_solution = true;

  // After a saddle escape the descent at the new rank is long and flat, and
  // the certificate usually becomes provable within the tolerance well
  // before the local solver's own tests are met (a 10^5-pose city with a
  // rank-4 saddle: after 185 of 379 Hessian-vector products). With this on,
  // levels entered by an escape test the certificate during their
  // optimization: one factorization of S + eta I, eta half the tolerance's
  // shift (certification_max_relative_bound * F(Y) / (2 d n)), in double
  // where double can prove it, else double-double (but where double reaches
  // three quarters of the shift, as on maps of ~10^6 poses, in double at the
  // smallest shift it reaches, on the double-double test's schedule),
  // whenever the Hessian-vector products since the last test number at
  // least twice a factorization's cost in products (the symbolic analysis's
  // flop count, a double-double test priced at 1.5 double ones; not a time,
  // so results do not depend on the machine's load or the thread count) and
  // a quarter of the level's products so far (the 10^6-pose city: certified
  // after 173-175 rank-5 products; with half, 175 or 491 on two trajectories
  // that differ in round-off: a test's outcome near the tolerance is
  // marginal). The level stops at the first test that passes; its proof
  // stands, and the level's verification tightens it in double where double
  // reaches at least 2x below it.
  // The returned poses are the same (rounding refines them to the same local
  // optimum); the proven bound is within the tolerance but can be looser than
  // after a converged descent (large maps: half to three quarters of the
  // tolerance). Off: every level runs to the local solver's tests.
  bool test_certificate_after_escape = true;

  // Stop the first level's descent as soon as its certificate is provable
  // (off by default: the poses are then certified but not polished). A level
  // that starts at a rank-d point (the chordal initialization, or given
  // poses), whose verification would prove in double-double at a sixteenth
  // of the goal's shift (certification_goal_relative_bound * F(Y) /
  // (16 d n); double cannot reach the goal there: long trajectories, all
  // but the smallest maps), tries that proof once the Riemannian gradient's
  // norm is at most 1e7 times that shift, and stops if it holds; the
  // verification keeps the proof, so the bound is the one it would prove at
  // that point (on the datasets the same to 3 digits as after the converged
  // descent) and costs no more factorizations. One test per level (a failed
  // one costs a factorization). On the 12 datasets the threshold separated
  // the points where the proof holds (ratios <= 1.15e7) from those where it
  // fails (>= 1.18e7). Not on maps whose factorization takes >= 1e10
  // multiply-adds (their first level often ends at a lifted saddle).
  // What is not run is the local solver's polish of an already certified
  // point: 8 of 22 products on kitti_00, 32 of 100 on city10000, 76 of 205
  // on parking-garage. The poses differ from the converged ones within what
  // the proof covers: F(x) up to 5.5e-8 relative above the converged F
  // (manhattan), poses 1.6e-5 apart on a 300-pose landmark map, where the
  // default polishes them to the local solver's 1e-6 relative gradient
  // tolerance.
  bool test_certificate_near_convergence = false;

  // Threads for the products with Q, the triangular solves (two subtrees of
  // the factor's elimination tree at a time), the double-double proof's
  // factorization (likewise, plus column ranges of its top separators), and
  // the exact preconditioner's factorization, which runs beside the chordal
  // initialization. Kernels under ~1.5 ms of work stay on one thread. <= 0:
  // all cores (std::thread::hardware_concurrency()). Results are bitwise the
  // same for every value. CHOLMOD's own factorizations are serial.
  int num_threads = 0;

  // Wall-clock limit for the whole solve (<= 0: none).
  double max_time_s = 0;
  // Log progress (rank, iteration, F, gradient norm, trust radius) via glog.
  bool verbose = false;
  // Optional per-iteration callback (rank, iteration, F, gradient norm,
  // trust radius); return false to stop the current level.
  std::function<bool(int rank, int iteration, double f, double gradient_norm,
                     double trust_radius)>
      callback;
  // Optional progress report (see SolverProgress): called at every stage
  // boundary and after every trust-region iteration, always from the thread
  // that called Solve. Must be cheap (throttle any output).
  std::function<void(const SolverProgress&)> progress;
};

struct SolverSummary {
  enum class Status {
    // The rounded poses are proven within certification_max_relative_bound
    // of the optimum (relative to the proven lower bound): a global optimum.
    kCertifiedOptimum,
    // A lower bound was proven, but the poses' relative suboptimality bound
    // is above certification_max_relative_bound (e.g. a relaxation that is
    // not exact here: see relaxation_exact). lower_bound is valid. Where the
    // relaxation was certified within the tolerance but the rounded poses
    // were not, and a tighter proof could have brought them within (F(Y)
    // above the lower bound they need), the staircase has tried it first:
    // Y verified again at the shift that bound allows, then escapes and
    // levels towards it (a level "verified again for the rounded poses" in
    // `levels`); this status means it failed (the relaxation's optimum is
    // below that bound, or max_rank or the time limit stopped it), and the
    // poses and bound are those from before.
    kBoundAboveTolerance,
    kSaddleNotEscaped,  // Negative curvature found, no descent along it.
    kEigenImprecision,  // No shift proven and no negative curvature found.
    kMaxRankReached,    // Not certified at max_rank.
    kTimeLimit,         // max_time_s reached.
    kInvalidInput,      // The graph failed validation; see message.
  };
  struct Level {
    int rank = 0;
    int iterations = 0;
    int hessian_vector_products = 0;
    double sdp_value = 0;  // F(Y) at the end of the level.
    double gradient_norm = 0;
    std::string termination;
    bool certified = false;
    double eta = 0;
    double lambda_min_estimate = 0;
    double optimize_time_s = 0;
    double verify_time_s = 0;
    // The level's certificate factorizations: double, double-double
    // (including those of certificate tests).
    int factorizations = 0;
    int extended_factorizations = 0;
    // Certificate tests during the optimization (test_certificate_after_
    // escape) and whether one passed (the level's optimization then stopped
    // there); their time counts in verify_time_s, not optimize_time_s.
    int certificate_tests = 0;
    bool certificate_test_passed = false;
  };

  Status status = Status::kInvalidInput;
  // Error text for kInvalidInput; the bound and the tolerance for
  // kBoundAboveTolerance.
  std::string message;
  int dimension = 0, num_poses = 0, num_measurements = 0;
  // Landmarks, landmark measurements and priors of the graph.
  int num_landmarks = 0, num_landmark_measurements = 0, num_priors = 0;
  // F(x) (pose_graph.h: eq. (12) plus the landmark and prior terms) at the
  // returned solution.
  double objective = 0;
  // F(Y) = tr(Q Y^T Y) at the final factor Y (the SDP relaxation's value
  // there).
  double sdp_value = 0;
  // Proven lower bound on the optimal value: max(0, tr(Lambda) - eta d n),
  // rounded down (F is a sum of squares, so 0 is always one; n counts the
  // world pose when the graph has priors). Solutions with F(x) <= 1e-12 times
  // the sum of all precisions (trees, noiseless data) are certified by
  // F >= 0 alone.
  double lower_bound = 0;
  // (objective - lower_bound) and its ratio to lower_bound, with the
  // objective rounded up by a bound on its own evaluation's round-off
  // (internal/objective_bound.h; ~1e-12 relative).
  double suboptimality_bound = 0;
  double relative_suboptimality_bound = 0;
  // Relative rounding gap (F(x) - F(Y)) / F(Y).
  double rounding_gap = 0;
  double lambda_min_estimate = 0;  // NaN when no eigensolve was needed.
  // Shift proven for S + eta I >= 0 (all round-off included; +inf if none).
  double eta = 0;
  // The arithmetic of the factorization that proved eta: "double",
  // "double-double", or "none" (no shift proven).
  std::string proof_precision = "none";
  // The SDP relaxation is exact here: the final factor was certified optimal
  // for the relaxation and the rounded poses attain its value
  // (rounding_gap <= certification_max_rounding_gap, or F = 0). Reported on
  // its own: a non-exact relaxation still certifies the poses when their
  // proven bound is within the tolerance.
  bool relaxation_exact = false;
  int final_rank = 0;
  int iterations = 0;
  int hessian_vector_products = 0;
  // The truncated-CG preconditioner the solve ended with (kAutomatic
  // resolved): "none", "block-Jacobi", "sparse Cholesky of D" or "exact
  // (Q + eps I)^-1"; when kAutomatic's block-Jacobi switched, "exact (Q +
  // eps I)^-1 after N block-Jacobi iterations". When the first level used
  // the Newton preconditioner (newton_at_rank_d), followed by "; Newton at
  // rank d (N factorizations)", or that alone when the preconditioner above
  // was never applied.
  std::string preconditioner;
  // Cholesky factorizations of the certificate matrix in verification
  // (certificate tests included), in double and in double-double, and the
  // seconds the latter took (part of verification_time_s).
  int factorizations = 0;
  int extended_factorizations = 0;
  double extended_proof_time_s = 0;
  // Certificate tests during the descents after saddle escapes (the sum of
  // the levels'; test_certificate_after_escape).
  int certificate_tests = 0;
  std::vector<Level> levels;
  // Wall-clock seconds per stage.
  double data_time_s = 0, initialization_time_s = 0, optimization_time_s = 0,
         verification_time_s = 0, rounding_time_s = 0, total_time_s = 0;

  bool certified() const { return status == Status::kCertifiedOptimum; }
  std::string StatusString() const;
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Solves the pose graph; the initialization comes from options. Returns the
// poses (empty on invalid input); for a graph with landmarks, the overloads
// with a Solution also return the landmark positions.
Poses Solve(const PoseGraph& graph, const SolverOptions& options,
            SolverSummary* summary);

// Solves the pose graph starting from the given poses (their rotations are
// projected to SO(d); the translations are not used: they are optimal for the
// rotations at every step); options.initialization is ignored.
Poses Solve(const PoseGraph& graph, const Poses& initial,
            const SolverOptions& options, SolverSummary* summary);

// The same for graphs with landmarks and priors (and any other graph):
// *solution gets the poses and one position per landmark (dense landmark
// order), both empty on invalid input. Landmarks, like translations, are
// eliminated in closed form (sesync_problem.h), so only the initial poses'
// rotations matter. Gauge: with priors the solution is in the world frame
// of the priors (they fix the gauge; no FIX pose); without priors as for
// pose graphs (the FIX pose, else pose 0, at its initial value, else at
// the identity), landmarks moved with the poses.
void Solve(const PoseGraph& graph, const SolverOptions& options,
           Solution* solution, SolverSummary* summary);
void Solve(const PoseGraph& graph, const Poses& initial,
           const SolverOptions& options, Solution* solution,
           SolverSummary* summary);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_SESYNC_SOLVER_H_
