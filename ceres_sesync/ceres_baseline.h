// Local-search baselines: the maximum-likelihood objective (12) of Rosen et
// al. (IJRR 2019), with the landmark and prior terms of pose_graph.h,
//
//   F(x, p) = sum_(i,j) kappa_ij ||R_j - R_i R~_ij||_F^2
//                     + tau_ij   ||t_j - t_i - R_i t~_ij||_2^2
//           + sum_(i,l) nu_il    ||p_l - t_i - R_i z_il||_2^2
//           + sum_k     kappa_k  ||R_i(k) - R~_k||_F^2 + tau_k ||t_i(k) -
//           g_k||^2,
//
// minimized directly by Ceres (Levenberg-Marquardt, or Powell's dogleg with
// the Gauss-Newton model, the paper's PDL-GN baseline). These find a local
// minimum only; nothing certifies it.
//
// Ceres minimizes 0.5 * sum ||r||^2, so with the residuals used here F = 2 *
// Ceres cost. Parametrization:
//  - d = 2: per pose a translation block (x, y) and an angle block (theta),
//    R(theta) = [cos -sin; sin cos]; residual (6 entries)
//      [sqrt(kappa) vec(R(theta_j) - R(theta_i) R~);
//       sqrt(tau) (t_j - t_i - R(theta_i) t~)].
//  - d = 3: per pose a translation block (3) and an Eigen quaternion block
//    (x, y, z, w) on ceres::EigenQuaternionManifold; residual (12 entries)
//    with vec(R(q_j) - R(q_i) R~) (9) and the translation term (3).
//  - per landmark a position block (d); a landmark measurement is a residual
//    sqrt(nu) (p_l - t_i - R_i z) (d entries) over (t_i, rotation_i, p_l).
//  - a prior gives up to two residual blocks: sqrt(kappa) vec(R_i - R~)
//    (d^2 entries) over rotation_i if kappa > 0, sqrt(tau) (t_i - g) (d
//    entries) over t_i if tau > 0.
// Jacobians by automatic differentiation.
//
// Gauge: without priors F is invariant under a global rigid motion, and one
// pose (graph.fixed_pose if >= 0, else pose 0) is held constant. Priors fix
// the gauge themselves (graph.fixed_pose is -1 then, see ValidatePoseGraph):
// if some prior has a position term nothing is held constant and the result
// is in the world frame of the priors; if all priors are rotation-only, the
// global translation is still free and only pose 0's translation is held.
// Priors that leave a rotation free (e.g. position priors at one point
// only) leave the problem rank-deficient in that direction; the trust
// region's regularization copes, and the result is one of the minimizers.
//
// Robust losses (CeresRobustLoss): each measurement's residual block gets a
// ceres::LossFunction on its squared norm s = f_k, the measurement's term of
// eq. (12). With the scale a = sqrt(threshold) (Ceres's parameter),
//   Huber:  rho(s) = s for s <= a^2, 2 a sqrt(s) - a^2 beyond;
//   Cauchy: rho(s) = a^2 log(1 + s / a^2),
// so threshold = c^2, the TLS threshold of robust_solver.h, compares the
// losses with the robust solve on the same scale. Landmark measurements get
// the loss with their own landmark_threshold, and priors with
// prior_threshold on each of their residual blocks (rotation and position
// apart); with 0 (the default) they get none.

#ifndef CERES_SESYNC_CERES_BASELINE_H_
#define CERES_SESYNC_CERES_BASELINE_H_

#include <string>
#include <vector>

#include "ceres/problem.h"
#include "ceres/solver.h"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct CeresRobustLoss {
  enum class Type {
    kNone,    // Least squares (no loss function).
    kHuber,   // ceres::HuberLoss(sqrt(threshold)).
    kCauchy,  // ceres::CauchyLoss(sqrt(threshold)).
  };
  Type type = Type::kNone;
  // a^2 on f_k (> 0 with a loss): where the loss leaves the quadratic.
  double threshold = 0;
  // a^2 of the same loss on the f_k of landmark measurements, and on the
  // rotation and position terms of priors (>= 0; 0: least squares there).
  double landmark_threshold = 0;
  double prior_threshold = 0;
};

struct CeresBaselineOptions {
  enum class Method {
    // ceres::LEVENBERG_MARQUARDT trust region.
    kLevenbergMarquardt,
    // ceres::DOGLEG with TRADITIONAL_DOGLEG: Powell's dogleg with the
    // Gauss-Newton model (the paper's PDL-GN baseline).
    kPowellDogleg,
  };
  Method method = Method::kPowellDogleg;
  // Stop when |F_old - F_new| / F_old < function_tolerance (the paper's
  // relative-decrease criterion, 1e-6).
  double function_tolerance = 1e-6;
  // Stop when max_i |x_i - Plus(x_i, -grad_i)| < gradient_tolerance (Ceres's
  // default 1e-10).
  double gradient_tolerance = 1e-10;
  // Stop when |step| < parameter_tolerance * (|x| + parameter_tolerance)
  // (Ceres's default 1e-8).
  double parameter_tolerance = 1e-8;
  // Maximum number of iterations (the paper's limit: 1000).
  int max_num_iterations = 1000;
  // Wall-clock limit of the solve, in seconds.
  double max_solver_time_s = 1e9;
  // Threads for Jacobian evaluation and the linear solver.
  int num_threads = 1;
  // Log per-iteration progress to stdout (Ceres's minimizer_progress_to_
  // stdout).
  bool verbose = false;
  // Robust loss on every measurement (default: none, least squares).
  CeresRobustLoss loss;
};

struct CeresBaselineSummary {
  // Ceres's own summary of the solve.
  ceres::Solver::Summary solver_summary;
  // F at the initial poses (and landmarks), on the scale of eq. (12) (= 2 *
  // Ceres cost).
  double initial_objective = 0;
  // F at the returned poses (and landmarks), on the scale of eq. (12).
  double final_objective = 0;
  // What Ceres minimized, 2 * its cost: sum_k rho(f_k) with a robust loss,
  // else F (equal to the objectives above).
  double initial_robust_objective = 0;
  double final_robust_objective = 0;
  // Number of trust-region iterations (successful + unsuccessful steps).
  int iterations = 0;
  // Wall time of ceres::Solve, in seconds.
  double time_s = 0;
  // One line: method, objectives, iterations, time, termination.
  std::string BriefReport() const;
};

// Parameter storage of a pose graph in the form Ceres optimizes (see the top
// of this file): translations (d per pose), rotations (1 angle per pose in
// 2D; 4 quaternion coefficients x, y, z, w per pose in 3D) and landmark
// positions (d per landmark), contiguous.
struct CeresPoseBlocks {
  int dimension = 0;
  std::vector<double> translations;
  std::vector<double> rotations;
  std::vector<double> landmarks;

  int num_poses() const {
    return dimension > 0 ? static_cast<int>(translations.size()) / dimension
                         : 0;
  }
  int num_landmarks() const {
    return dimension > 0 ? static_cast<int>(landmarks.size()) / dimension : 0;
  }
  double* translation(int i) { return translations.data() + dimension * i; }
  double* rotation(int i) {
    return rotations.data() + (dimension == 2 ? 1 : 4) * i;
  }
  double* landmark(int l) { return landmarks.data() + dimension * l; }

  // Converts poses (rotations projected onto SO(d) through the angle /
  // normalized quaternion) into blocks, with no landmarks. Returns false if
  // dimension is not 2 or 3 or a pose has the wrong size or non-finite
  // entries.
  bool FromPoses(int dimension, const Poses& poses, std::string* error);
  // The same for poses and landmark positions.
  bool FromSolution(int dimension, const Solution& solution,
                    std::string* error);
  // Converts the blocks back into poses (quaternions normalized) and
  // landmark positions.
  Poses ToPoses() const;
  LandmarkPositions ToLandmarks() const;
};

// Adds the residual blocks of `graph` (measurements, landmark measurements,
// priors; see the top of this file) over the parameter blocks in `blocks`
// (which must outlive `problem` and have graph.num_poses poses and
// graph.num_landmarks landmarks), sets the quaternion manifolds (3D) and
// holds the gauge constant (see "Gauge" above). `problem` should be empty and
// use the default ownership options. `loss` (default: none) puts a robust
// loss on every pose-pose measurement (and on the landmark and prior terms
// with their thresholds). Returns false (problem untouched) if the graph
// fails ValidatePoseGraph (landmarks and priors allowed), the sizes disagree,
// a loss has no positive finite threshold or a landmark or prior threshold
// is negative or not finite.
bool BuildCeresProblem(const PoseGraph& graph, CeresPoseBlocks* blocks,
                       ceres::Problem* problem, std::string* error,
                       const CeresRobustLoss& loss = {});

// Minimizes F with Ceres from `initial` (one pose per pose and one position
// per landmark of `graph`). The gauge (see above) stays at its initial
// value. Linear solver: SPARSE_NORMAL_CHOLESKY with SuiteSparse. On success
// fills `result` and `summary` (if not null) and returns true, also when
// Ceres stopped at the iteration or time limit (see
// summary->solver_summary.termination_type). Returns false with a message
// for invalid input or if Ceres reports a failure.
bool SolveWithCeres(const PoseGraph& graph, const Solution& initial,
                    const CeresBaselineOptions& options, Solution* result,
                    CeresBaselineSummary* summary, std::string* error);
// The same for graphs without landmarks (priors are fine): poses only.
// Returns false with a message for a graph with landmarks.
bool SolveWithCeres(const PoseGraph& graph, const Poses& initial,
                    const CeresBaselineOptions& options, Poses* result,
                    CeresBaselineSummary* summary, std::string* error);

// Odometry initialization: places the root pose and composes the
// measurements along a breadth-first spanning tree of the pose-pose
// measurement graph (neighbours visited in measurement order): x_j = x_i *
// x~_ij over an edge (i, j) traversed forward, x_i = x_j * x~_ij^-1 backward.
// The root is graph.fixed_pose if >= 0, else (with priors) the first pose
// with a full pose prior, or pose 0; it is placed at graph.initial_poses[root]
// when initial poses are present, else at the identity with the rotation and
// position of its priors (the first of each kind), i.e. in the priors' world
// frame. With priors, the components not reached from the root are grown the
// same way from their poses with priors (in prior order). Poses unreachable
// otherwise (e.g. linked to the rest only through landmarks; all poses if the
// graph has an invalid dimension) are left at the identity.
Poses OdometryInitialization(const PoseGraph& graph);

// Initial landmark positions for `poses`: each landmark at t_i + R_i z of
// its first measurement (in measurement order). Landmarks without a usable
// measurement are left at the origin. With OdometryInitialization this is
// the "from odometry" start of the baselines:
//   Solution start{poses, InitialLandmarkPositions(graph, poses)}.
LandmarkPositions InitialLandmarkPositions(const PoseGraph& graph,
                                           const Poses& poses);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CERES_BASELINE_H_
