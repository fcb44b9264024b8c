// The data matrices of the SE-Sync rotation-only problem (Rosen et al., IJRR
// 2019, Problem 4 / eq. 24) in the translation-eliminated form, built once from
// a validated PoseGraph in O(m) memory.
//
// With R = [R_1 ... R_n] (d x dn) and translations T = [t_1 ... t_n] (d x n),
// the objective (12) is tr([T R] M [T R]^T) with the sparse
//
//   M = [ L(W^tau)   -V ]     L(W^tau): translational weight Laplacian (n x n)
//       [ -V^T        D ],    D = L(G^rho) + Sigma~ (dn x dn), V (n x dn).
//
// Fixing t_0 = 0 (the objective is translation invariant) and eliminating the
// translations gives Q = D - Vbar^T Lbar^{-1} Vbar, where Lbar and Vbar drop
// the first row (and column) of L(W^tau) and V. Q itself is dense; products
// Y Q cost O(m r) through one sparse Cholesky factorization of Lbar (eq. 39).

#ifndef CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_
#define CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_

#include <memory>
#include <utility>
#include <vector>

#include "Eigen/CholmodSupport"
#include "Eigen/Core"
#include "Eigen/SparseCore"
#include "ceres_sesync/internal/measurement_weights.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::internal {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
// CHOLMOD's Cholesky factorization (through Eigen) plus an a posteriori bound
// on its floating-point backward error.
class CholmodFactor
    : public Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> {
 public:
  // After a successful LL^T factorization P A P^T = L L^T + E: bounds on the
  // floating-point backward error E such that
  //   A + diag(head_bound I, tail_bound I) is positive semidefinite,
  // with the head block the original indices < split and the tail the rest.
  // Uses the componentwise bound |E| <= gamma_{k+1} |L| |L^T| for Cholesky
  // (Demmel 1989; Higham, "Accuracy and Stability of Numerical Algorithms",
  // Thm. 10.3) with k the number of stored entries in the row of L; the
  // bound holds for every order of summation (Higham Lemma 8.4), so blocked
  // supernodal kernels need no widening; and
  // -E <= diag(rho) for rho_i = sum_j |E_ij| (symmetric E, Gershgorin-type:
  // 2 |x_i x_j| <= x_i^2 + x_j^2). O(nnz(L)), on the factor in place.
  void BackwardErrorBound(int split, double* head_bound, double* tail_bound);
  // The same bound row by row: rho[i] >= sum_j |E_ij| for every original
  // index i.
  void RowBackwardErrorBounds(std::vector<double>* rho);
  // After a successful factorization: a copy of the factor for fast solves
  // with r x N right-hand sides.
  SparseCholeskyFactor ExtractFactor();
  // analyzePattern() with a fill-reducing ordering chosen by the caller
  // (ordering[k] = original index of the k-th pivot) instead of CHOLMOD's
  // own (AMD, possibly METIS) on the full matrix.
  void AnalyzePatternWithOrdering(const SparseMatrix& lower,
                                  std::vector<int> ordering);
  // After analyzePattern(): CHOLMOD's fill-reducing ordering.
  std::vector<int> Ordering() const;
  // After analyzePattern(): whether CHOLMOD chose the supernodal layout
  // (dense fill, expensive factorizations).
  bool IsSupernodal() const;
};

// How CHOLMOD organizes the factor. Simplicial: fast for sparse factors and
// for repeated solves; supernodal: dense BLAS kernels, fast only for heavy
// fill; automatic: supernodal when flops / nnz(L) >= kSupernodalSwitch after
// the symbolic analysis. Measured on the certificate matrix of the benchmark
// datasets (CHOLMOD 3 with Debian's ATLAS, one thread), simplicial vs
// supernodal factorization: city10000 (flops / nnz(L) = 84) 38 vs 75 ms,
// cubicle (152) 85 vs 120 ms, sphere2500 (170) 38 vs 55 ms, torus3D (265)
// 146 vs 118 ms; CHOLMOD's own switch (40) would pick supernodal for the
// first three.
enum class CholmodLayout { kSimplicial, kSupernodal, kAutomatic };
constexpr double kSupernodalSwitch = 200;

// Sets a true LL^T factorization in every layout (which fails on matrices
// that are not positive definite, unlike LDL^T) and silences CHOLMOD's own
// printing (failures are reported through info()).
void ConfigureCholmod(CholmodLayout layout, CholmodFactor* factor);

// The data matrix M of the objective as a sum of terms, one
// visit(block, row, column, value) per term, with values computed in
// `Scalar` from the measurements (double, or DoubleDouble for the
// high-precision certificate) and the precisions of the weighted problem
// (measurement_weights.h; empty weights: the graph's own). Blocks and their
// indices:
//   kTranslation:   L(W^tau), poses (row, column);
//   kCoupling:      V, pose row, rotation column d*i + a;
//   kRotation:      L(G^rho), rotation indices;
//   kRotationSigma: Sigma~, rotation indices (D = L(G^rho) + Sigma~).
// The symmetric blocks get both (row, column) and (column, row) of every
// off-diagonal term. Within a block, entries are the sums of their terms in
// visiting order (so assembling from these terms reproduces SESyncProblem's
// matrices bitwise). The terms visited, and so the sparsity pattern, do not
// depend on the weights: a zero weight visits exact zeros.
enum class DataBlock { kTranslation, kCoupling, kRotation, kRotationSigma };

template <typename Scalar, typename Visit>
void ForEachDataTerm(const PoseGraph& graph, const MeasurementWeights& weights,
                     Visit&& visit) {
  const int d = graph.dimension;
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const int i = e.i, j = e.j;
    const Precisions p = WeightedPrecisions(e, weights, k);
    const Scalar kappa(p.kappa), tau(p.tau);
    for (int a = 0; a < d; ++a) {
      visit(DataBlock::kRotation, d * i + a, d * i + a, kappa);
      visit(DataBlock::kRotation, d * j + a, d * j + a, kappa);
      for (int b = 0; b < d; ++b) {
        const Scalar r = -kappa * Scalar(e.R(a, b));
        visit(DataBlock::kRotation, d * i + a, d * j + b, r);
        visit(DataBlock::kRotation, d * j + b, d * i + a, r);
        visit(DataBlock::kRotationSigma, d * i + a, d * i + b,
              tau * Scalar(e.t(a)) * Scalar(e.t(b)));
      }
      // V = A Omega B^T: +tau t~^T at (j, block i), -tau t~^T at (i, block i).
      const Scalar v = tau * Scalar(e.t(a));
      visit(DataBlock::kCoupling, j, d * i + a, v);
      visit(DataBlock::kCoupling, i, d * i + a, -v);
    }
    visit(DataBlock::kTranslation, i, i, tau);
    visit(DataBlock::kTranslation, j, j, tau);
    visit(DataBlock::kTranslation, i, j, -tau);
    visit(DataBlock::kTranslation, j, i, -tau);
  }
}

template <typename Scalar, typename Visit>
void ForEachDataTerm(const PoseGraph& graph, Visit&& visit) {
  ForEachDataTerm<Scalar>(graph, MeasurementWeights(),
                          std::forward<Visit>(visit));
}

class SESyncProblem {
 public:
  // `graph` must pass ValidatePoseGraph and outlive this object. Check ok()
  // afterwards: it fails only if the translational Laplacian could not be
  // factorized. Products with Q use up to `num_threads` threads (results do
  // not depend on it). `weights` (measurement_weights.h; empty: all 1)
  // define the weighted problem; they must pass CheckMeasurementWeights.
  explicit SESyncProblem(const PoseGraph& graph, int num_threads = 1,
                         MeasurementWeights weights = {});

  const PoseGraph& graph() const { return *graph_; }
  // The weights of the problem (empty: all 1).
  const MeasurementWeights& weights() const { return weights_; }

  // Re-weights the problem in place: recomputes the VALUES of every matrix
  // and the rounding bounds from ForEachDataTerm with the new weights. The
  // sparsity patterns do not change (zero weights keep explicit zeros), so
  // the vertex ordering and Lbar's symbolic analysis are kept and Lbar is
  // only refactorized numerically. Users of the matrices holding values or
  // factors of their own (CertificateMatrix, SESyncPreconditioner) must be
  // refreshed too. `weights` must pass CheckMeasurementWeights (connected);
  // returns ok().
  bool UpdateWeights(MeasurementWeights weights);

  bool ok() const { return ok_; }
  int dimension() const { return d_; }
  int num_poses() const { return n_; }
  int num_threads() const { return num_threads_; }

  // YQ = Y * Q for Y of size r x dn. O(m r) plus one Cholesky solve.
  void MultiplyQ(const Eigen::MatrixXd& Y, Eigen::MatrixXd* YQ) const;

  // Optimal translations (d x n, eq. 21) for the rotations R (d x dn), with
  // t_0 = 0.
  Eigen::MatrixXd RecoverTranslations(const Eigen::MatrixXd& R) const;

  // D = L(G^rho) + Sigma~ (dn x dn, both triangles stored).
  const SparseMatrix& D() const { return D_; }
  // Vbar: V without its first row ((n-1) x dn).
  const SparseMatrix& Vbar() const { return Vbar_; }
  // Lbar: L(W^tau) without its first row and column (both triangles stored).
  const SparseMatrix& Lbar() const { return Lbar_; }
  // The rotational connection Laplacian L(G^rho) alone (dn x dn).
  const SparseMatrix& RotationLaplacian() const { return Lrho_; }
  // A fill-reducing ordering of the n poses (from the pattern of L(W^tau)):
  // ordering[k] = pose eliminated k-th.
  const std::vector<int>& vertex_ordering() const { return vertex_ordering_; }
  // A bound on the backward error of Lbar's Cholesky factorization
  // (CholmodFactor::BackwardErrorBound): the scale of the round-off that
  // factorizations of matrices containing Lbar make in its rows. O(nnz) per
  // call.
  double LbarBackwardError() const;

  // Bounds on the rounding of the matrices as stored against their exact
  // values from the measurements (ForEachDataTerm), per row of
  // M = [L(W^tau) -V; -V^T D]: sum_j |stored M_ij - exact M_ij| over the row
  // (gamma_{k+1} times the sum of the row's |terms|, k its number of terms).
  // Translation rows by pose (size n), rotation rows (size dn).
  const std::vector<double>& translation_row_rounding() const {
    return translation_row_rounding_;
  }
  const std::vector<double>& rotation_row_rounding() const {
    return rotation_row_rounding_;
  }

 private:
  // The values of every matrix and the rounding bounds from the current
  // weights (the patterns are the same for all weights). `lw` (if not null)
  // gets the terms of L(W^tau).
  void Assemble(std::vector<Eigen::Triplet<double>>* lw);
  // Numeric factorization of Lbar (symbolic analysis done); sets ok_.
  void FactorizeLbar();

  const PoseGraph* graph_ = nullptr;
  MeasurementWeights weights_;
  int d_ = 0, n_ = 0, num_threads_ = 1;
  std::vector<double> translation_row_rounding_, rotation_row_rounding_;
  bool ok_ = false;
  SparseMatrix D_, Lrho_, Vbar_, VbarT_, minus_Vbar_, Lbar_;
  std::unique_ptr<CholmodFactor> lbar_factor_;
  SparseCholeskyFactor lbar_solver_;  // The same factor, for MultiplyQ.
  std::vector<int> vertex_ordering_;
};

// tr(Lambda) = sum_i tr(Lambda_i) for the d x d blocks of Lambda (d x dn).
double BlockDiagonalTrace(const Eigen::MatrixXd& Lambda, int d);

// out_i = V_i * Lambda_i for the d x d blocks Lambda (d x dn) and the r x d
// blocks V_i of V (r x dn).
void BlockDiagonalMultiply(const Eigen::MatrixXd& V,
                           const Eigen::MatrixXd& Lambda, int d,
                           Eigen::MatrixXd* out);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_
