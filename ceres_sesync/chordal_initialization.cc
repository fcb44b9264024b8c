#include "ceres_sesync/chordal_initialization.h"

#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync {

namespace internal {

bool ChordalRotationsFromLaplacian(const SparseMatrix& L, int d,
                                   Eigen::MatrixXd* R) {
  const int dn = static_cast<int>(L.rows());
  R->setIdentity(d, dn);
  R->leftCols(d).setIdentity();
  if (dn == d) return true;
  // With R = [I, X]: minimize tr(X L11 X^T) + 2 tr(L01 X^T), i.e. solve
  // L11 X^T = -L10 (L11 is positive definite for a connected graph).
  const SparseMatrix L11 = L.bottomRightCorner(dn - d, dn - d);
  const Eigen::MatrixXd L10 = L.bottomLeftCorner(dn - d, d);
  CholmodFactor factor;
  ConfigureCholmod(CholmodLayout::kSimplicial, &factor);
  factor.compute(L11);
  if (factor.info() != Eigen::Success) return false;
  const Eigen::MatrixXd Xt = factor.solve(-L10);
  R->rightCols(dn - d) = ProjectBlocksToRotations(Xt.transpose(), d);
  return true;
}

}  // namespace internal

bool ChordalRotations(const PoseGraph& graph, Eigen::MatrixXd* R,
                      std::string* error) {
  if (!ValidatePoseGraph(graph, error)) return false;
  const internal::SESyncProblem problem(graph);
  if (!internal::ChordalRotationsFromLaplacian(problem.RotationLaplacian(),
                                               graph.dimension, R)) {
    if (error) *error = "chordal initialization: sparse Cholesky failed";
    return false;
  }
  return true;
}

bool ChordalInitialization(const PoseGraph& graph, Poses* poses,
                           std::string* error) {
  if (!ValidatePoseGraph(graph, error)) return false;
  const internal::SESyncProblem problem(graph);
  Eigen::MatrixXd R;
  if (!problem.ok() || !internal::ChordalRotationsFromLaplacian(
                           problem.RotationLaplacian(), graph.dimension, &R)) {
    if (error) *error = "chordal initialization: sparse Cholesky failed";
    return false;
  }
  const Eigen::MatrixXd T = problem.RecoverTranslations(R);
  const int d = graph.dimension;
  poses->resize(graph.num_poses);
  for (int i = 0; i < graph.num_poses; ++i) {
    (*poses)[i] = Pose{R.middleCols(d * i, d), T.col(i)};
  }
  return true;
}

}  // namespace ceres_sesync
