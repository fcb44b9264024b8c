// The Riemannian Newton preconditioner of a level whose blocks are square
// (r = d: Y_i in O(d), the staircase's first level optimized on its d
// nonzero rows). There every tangent vector is V_i = Y_i Omega_i with Omega_i
// skew, so the Riemannian Hessian of F (eq. 44) is a matrix in the
// coordinates of the Omega_i: with translations kept as unknowns (the
// Schur complement over them is the Hessian of F itself), H = 2 E^T (I_d (x)
// K_0) E, where K_0 = [Lbar -Vbar; -Vbar^T D - Lambda] is the certificate
// matrix at shift 0 and E maps the coordinates (per vertex: d translation
// unknowns, d(d-1)/2 rotation unknowns) to the tangent vector's rows. H is
// sparse with the vertex graph's pattern in blocks of d + d(d-1)/2 (3 in 2D,
// 6 in 3D), like a Gauss-Newton system of SE(d)^n, but it is the exact
// Hessian: as a preconditioner of truncated CG it is the exact inverse, so
// each trust-region subproblem takes one or two products where (Q + eps I)^-1
// (which does not commute with the tangent projection) can take a hundred.
// H is positive definite near a nondegenerate local minimum, up to the
// global rotation (the gauge), which the shift eps on the rotation unknowns
// removes; elsewhere the factorization fails and the caller falls back.

#ifndef CERES_SESYNC_INTERNAL_TANGENT_NEWTON_H_
#define CERES_SESYNC_INTERNAL_TANGENT_NEWTON_H_

#include <memory>
#include <vector>

#include "Eigen/Core"
#include "ceres_sesync/internal/extended_cholesky.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"

namespace ceres_sesync::internal {

class TangentNewton {
 public:
  explicit TangentNewton(const SESyncProblem& problem);
  // Assembles H at Y (d x dn, blocks in O(d)) with the multipliers Lambda
  // (d x dn), adds eps to the rotation unknowns' diagonal, and factorizes.
  // Returns false if H + eps is not numerically positive definite.
  bool Factorize(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& Lambda,
                 double eps);
  // PV = H^{-1} applied to the tangent vector V at the factorized Y (the
  // rotation part of the solution of H z = [0; coordinates of V]).
  void Apply(const Eigen::MatrixXd& V, Eigen::MatrixXd* PV) const;
  // The point of the last successful Factorize().
  const Eigen::MatrixXd& point() const { return Y_; }
  // Keeps the factor of the last successful Factorize() and moves the
  // tangent basis that Apply() maps through to Y (blocks in O(d)): Apply()
  // is then E(Y) H_old^{-1} E(Y)^T, symmetric positive definite on Y's
  // tangent space, H_old's inverse carried to Y. point() becomes Y.
  void Rebase(const Eigen::MatrixXd& Y);
  int factorizations() const { return factorizations_; }

 private:
  // rotated_: the tangent basis Y_i E_k at Y.
  void SetBasis(const Eigen::MatrixXd& Y);
  // Fills values_ with H + eps (the rotation unknowns' diagonal) at Y, in
  // the order of slot_; also sets rotated_.
  template <int D>
  void Assemble(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& Lambda,
                double eps);

  const SESyncProblem& problem_;
  int d_, p_, n_, t0_;
  int num_unknowns_ = 0, rotation_offset_ = 0;
  // Per vertex: its reduced translation node and rotation block (-1: none),
  // and its unknowns unknowns_[unknown_start_[v] ..].
  std::vector<int> translation_of_vertex_, rotation_of_vertex_;
  std::vector<int> unknown_start_, unknowns_;
  // The vertex pairs (v >= w) of the pattern, by w, and K_0's (1 + d) x
  // (1 + d) block of each without Lambda (column-major).
  std::vector<int> pair_first_, pair_second_;
  std::vector<double> base_;
  std::vector<int> ordering_;  // Unknowns in elimination order.
  std::vector<int> slot_;      // Where each computed entry goes.
  std::vector<double> values_;
  std::unique_ptr<DoubleDoubleCholesky> cholesky_;
  std::unique_ptr<SparseCholeskyFactor> solver_;
  Eigen::MatrixXd Y_;
  Eigen::MatrixXd rotated_;        // Y_i E_k (d x d each) at the last Y.
  std::vector<double> embedding_;  // Assemble()'s E_a of every vertex.
  int factorizations_ = 0;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_TANGENT_NEWTON_H_
