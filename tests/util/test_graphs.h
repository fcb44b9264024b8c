// Shared helpers for tests that need small pose graphs: random connected
// graphs with known ground truth (noisy or exact measurements), conversions
// between Poses and the stacked matrices of the SE-Sync formulation, a
// gauge-invariant pose comparison, and the SE-Sync data matrices built DENSELY
// from first principles (for checking the sparse/implicit implementations on
// small problems).
//
// Everything here is independent of the library's internal matrices: it only
// uses the public data model (pose_graph.h) and the Langevin sampler.

#ifndef CERES_SESYNC_TESTS_UTIL_TEST_GRAPHS_H_
#define CERES_SESYNC_TESTS_UTIL_TEST_GRAPHS_H_

#include <cstdint>
#include <random>
#include <vector>

#include "Eigen/Core"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::test_util {

struct RandomGraphOptions {
  // Dimension d (2 or 3).
  int dimension = 3;
  // Number of poses n (>= 1).
  int num_poses = 20;
  // Edges added on top of a random spanning tree (pairs drawn uniformly among
  // distinct poses; parallel edges are possible).
  int num_loop_closures = 10;
  // Precisions of every measurement.
  double kappa = 100;
  double tau = 100;
  // If true, measurements are exact (F(ground truth) = 0).
  bool noiseless = false;
  // Ground-truth translations are uniform in [-scale, scale]^d.
  double translation_scale = 3;
  // If true, the spanning tree is the chain 0-1-2-...; otherwise each pose
  // k >= 1 attaches to a uniformly random earlier pose.
  bool chain = false;
  uint64_t seed = 0;
};

// A random connected pose graph with uniformly random ground-truth rotations
// and noise from the generative model (Rosen et al. 2019, eq. 10): R~ =
// R_i^T R_j Langevin(kappa), t~ = R_i^T (t_j - t_i) + N(0, I / tau). Edge
// orientation is random. `ground_truth` may be null.
PoseGraph RandomPoseGraph(const RandomGraphOptions& options,
                          Poses* ground_truth);

struct RandomLandmarkGraphOptions {
  // The pose graph (RandomPoseGraph with these options; its seed is used
  // for everything).
  RandomGraphOptions poses;
  // Number of landmarks, uniform in [-scale, scale]^d (scale:
  // poses.translation_scale), each observed by `observations_per_landmark`
  // poses drawn uniformly (with repetition) with precision nu.
  int num_landmarks = 8;
  int observations_per_landmark = 2;
  double nu = 50;
  // Priors on random poses: position-only (precision prior_tau), rotation-
  // only (prior_kappa) and full pose priors (both).
  int num_position_priors = 0;
  int num_rotation_priors = 0;
  int num_pose_priors = 0;
  double prior_kappa = 200;
  double prior_tau = 100;
};

// RandomPoseGraph plus landmarks and priors with noise from the same model
// (exact if options.poses.noiseless): z = R_i^T (p_l - t_i) + N(0, I / nu),
// g = t_i + N(0, I / prior_tau), R~ = R_i Langevin(prior_kappa). Landmark
// ids continue after the pose ids (n, n + 1, ...). `truth` may be null.
PoseGraph RandomLandmarkGraph(const RandomLandmarkGraphOptions& options,
                              Solution* truth);

// A Haar-uniform random rotation in SO(d).
Eigen::MatrixXd RandomRotation(int d, std::mt19937_64* rng);

// n random poses (uniform rotations, translations uniform in [-s, s]^d).
Poses RandomPoses(int d, int n, double translation_scale, std::mt19937_64* rng);

// Replaces every measurement's R~ and t~ by the exact relative pose of
// `truth` (kappa, tau kept).
void MakeMeasurementsExact(const Poses& truth, PoseGraph* graph);

// R = [R_1 ... R_n] (d x dn) and T = [t_1 ... t_n] (d x n).
Eigen::MatrixXd StackRotations(const Poses& poses);
Eigen::MatrixXd StackTranslations(const Poses& poses);
Poses PosesFromMatrices(const Eigen::MatrixXd& R, const Eigen::MatrixXd& T);

// Gauge-invariant distance between two sets of poses: the largest over i of
// ||A_0^T A_i - B_0^T B_i||_F (rotations) and of ||A_0^T (a_i - a_0) - B_0^T
// (b_i - b_0)|| (translations), i.e. the poses compared in the frame of pose
// 0. Returns the max of both.
double GaugeInvariantPoseDistance(const Poses& a, const Poses& b);

// The dense (n + dn) x (n + dn) data matrix M of the objective, built
// directly from the residuals: with X = [T R] (d x (n + dn)),
//   F(x) = sum kappa ||R_j - R_i R~||_F^2 + tau ||t_j - t_i - R_i t~||^2
//        = tr(X M X^T),
// M = sum kappa E E^T + tau e e^T, where X E = R_j - R_i R~ and X e = t_j - t_i
// - R_i t~. Columns 0..n-1 are translations, then rotation blocks.
Eigen::MatrixXd DenseDataMatrix(const PoseGraph& graph);

// The dense data matrix of the objective with landmarks and priors
// (pose_graph.h), from the residuals: with the world pose w = (I, 0)
// appended as a pose and
//   X = [t_1 .. t_n, p_1 .. p_L, t_w | R_1 .. R_n, R_w]
// (d x (n + L + 1 + d (n + 1))), F(x, p) = tr(X M X^T) at t_w = 0, R_w = I.
// Every term is ||X e||^2 or ||X E||_F^2 for a fixed e / E: an edge as in
// DenseDataMatrix, a landmark measurement X e = p_l - t_i - R_i z, a
// rotation prior X E = R_i - R_w R~, a position prior X e = t_i - t_w -
// R_w g. Columns: translations 0..n-1, landmarks n..n+L-1, t_w at n+L, then
// the rotation blocks (pose i at n+L+1+d i, R_w last).
Eigen::MatrixXd DenseLandmarkDataMatrix(const PoseGraph& graph);

// X = [T P t_w | R R_w] of DenseLandmarkDataMatrix for a solution.
Eigen::MatrixXd StackLandmarkSolution(const PoseGraph& graph,
                                      const Solution& solution);

// DenseLandmarkDataMatrix in the solver's index sets (documented in
// ceres_sesync/internal/sesync_problem.h, ProblemLayout): translation nodes
// [t_1 .. t_n, p_1 .. p_L, t_w if some prior has a position term], rotation
// blocks [R_1 .. R_n, R_w if the graph has priors], and the gauge node (t_w
// if present, else t_1) dropped. With M = [L -V; -V^T D] on those sets:
// Lbar, Vbar (the reduced translation rows; Vbar = -M_TR), D = M_RR, and
// Q = D - Vbar^T Lbar^-1 Vbar by a dense Cholesky solve. A second route to Q
// besides DenseLandmarkQ. Also: which columns of X (StackLandmarkSolution)
// the sets select.
struct DenseLandmarkProblem {
  Eigen::MatrixXd Lbar, Vbar, D, Q;
  std::vector<int> translation_columns;  // Columns of X, in node order.
  std::vector<int> rotation_columns;     // First column of each block.
  int gauge_column = 0;
};
DenseLandmarkProblem BuildDenseLandmarkProblem(const PoseGraph& graph);

// Q of a graph with landmarks and priors as the Schur complement of the
// translation block of DenseLandmarkDataMatrix through its pseudo-inverse,
// restricted to the rotation blocks of the solver (R_w only with priors).
Eigen::MatrixXd DenseLandmarkQ(const PoseGraph& graph);

// The rotations R (d x dn) of a solution in the solver's rotation blocks:
// the poses', then R_w = I if the graph has priors.
Eigen::MatrixXd StackSolverRotations(const PoseGraph& graph,
                                     const Poses& poses);

// Dense Q (dn x dn): the Schur complement of the translation block of M,
// Q = M_RR - M_RT pinv(M_TT) M_TR (pinv: the Laplacian M_TT of a connected
// graph has the 1-dimensional kernel span(1), orthogonal to M_TR's columns).
Eigen::MatrixXd DenseQ(const PoseGraph& graph);

// Dense Q by the paper's formula (Rosen et al. 2019, eq. 24):
//   Q = L(G^rho) + T^T Omega^{1/2} Pi Omega^{1/2} T,
// with Pi the orthogonal projector onto ker(A Omega^{1/2}) computed by SVD.
// Independent of DenseQ (used to cross-check the test reference itself).
Eigen::MatrixXd DenseQFromPaper(const PoseGraph& graph);

// Smallest eigenvalue and a unit eigenvector of a dense symmetric matrix.
double DenseMinEigenvalue(const Eigen::MatrixXd& S,
                          Eigen::VectorXd* eigenvector = nullptr);

// The dense block-diagonal matrix with the d x d blocks of Lambda (d x dn).
Eigen::MatrixXd BlockDiagonalToDense(const Eigen::MatrixXd& Lambda, int d);

}  // namespace ceres_sesync::test_util

#endif  // CERES_SESYNC_TESTS_UTIL_TEST_GRAPHS_H_
