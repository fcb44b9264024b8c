// Using the Stiefel manifold St(d, r) = {Y in R^(r x d) : Y^T Y = I} as a
// parameter-block manifold in Ceres.
//
//  (a) ceres::Problem: orthogonal Procrustes. Find Y in St(2, 3) (a 3 x 2
//      matrix with orthonormal columns) minimizing sum_k ||Y a_k - b_k||^2.
//      Closed form: Y* = polar factor of M = sum_k b_k a_k^T.
//  (b) ceres::GradientProblem: chordal rotation averaging of n rotations at
//      once on St(3, 3)^n = O(3)^n. Minimize
//      f(Y) = sum_i sum_k ||Y_i - R_ik||_F^2 over the blocks Y_i.
//      Closed form: Y_i* = polar factor of sum_k R_ik.
//
// The parameter block is always an r x d (or r x dn) column-major matrix,
// i.e. Y(j, l) is stored at y[j + r * l]. The program exits with status 1 if
// a solution disagrees with its closed form.

#include <cstdio>
#include <random>

#include "Eigen/Dense"
#include "ceres/ceres.h"
#include "ceres_sesync/stiefel_manifold.h"

namespace {

using Eigen::MatrixXd;

// Residual Y a - b for one correspondence (a in R^2, b in R^3).
struct ProcrustesResidual {
  ProcrustesResidual(const Eigen::Vector2d& a, const Eigen::Vector3d& b)
      : a(a), b(b) {}
  template <typename T>
  bool operator()(const T* y, T* residual) const {
    for (int j = 0; j < 3; ++j) {
      residual[j] = y[j] * a(0) + y[j + 3] * a(1) - b(j);  // Column-major Y.
    }
    return true;
  }
  Eigen::Vector2d a;
  Eigen::Vector3d b;
};

// f(Y) = sum_i sum_k ||Y_i - R_ik||^2 on the 3 x 3n matrix Y; its gradient is
// 2 (K Y_i - sum_k R_ik) per block. (The GradientProblemSolver maps the
// Euclidean gradient to the tangent space through the manifold.)
class RotationAveraging : public ceres::FirstOrderFunction {
 public:
  // measurements[k] is the 3 x 3n matrix [R_1k, ..., R_nk].
  explicit RotationAveraging(const std::vector<MatrixXd>& measurements)
      : measurements_(measurements) {}
  int NumParameters() const override {
    return static_cast<int>(measurements_[0].size());
  }
  bool Evaluate(const double* parameters, double* cost,
                double* gradient) const override {
    const Eigen::Map<const MatrixXd> y(parameters, 3, measurements_[0].cols());
    *cost = 0.0;
    MatrixXd grad = MatrixXd::Zero(y.rows(), y.cols());
    for (const MatrixXd& r : measurements_) {
      *cost += (y - r).squaredNorm();
      grad += 2.0 * (y - r);
    }
    if (gradient != nullptr) {
      Eigen::Map<MatrixXd>(gradient, y.rows(), y.cols()) = grad;
    }
    return true;
  }

 private:
  std::vector<MatrixXd> measurements_;
};

MatrixXd Gaussian(int rows, int cols, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  MatrixXd m(rows, cols);
  for (Eigen::Index k = 0; k < m.size(); ++k) m.data()[k] = normal(*rng);
  return m;
}

}  // namespace

int main() {
  std::mt19937_64 rng(2024);
  bool ok = true;

  // ---- (a) Orthogonal Procrustes in a ceres::Problem, Y in St(2, 3). ----
  {
    const MatrixXd y_true =
        ceres_sesync::RandomStiefelProductPoint(2, 3, 1, &rng);
    ceres::Problem problem;
    // Initial guess: any point of St(2, 3); Ceres keeps it on the manifold.
    MatrixXd y = ceres_sesync::RandomStiefelProductPoint(2, 3, 1, &rng);
    MatrixXd m = MatrixXd::Zero(3, 2);
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector2d a = Gaussian(2, 1, &rng);
      const Eigen::Vector3d b = y_true * a + 0.05 * Gaussian(3, 1, &rng);
      m += b * a.transpose();
      problem.AddResidualBlock(
          new ceres::AutoDiffCostFunction<ProcrustesResidual, 3, 6>(
              new ProcrustesResidual(a, b)),
          nullptr, y.data());
    }
    // The Problem takes ownership of the manifold.
    problem.SetManifold(y.data(), new ceres_sesync::StiefelManifold(2, 3));

    ceres::Solver::Options options;
    // Stop on the gradient or when the cost stops changing at rounding level.
    options.function_tolerance = 0.0;
    options.parameter_tolerance = 0.0;
    options.gradient_tolerance = 1e-10;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);

    MatrixXd closed_form;
    ceres_sesync::ProjectToStiefelProduct(m, 2, &closed_form);  // polar(M)
    const double error = (y - closed_form).cwiseAbs().maxCoeff();
    const double orthonormality =
        ceres_sesync::StiefelProductOrthonormalityError(y, 2);
    std::printf(
        "(a) Procrustes on St(2,3) with ceres::Problem: %d iterations, "
        "cost %.6e\n    max |Y - polar(M)| = %.2e, max |Y^T Y - I| = %.2e\n",
        static_cast<int>(summary.iterations.size()), summary.final_cost, error,
        orthonormality);
    if (!summary.IsSolutionUsable() || !(error < 1e-8) ||
        !(orthonormality < 1e-14)) {
      std::printf("    FAILED\n");
      ok = false;
    }
  }

  // ---- (b) Rotation averaging as a ceres::GradientProblem on O(3)^n. ----
  {
    const int n = 4, measurements_per_rotation = 6;
    const MatrixXd truth =
        ceres_sesync::RandomStiefelProductPoint(3, 3, n, &rng);
    std::vector<MatrixXd> measurements;
    MatrixXd sum = MatrixXd::Zero(3, 3 * n);
    for (int k = 0; k < measurements_per_rotation; ++k) {
      MatrixXd noisy;  // Truth + noise, projected back to O(3) blockwise.
      ceres_sesync::ProjectToStiefelProduct(
          truth + 0.2 * Gaussian(3, 3 * n, &rng), 3, &noisy);
      measurements.push_back(noisy);
      sum += noisy;
    }
    // O(3) has two components and a retraction cannot jump between them, so
    // initialize with a measurement (same component as the answer).
    MatrixXd y = measurements[0];
    // The GradientProblem takes ownership of the function and the manifold.
    ceres::GradientProblem problem(
        new RotationAveraging(measurements),
        new ceres_sesync::StiefelProductManifold(/*d=*/3, /*r=*/3, n));
    ceres::GradientProblemSolver::Options options;
    options.line_search_direction_type = ceres::LBFGS;
    options.function_tolerance = 1e-16;
    options.parameter_tolerance = 1e-16;
    options.gradient_tolerance = 3e-8;
    options.max_num_iterations = 1000;
    ceres::GradientProblemSolver::Summary summary;
    ceres::Solve(options, problem, y.data(), &summary);

    MatrixXd closed_form;
    ceres_sesync::ProjectToStiefelProduct(sum, 3, &closed_form);
    const double error = (y - closed_form).cwiseAbs().maxCoeff();
    const double orthonormality =
        ceres_sesync::StiefelProductOrthonormalityError(y, 3);
    std::printf(
        "(b) Rotation averaging of %d rotations on St(3,3)^%d with "
        "ceres::GradientProblem (LBFGS): %d iterations, cost %.6e\n"
        "    max |Y - polar(sum_k R_k)| = %.2e, max |Y_i^T Y_i - I| = %.2e\n",
        n, n, static_cast<int>(summary.iterations.size()), summary.final_cost,
        error, orthonormality);
    // LBFGS stops on the gradient (3e-8, just above the level where the
    // line search can no longer resolve cost changes) and the Hessian is
    // well conditioned (~2K I), so the iterate is accurate to ~1e-9.
    if (!summary.IsSolutionUsable() || !(error < 1e-8) ||
        !(orthonormality < 1e-14)) {
      std::printf("    FAILED: %s\n", summary.message.c_str());
      ok = false;
    }
  }

  std::printf("%s\n", ok ? "OK" : "FAILED");
  return ok ? 0 : 1;
}
