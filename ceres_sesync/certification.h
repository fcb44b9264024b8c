// Certifying any pose-graph solution after the fact.
//
//   ceres_sesync::Certificate certificate;
//   ceres_sesync::Certify(graph, poses_from_ceres, {}, &certificate);
//   if (certificate.certified) { ... globally optimal to within the bound ... }
//
// Method (Rosen et al. 2019, Section 5.3 and Theorem 7; see also
// ../shared/sesync-notes.md, "Bound for any feasible candidate"): the
// candidate's rotations R (projected to SO(d) if slightly off) define the
// multipliers Lambda = SymBlockDiag_d(Q R^T R) and the certificate matrix
// S = Q - Lambda, where Q is the rotation-only data matrix with the
// translations eliminated (eq. 24). For every shift eta with S + eta I
// positive semidefinite, Lambda - eta I is feasible for the dual of the SDP
// relaxation, so
//
//   p*_MLE >= p*_SDP >= tr(Lambda) - eta d n = F(R, t*(R)) - eta d n,
//
// a lower bound on the optimal value that holds whether or not the candidate
// is optimal. The shift is proven by a sparse Cholesky factorization of the
// translation-augmented matrix [Lbar -Vbar; -Vbar^T D - Lambda + eta I] (whose
// Schur complement is S + eta I), plus a bound on that factorization's
// floating-point backward error.
//
// Translations: the candidate's translations are used as given. The bound on
// F(candidate) - p*_MLE is F(candidate) - lower bound, where F(candidate)
// includes the translational terms at the given translations; translations
// that are not optimal for the rotations only make that bound larger (they are
// never re-optimized silently). Certify answers "certified" when that bound,
// relative to the lower bound, is at most `max_relative_suboptimality`.
//
// What is proven, round-off included: the candidate's F (with its rotations
// projected to SO(d)) minus a lower bound on the optimum of the problem
// defined by the graph's measurements as doubles. The shift eta is proven
// by a Cholesky factorization of K_eta with its translation block lowered
// (CertificateMatrix::Prove): the rounding of the data matrices, of the
// assembly and the factorization's backward error (Higham, Thm. 10.3, any
// summation order) are bounded row by row; the translation rows' bound is
// absorbed by the lowering and the rotation rows' bound is added to eta, so
// S + eta I >= 0 follows with no first-order step. The lower bound
// tr(Lambda) - eta d n is summed in double-double and rounded down. Double
// precision resolves the certificate to about 1e-16 of the data's scale,
// amplified on large maps by the squared extent of the map; when that is
// above the goal (CertifyOptions::goal_relative_suboptimality), the proof is
// redone in double-double arithmetic (internal/double_double.h: ~1e-31),
// which certifies long trajectories and large maps to ~1e-7 and better.
// Local minima from local search have lambda_min(S) many orders of magnitude
// below these allowances, so they are never certified.
//
// Landmarks and priors (pose_graph.h): the candidate is a Solution (poses and
// landmark positions, used as given, like translations). The landmarks are
// eliminated with the translations (internal/sesync_problem.h), so Q and
// Lambda stay matrices of rotation blocks; a graph with priors adds the
// world pose w as one more block at R_w = I (the candidate is expressed in
// the world frame), and the bound is that of the problem extended by w,
// which has the same optimum (its objective is invariant under a global
// rigid motion and equals F at w = (I, 0)). n below counts w.

#ifndef CERES_SESYNC_CERTIFICATION_H_
#define CERES_SESYNC_CERTIFICATION_H_

#include <string>

#include "Eigen/Core"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"

namespace ceres_sesync {

struct CertifyOptions {
  // The candidate is certified when (F(candidate) - lower bound) / lower bound
  // <= max_relative_suboptimality.
  double max_relative_suboptimality = 1e-3;
  // First shift tried, as a relative bound: eta d n = this * tr(Lambda).
  double target_relative_bound = 1e-9;
  // Candidate rotations further than this (Frobenius) from SO(d) are
  // projected with a warning; closer ones silently.
  double rotation_warning_tolerance = 1e-6;
  // If not certified: run the SE-Sync staircase from the candidate and return
  // its (certified, if possible) solution in Certificate::improved_poses.
  bool improve_if_not_certified = false;
  // Options for that improvement run.
  SolverOptions solver_options;
  // A proof whose relative bound is above this is tightened in
  // double-double arithmetic (proof_arithmetic kAutomatic); see
  // SolverOptions::certification_goal_relative_bound.
  double goal_relative_suboptimality = 1e-6;
  SolverOptions::ProofArithmetic proof_arithmetic =
      SolverOptions::ProofArithmetic::kAutomatic;
  // Threads for the products with Q, the solves and the double-double proof
  // (<= 0: all cores); see SolverOptions::num_threads.
  int num_threads = 0;
};

struct Certificate {
  // The candidate is globally optimal to within relative_suboptimality_bound
  // (<= CertifyOptions::max_relative_suboptimality).
  bool certified = false;
  // F(candidate), eq. (12), with the candidate's own translations.
  double objective = 0;
  // F(R, t*(R)) = tr(Lambda): the objective with optimal translations for
  // the candidate's rotations.
  double rotation_objective = 0;
  // Estimate of lambda_min(S) (NaN if the first Cholesky test succeeded and
  // no eigensolve was needed).
  double lambda_min = 0;
  // Shift for which S + eta I was proven positive semidefinite (all
  // round-off included); +inf if none.
  double eta = 0;
  // The arithmetic of the factorization that proved eta: "double",
  // "double-double" or "none".
  std::string proof_precision = "none";
  // Certificate factorizations in double and in double-double, and the
  // seconds the latter took (part of time_s).
  int factorizations = 0;
  int extended_factorizations = 0;
  double extended_proof_time_s = 0;
  // Proven lower bound on the optimal value: max(0, tr(Lambda) - eta d n)
  // (F is a sum of squares). A candidate with F <= 1e-12 times the sum of
  // all precisions (e.g. a tree, or noiseless data) is certified by F >= 0
  // alone.
  double lower_bound = 0;
  // (objective - lower_bound) and its ratio to lower_bound, with the
  // objective rounded up by a bound on its own evaluation's round-off
  // (internal/objective_bound.h; ~1e-12 relative).
  double suboptimality_bound = 0;
  double relative_suboptimality_bound = 0;
  // Largest Frobenius distance of a candidate rotation from SO(d).
  double max_rotation_error = 0;
  // When lambda_min(S) is clearly negative: a unit vector v in R^{dn}
  // (the d-blocks follow the graph's pose order, then R_w with priors) with
  // v^T S v =
  // negative_curvature < 0, a witness that the candidate is not optimal for
  // the relaxation.
  Eigen::VectorXd negative_curvature_direction;
  double negative_curvature = 0;
  // The improved solution (CertifyOptions::improve_if_not_certified): poses
  // and landmark positions.
  bool has_improved_poses = false;
  Poses improved_poses;
  LandmarkPositions improved_landmarks;
  SolverSummary improvement_summary;
  // Seconds spent (excluding the improvement run).
  double time_s = 0;

  std::string BriefReport() const;
  std::string FullReport() const;
};

// Certifies `candidate` (one pose per graph pose, one position per landmark)
// for `graph` (d = 2 or 3). Returns false with a message in `error` for
// invalid input (graph fails ValidatePoseGraph, wrong number of poses or
// landmarks, wrong dimensions, non-finite values); `certificate` is then not
// filled.
bool Certify(const PoseGraph& graph, const Solution& candidate,
             const CertifyOptions& options, Certificate* certificate,
             std::string* error);
// The same for a graph without landmarks (one with landmarks is an error:
// their positions are part of the candidate).
bool Certify(const PoseGraph& graph, const Poses& candidate,
             const CertifyOptions& options, Certificate* certificate,
             std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CERTIFICATION_H_
