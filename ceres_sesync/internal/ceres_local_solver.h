// Ceres as the local solver of a staircase level: minimizes
// F(Y) = tr(Q Y^T Y) over St(d, r)^n with ceres::GradientProblemSolver (LBFGS)
// on StiefelProductManifold, instead of the built-in trust-region method.

#ifndef CERES_SESYNC_INTERNAL_CERES_LOCAL_SOLVER_H_
#define CERES_SESYNC_INTERNAL_CERES_LOCAL_SOLVER_H_

#include <string>

#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

struct CeresLocalSolverSummary {
  int iterations = 0;
  int cost_evaluations = 0;
  double final_cost = 0;
  std::string termination;
};

// Minimizes from Y (r x dn, overwritten). Stops on ceres's gradient tolerance
// (max-norm of the tangent step x - Plus(x, -g)), relative function decrease,
// max_iterations or max_time_s (<= 0: none).
void MinimizeWithCeresLbfgs(const SESyncProblem& problem, int max_iterations,
                            double gradient_tolerance,
                            double function_tolerance, double max_time_s,
                            Eigen::MatrixXd* Y,
                            CeresLocalSolverSummary* summary);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CERES_LOCAL_SOLVER_H_
