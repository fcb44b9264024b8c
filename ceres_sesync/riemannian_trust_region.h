// A truncated-Newton Riemannian trust-region method (RTR; Absil, Baker and
// Gallivan 2007) with a Steihaug-Toint truncated conjugate-gradient inner
// solver and an optional preconditioner, for any smooth cost on a matrix
// manifold with the Frobenius metric. SE-Sync uses it on St(d, r)^n (Rosen et
// al. 2019, Algorithm 1), but nothing here is specific to SE-Sync.

#ifndef CERES_SESYNC_RIEMANNIAN_TRUST_REGION_H_
#define CERES_SESYNC_RIEMANNIAN_TRUST_REGION_H_

#include <functional>
#include <string>

#include "Eigen/Core"

namespace ceres_sesync {

// The cost and manifold geometry seen by the solver. Points and tangent
// vectors are matrices of the same shape; the metric is <A, B> = tr(A^T B).
class RiemannianCostFunction {
 public:
  virtual ~RiemannianCostFunction() = default;
  // Evaluates f(x) and makes x the current point: Gradient(),
  // HessianVector() and Precondition() refer to the last evaluated point.
  virtual double Evaluate(const Eigen::MatrixXd& x) = 0;
  // Riemannian gradient at the current point.
  virtual void Gradient(Eigen::MatrixXd* gradient) = 0;
  // Riemannian Hessian at the current point applied to the tangent vector v.
  virtual void HessianVector(const Eigen::MatrixXd& v, Eigen::MatrixXd* hv) = 0;
  // Applies a symmetric positive definite preconditioner (an approximation of
  // the inverse Hessian) to the tangent vector v; the result must be tangent.
  // The default is the identity.
  virtual void Precondition(const Eigen::MatrixXd& v, Eigen::MatrixXd* pv) {
    *pv = v;
  }
  // Optional: f(x') - f(x) for the point evaluated last (x') and the one
  // evaluated just before it (x), computed without subtracting the two
  // values, and a bound on its round-off. Near a minimum where f is a sum of
  // large terms that nearly cancel (a zero-residual fit), the round-off of
  // f itself (~eps times the terms) swamps the decrease of a step and stops
  // the solve short; a difference computed from x' - x does not. Returns
  // false (the default) to use the two values.
  virtual bool EvaluationDifference(double* difference, double* round_off) {
    (void)difference;
    (void)round_off;
    return false;
  }
  // Retraction: the point reached from x along the tangent vector v.
  virtual void Retract(const Eigen::MatrixXd& x, const Eigen::MatrixXd& v,
                       Eigen::MatrixXd* result) = 0;
  // Adaptive preconditioning: called after every truncated-CG solve with its
  // number of inner iterations (converged = false), and whenever a
  // convergence test is met (converged = true: the preconditioned gradient,
  // relative decrease or step test). Returns true iff Precondition()
  // applies a different preconditioner from now on; the solver then goes on
  // in the new one instead of stopping, so that a solve always stops on its
  // final preconditioner's tests, and restarts the trust radius in its norm
  // (as at the start). The default keeps the preconditioner.
  virtual bool UpdatePreconditioner(int inner_iterations, bool converged) {
    (void)inner_iterations;
    (void)converged;
    return false;
  }
  // Orthogonal projection of v onto the tangent space at the current point
  // (used to suppress round-off drift in the inner solver). Must allow
  // result == &v (the inner solver projects in place).
  virtual void ProjectToTangent(const Eigen::MatrixXd& v,
                                Eigen::MatrixXd* result) = 0;
};

struct RiemannianTrustRegionOptions {
  // Maximum number of outer (trust-region) iterations; the paper's value.
  int max_iterations = 1000;
  // Maximum number of Hessian-vector products per truncated-CG solve.
  int max_inner_iterations = 10000;
  // Stop when ||grad f|| <= gradient_tolerance.
  double gradient_tolerance = 1e-6;
  // Stop when sqrt(<grad f, P grad f>) <= preconditioned_gradient_tolerance
  // (P the preconditioner, in its final form if it adapts: see
  // RiemannianCostFunction::UpdatePreconditioner).
  double preconditioned_gradient_tolerance = 1e-6;
  // Stop when an accepted step decreases f by less than this fraction of |f|.
  double relative_decrease_tolerance = 1e-12;
  // Stop when a step has norm below this, or when rejections have shrunk the
  // trust radius below 1e-12 times its initial value. Steps are accepted only
  // if they decrease f by more than 4 machine epsilons of |f| (round-off).
  double step_tolerance = 1e-10;
  // Initial trust radius (in the preconditioner's norm); <= 0 means "from the
  // first Cauchy step".
  double initial_trust_radius = -1;
  // Truncated-CG stopping: ||r|| <= ||r0|| min((||r0|| / ||g_0||)^theta,
  // kappa), with g_0 the gradient at the start (scale-free). theta = 0.5
  // (superlinear, as in Rosen et al.'s reference implementation) needed 30%
  // fewer Hessian-vector products than theta = 1 on the benchmark datasets
  // (ais2klinik: 463 vs 1272).
  double tcg_kappa = 0.1;
  double tcg_theta = 0.5;
  // Truncated CG also stops once its residual's preconditioned norm
  // sqrt(<r, P r>) is at most this fraction of preconditioned_gradient_
  // tolerance: the model's gradient at the step then passes the final test
  // with room for the model's error, and further products would only solve
  // the last Newton system more accurately than the tolerance asks (on the
  // shared datasets: intel 27 -> 23 products, manhattan 11 -> 9, smallGrid3D
  // 35 -> 28, the others the same; the same poses and bounds). 0: off.
  double tcg_tolerance_fraction = 0.1;
  // Wall-clock limit in seconds (<= 0: none).
  double max_time_s = 0;
  // Called after every accepted step (outer iteration); return false to
  // stop. `hessian_vector_products`: those since the previous call, i.e. of
  // this step's truncated-CG solve and of the solves of any steps rejected
  // on the way to it.
  std::function<bool(int iteration, double f, double gradient_norm,
                     double trust_radius, int hessian_vector_products)>
      callback;
};

struct RiemannianTrustRegionSummary {
  enum class Termination {
    kGradientTolerance,
    kPreconditionedGradientTolerance,
    kRelativeDecrease,
    kStepTolerance,
    kMaxIterations,
    kMaxTime,
    kUserCallback,
    kNonFinite,
  };
  Termination termination = Termination::kMaxIterations;
  int iterations = 0;
  int hessian_vector_products = 0;
  double initial_cost = 0;
  double final_cost = 0;
  double final_gradient_norm = 0;
  double final_preconditioned_gradient_norm = 0;
  double time_s = 0;
  std::string TerminationString() const;
};

// Minimizes the cost from `x` (overwritten with the result).
void MinimizeRiemannianTrustRegion(const RiemannianTrustRegionOptions& options,
                                   RiemannianCostFunction* cost,
                                   Eigen::MatrixXd* x,
                                   RiemannianTrustRegionSummary* summary);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_RIEMANNIAN_TRUST_REGION_H_
