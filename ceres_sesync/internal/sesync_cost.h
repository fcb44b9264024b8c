// The Burer-Monteiro cost F(Y) = tr(Q Y^T Y) on St(d, r)^n (Rosen et al. 2019,
// Problem 9) with its Riemannian gradient (43), Hessian (44) and
// preconditioners, as a RiemannianCostFunction.

#ifndef CERES_SESYNC_INTERNAL_SESYNC_COST_H_
#define CERES_SESYNC_INTERNAL_SESYNC_COST_H_

#include <memory>

#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/riemannian_trust_region.h"

namespace ceres_sesync::internal {

enum class PreconditionerType {
  kNone,
  kBlockJacobi,     // Inverse diagonal blocks of D + eps I.
  kSparseCholesky,  // (D + eps I)^{-1} by sparse Cholesky.
  kRegularizedQ,    // (Q + eps I)^{-1} by sparse Cholesky of K_eps.
};

// Approximate inverse of the Euclidean Hessian 2Q: either from
// D = L(G^rho) + Sigma~ (the sparse part of Q) or exactly from Q through the
// sparse translation-augmented matrix K_eps of certificate_matrix.h (its Schur
// complement is Q + eps I). eps = lambda_max(D) / max_condition, where
// lambda_max(D) >= lambda_max(Q) is bounded by Gershgorin.
class SESyncPreconditioner {
 public:
  // kRegularizedQ factorizes K_eps in `workspace` when given (sharing its
  // symbolic analysis with the caller's certificate tests; the factor is
  // copied, so the workspace may be refactorized afterwards).
  SESyncPreconditioner(const SESyncProblem& problem, PreconditionerType type,
                       double max_condition,
                       CertificateMatrix* workspace = nullptr);
  ~SESyncPreconditioner();
  // After problem.UpdateWeights() (and workspace->Refresh()): recomputes eps
  // and refactorizes numerically, reusing the symbolic analysis (of the
  // workspace for kRegularizedQ, of its own factor for kSparseCholesky).
  void Update(const SESyncProblem& problem,
              CertificateMatrix* workspace = nullptr);
  // X = V (D + eps I)^{-1} (or the block-Jacobi version); V is r x dn.
  void Apply(const Eigen::MatrixXd& V, Eigen::MatrixXd* X) const;
  PreconditionerType type() const { return type_; }

 private:
  int d_;
  int num_threads_;
  PreconditionerType type_;
  double max_condition_;
  // The analyses kept for Update(): kSparseCholesky's factor of D + eps I,
  // kRegularizedQ's own K_eps when no workspace is given.
  std::unique_ptr<CholmodFactor> d_factor_;
  std::unique_ptr<CertificateMatrix> own_workspace_;
  Eigen::MatrixXd block_inverses_;  // d x dn, for block-Jacobi.
  // D + eps I (kSparseCholesky) or K_eps (kRegularizedQ, whose first
  // translation_size_ unknowns are the translations).
  SparseCholeskyFactor factor_;
  int translation_size_ = 0;
};

class SESyncCost : public RiemannianCostFunction {
 public:
  // Both must outlive this object.
  SESyncCost(const SESyncProblem* problem,
             const SESyncPreconditioner* preconditioner);

  double Evaluate(const Eigen::MatrixXd& Y) override;
  void Gradient(Eigen::MatrixXd* gradient) override;
  void HessianVector(const Eigen::MatrixXd& V, Eigen::MatrixXd* hv) override;
  void Precondition(const Eigen::MatrixXd& V, Eigen::MatrixXd* pv) override;
  void Retract(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& V,
               Eigen::MatrixXd* result) override;
  void ProjectToTangent(const Eigen::MatrixXd& V,
                        Eigen::MatrixXd* result) override;

  // Lagrange multipliers Lambda = SymBlockDiag_d(Q Y^T Y) (d x dn) at the
  // current point.
  const Eigen::MatrixXd& Lambda() const { return lambda_; }
  int hessian_vector_products() const { return hessian_vector_products_; }

 private:
  const SESyncProblem* problem_;
  const SESyncPreconditioner* preconditioner_;
  int d_;
  Eigen::MatrixXd Y_, YQ_, lambda_;
  Eigen::MatrixXd vq_, v_lambda_;  // Workspace of HessianVector/Precondition.
  int hessian_vector_products_ = 0;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SESYNC_COST_H_
