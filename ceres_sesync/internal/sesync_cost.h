// The Burer-Monteiro cost F(Y) = tr(Q Y^T Y) on St(d, r)^n (Rosen et al. 2019,
// Problem 9) with its Riemannian gradient (43), Hessian (44) and
// preconditioners, as a RiemannianCostFunction.

#ifndef CERES_SESYNC_INTERNAL_SESYNC_COST_H_
#define CERES_SESYNC_INTERNAL_SESYNC_COST_H_

#include <limits>
#include <memory>

#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/tangent_newton.h"
#include "ceres_sesync/riemannian_trust_region.h"

namespace ceres_sesync::internal {

enum class PreconditionerType {
  kNone,
  kBlockJacobi,     // Inverse diagonal blocks of D + eps I.
  kSparseCholesky,  // (D + eps I)^{-1} by sparse Cholesky.
  kRegularizedQ,    // (Q + eps I)^{-1} by sparse Cholesky of K_eps.
  // Block-Jacobi while truncated CG converges in few iterations with it,
  // then kRegularizedQ for the rest of the solve (see Update()).
  kAdaptive,
};

// How the factor of kRegularizedQ / kAdaptive is stored (the factorization
// itself is in double either way). Single halves the memory and the memory
// traffic of every application; the operator is then (L~ L~^T)^{-1} for the
// rounded factor L~: still symmetric positive definite, so truncated CG and
// the trust region keep their guarantees, and within a small relative
// perturbation of the double one (sparse_cholesky_factor.h).
enum class FactorPrecision { kDouble, kSingle };

struct PreconditionerSettings {
  FactorPrecision precision = FactorPrecision::kDouble;
  // kAdaptive switches to the exact preconditioner once a truncated-CG solve
  // under block-Jacobi needs more than this many iterations (0: never for
  // this reason), ...
  int switch_iterations = 20;
  // ... once the truncated-CG solves under block-Jacobi have taken more
  // than this many iterations in all (0: no such limit), ...
  int switch_total_iterations = 0;
  // ... and, if this is set, when the stopping test is met under
  // block-Jacobi, so that the test that ends a solve is always the exact
  // preconditioner's, as with kRegularizedQ.
  bool switch_at_convergence = true;
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
  // copied, so the workspace may be refactorized afterwards). kAdaptive
  // factorizes only when it switches, in `workspace` (then it must outlive
  // this object and must not be in use at that moment: the switch happens
  // inside optimization) or in a workspace of its own.
  SESyncPreconditioner(const SESyncProblem& problem, PreconditionerType type,
                       double max_condition,
                       CertificateMatrix* workspace = nullptr,
                       const PreconditionerSettings& settings = {});
  ~SESyncPreconditioner();
  // After problem.UpdateWeights() (and the workspace's Refresh()):
  // recomputes eps and refactorizes numerically, reusing the symbolic
  // analysis (of the workspace for the exact preconditioner, of its own
  // factor for kSparseCholesky). kAdaptive keeps its current mode.
  void Refresh();
  // X = V (D + eps I)^{-1} (or the block-Jacobi version); V is r x dn.
  void Apply(const Eigen::MatrixXd& V, Eigen::MatrixXd* X) const;
  PreconditionerType type() const { return type_; }

  // For kAdaptive (a no-op returning false otherwise): after a truncated-CG
  // solve that took `inner_iterations` (converged = false), or when the
  // stopping test was met (converged = true). Switches from block-Jacobi to
  // the exact (Q + eps I)^{-1} by the rules of PreconditionerSettings and
  // returns true iff it switched (Apply() is then the exact operator from
  // now on).
  bool Update(int inner_iterations, bool converged);
  // For kAdaptive (a no-op returning false otherwise): switches to the exact
  // preconditioner now unless it already has; true iff it switched.
  bool SwitchToExact();
  // Whether Apply() is (Q + eps I)^{-1} now, how often it switched, and the
  // truncated-CG iterations taken under block-Jacobi before that.
  bool exact() const { return exact_; }
  int switches() const { return switches_; }
  int block_jacobi_iterations() const { return block_jacobi_iterations_; }
  // The exact preconditioner's factor (empty before it is computed).
  const SparseCholeskyFactor& factor() const { return factor_; }

 private:
  // Factorizes K_eps and keeps its copy (kRegularizedQ, kAdaptive).
  void FactorizeRegularizedQ();

  const SESyncProblem& problem_;
  int d_;
  int num_threads_;
  PreconditionerType type_;
  PreconditionerSettings settings_;
  double max_condition_;
  double eps_ = 0;
  CertificateMatrix* workspace_ = nullptr;
  std::unique_ptr<CertificateMatrix> own_workspace_;
  // kSparseCholesky's factorization of D + eps I (its analysis is kept for
  // Refresh()).
  std::unique_ptr<CholmodFactor> d_factor_;
  bool exact_ = false;
  int switches_ = 0;
  int block_jacobi_iterations_ = 0;
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
             SESyncPreconditioner* preconditioner);

  double Evaluate(const Eigen::MatrixXd& Y) override;
  void Gradient(Eigen::MatrixXd* gradient) override;
  void HessianVector(const Eigen::MatrixXd& V, Eigen::MatrixXd* hv) override;
  void Precondition(const Eigen::MatrixXd& V, Eigen::MatrixXd* pv) override;
  void Retract(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& V,
               Eigen::MatrixXd* result) override;
  void ProjectToTangent(const Eigen::MatrixXd& V,
                        Eigen::MatrixXd* result) override;
  // SESyncPreconditioner::Update (kAdaptive), and the switch to the Newton
  // preconditioner (EnableNewton).
  bool UpdatePreconditioner(int inner_iterations, bool converged) override;
  // At rank d (Y_i in O(d)): use the exact inverse of the Riemannian
  // Hessian in tangent coordinates (TangentNewton) from the start of every
  // solve if `from_start`, else switch to it when one of the first
  // kNewtonSwitchSolves truncated-CG solves of a solve takes more than
  // `switch_products` products (< 0: never). With `exact_fallback`, a point
  // where it cannot be used makes the SESyncPreconditioner exact first
  // (SwitchToExact(): a kAdaptive one chosen lazily in its place).
  void EnableNewton(int switch_products, bool from_start = false,
                    bool exact_fallback = false);
  // The Newton system built ahead (on this problem) for the use from the
  // start; ignored unless that is enabled and none was built yet.
  void ProvideNewton(std::unique_ptr<TangentNewton> newton);
  // Before each MinimizeRiemannianTrustRegion() with this cost: the switch
  // above may happen in it (if allowed); the preconditioner starts as the
  // SESyncPreconditioner unless Newton is used from the start.
  void BeginSolve(bool allow_newton);
  // Drops the Newton preconditioner (after the problem's weights changed;
  // it is rebuilt when next used).
  void ResetNewton();
  bool newton_active() const { return newton_active_; }
  // Factorizations of the Newton system since it was built (ResetNewton()
  // drops it).
  int newton_factorizations() const {
    return newton_ ? newton_->factorizations() : 0;
  }
  // F(Y') - F(Y) = <Y' - Y, (Y' + Y) Q> (Q symmetric) for the last two
  // evaluated points of the same shape, from their cached products with Q;
  // round-off 4 eps sum |Y' - Y| |(Y' + Y) Q| (elementwise; the products'
  // own round-off is of the same order).
  bool EvaluationDifference(double* difference, double* round_off) override;

  // Lagrange multipliers Lambda = SymBlockDiag_d(Q Y^T Y) (d x dn) at the
  // current point.
  const Eigen::MatrixXd& Lambda() const { return lambda_; }
  int hessian_vector_products() const { return hessian_vector_products_; }
  // Precondition() calls that applied the SESyncPreconditioner (not Newton).
  int preconditioner_applications() const {
    return preconditioner_applications_;
  }

 private:
  // Sets newton_ (`built`, else a new TangentNewton: its symbolic
  // analysis) and its shift, unless it is set.
  void BuildNewton(std::unique_ptr<TangentNewton> built = nullptr);

  const SESyncProblem* problem_;
  SESyncPreconditioner* preconditioner_;
  int d_;
  Eigen::MatrixXd Y_, YQ_, lambda_;
  // The point evaluated before the current one, and its product with Q.
  Eigen::MatrixXd previous_Y_, previous_YQ_;
  Eigen::MatrixXd vq_, v_lambda_;  // Workspace of HessianVector/Precondition.
  int hessian_vector_products_ = 0;
  int preconditioner_applications_ = 0;
  // The Newton preconditioner of rank-d levels (tangent_newton.h): allowed
  // when newton_switch_products_ >= 0, active from the start of a solve
  // (newton_from_start_) or once a truncated-CG solve at rank d took more
  // products than that; built then (its symbolic analysis). At a new point
  // it is refactorized only if the last truncated-CG solve took more than
  // kNewtonStaleProducts products, else its factor is kept and only its
  // tangent basis moves (TangentNewton::Rebase). A point where it is not
  // positive definite uses the preconditioner_ instead.
  int newton_switch_products_ = -1;
  bool newton_from_start_ = false, newton_exact_fallback_ = false;
  bool newton_allowed_ = false, newton_active_ = false;
  int solves_ = 0;  // Truncated-CG solves since BeginSolve().
  // Failed factorizations since BeginSolve() (used from the start), and the
  // truncated-CG solves left before the next try (Precondition()).
  int newton_failures_ = 0, newton_skip_solves_ = 0;
  // Products of the last truncated-CG solve (of this or an earlier solve).
  int last_solve_products_ = std::numeric_limits<int>::max();
  double newton_eps_ = 0;
  std::unique_ptr<TangentNewton> newton_;
  Eigen::MatrixXd newton_failed_;  // Where the factorization failed last.
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SESYNC_COST_H_
