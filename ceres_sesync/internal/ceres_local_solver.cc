#include "ceres_sesync/internal/ceres_local_solver.h"

#include "ceres/gradient_problem.h"
#include "ceres/gradient_problem_solver.h"
#include "ceres_sesync/stiefel_manifold.h"

namespace ceres_sesync::internal {
namespace {

// F(Y) and its Euclidean gradient 2 Y Q; Ceres maps the gradient to the
// tangent space through the manifold's RightMultiplyByPlusJacobian.
class BurerMonteiroCost : public ceres::FirstOrderFunction {
 public:
  BurerMonteiroCost(const SESyncProblem* problem, int r)
      : problem_(problem), r_(r) {}
  bool Evaluate(const double* parameters, double* cost,
                double* gradient) const override {
    const int columns = problem_->dimension() * problem_->num_rotations();
    const Eigen::Map<const Eigen::MatrixXd> Y(parameters, r_, columns);
    Eigen::MatrixXd YQ;
    problem_->MultiplyQ(Y, &YQ);
    *cost = Y.cwiseProduct(YQ).sum();
    if (gradient) Eigen::Map<Eigen::MatrixXd>(gradient, r_, columns) = 2 * YQ;
    return true;
  }
  int NumParameters() const override {
    return r_ * problem_->dimension() * problem_->num_rotations();
  }

 private:
  const SESyncProblem* problem_;
  int r_;
};

}  // namespace

void MinimizeWithCeresLbfgs(const SESyncProblem& problem, int max_iterations,
                            double gradient_tolerance,
                            double function_tolerance, double max_time_s,
                            Eigen::MatrixXd* Y,
                            CeresLocalSolverSummary* summary) {
  const int r = static_cast<int>(Y->rows());
  ceres::GradientProblem gradient_problem(
      new BurerMonteiroCost(&problem, r),
      new StiefelProductManifold(problem.dimension(), r,
                                 problem.num_rotations()));
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  options.max_num_iterations = max_iterations;
  options.gradient_tolerance = gradient_tolerance;
  options.function_tolerance = function_tolerance;
  options.parameter_tolerance = 0;
  if (max_time_s > 0) options.max_solver_time_in_seconds = max_time_s;
  ceres::GradientProblemSolver::Summary ceres_summary;
  ceres::Solve(options, gradient_problem, Y->data(), &ceres_summary);
  summary->iterations = static_cast<int>(ceres_summary.iterations.size());
  summary->cost_evaluations = ceres_summary.num_cost_evaluations;
  summary->final_cost = ceres_summary.final_cost;
  summary->termination = "ceres LBFGS: " + ceres_summary.message;
}

}  // namespace ceres_sesync::internal
