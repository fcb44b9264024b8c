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
//
// Landmarks and priors (pose_graph.h) keep this form; only the index sets
// grow (ProblemLayout). A landmark is a translation node without a rotation:
// its measurements are the translation halves of edges from their poses, so
// L(W^tau) and V gain rows and Q stays a matrix of rotation blocks. A prior is
// an edge from the world pose w = (I, 0), which becomes one more rotation
// block (R_w) and, when some prior has a position term, one more translation
// node (t_w). The extended objective is invariant under a global rigid
// motion of all poses, landmarks and w, and equals F(x, p) at w = (I, 0), so
// it has the same optimum; the solver solves it and expresses the answer in
// w's frame (staircase.h). With t_w present, t_w is the eliminated gauge
// node instead of t_0.
#ifndef CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_
#define CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_

#include <complex>
#include <future>
#include <memory>
#include <utility>
#include <vector>

#include "Eigen/CholmodSupport"
#include "Eigen/Core"
#include "Eigen/SparseCore"
#include "ceres_sesync/internal/measurement_weights.h"
#include "ceres_sesync/internal/openmp_teams.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"
#include "ceres_sesync/pose_graph.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using ComplexSparseMatrix =
    Eigen::SparseMatrix<std::complex<double>, Eigen::ColMajor, int>;

// Eigen's CHOLMOD LL^T (LL^H for complex) decomposition of the lower
// triangle, with two additions: numeric factorizations run CHOLMOD's OpenMP
// teams with one thread (openmp_teams.h: supernodal factorizations up to 2x
// faster, the same factor), and the symbolic analysis can take a
// fill-reducing ordering from the caller.
template <typename Matrix>
class CholmodDecompositionWithOrdering
    : public Eigen::CholmodDecomposition<Matrix, Eigen::Lower> {
  using Base = Eigen::CholmodDecomposition<Matrix, Eigen::Lower>;

 public:
  void factorize(const Matrix& matrix) {
    ScopedSerialOpenMpTeams serial_teams;
    Base::factorize(matrix);
  }
  // analyzePattern() with a fill-reducing ordering chosen by the caller
  // (ordering[k] = original index of the k-th pivot) instead of CHOLMOD's
  // own (AMD, possibly METIS) on the full matrix.
  void AnalyzePatternWithOrdering(const Matrix& lower,
                                  std::vector<int> ordering) {
    CHECK_EQ(static_cast<int>(ordering.size()), lower.rows());
    cholmod_common& common = this->cholmod();
    if (this->m_cholmodFactor != nullptr) {
      cholmod_free_factor(&this->m_cholmodFactor, &common);
    }
    cholmod_sparse A =
        Eigen::viewAsCholmod(lower.template selfadjointView<Eigen::Lower>());
    const int saved_methods = common.nmethods;
    const int saved_ordering = common.method[0].ordering;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_GIVEN;
    this->m_cholmodFactor =
        cholmod_analyze_p(&A, ordering.data(), nullptr, 0, &common);
    common.nmethods = saved_methods;
    common.method[0].ordering = saved_ordering;
    CHECK(this->m_cholmodFactor != nullptr) << "cholmod_analyze_p failed";
    analysis_flops_ = common.fl;
    analysis_nonzeros_ = common.lnz;
    this->m_isInitialized = true;
    this->m_info = Eigen::Success;
    this->m_analysisIsOk = true;
    this->m_factorizationIsOk = false;
  }
  // After AnalyzePatternWithOrdering(): CHOLMOD's predicted flop count of a
  // factorization and the number of nonzeros of L.
  double analysis_flops() const { return analysis_flops_; }
  double analysis_nonzeros() const { return analysis_nonzeros_; }

 private:
  double analysis_flops_ = 0, analysis_nonzeros_ = 0;
};

// The 2D chordal initialization's complex Hermitian systems (chordal.h).
using ComplexCholmodFactor =
    CholmodDecompositionWithOrdering<ComplexSparseMatrix>;

// CHOLMOD's Cholesky factorization (through Eigen) plus an a posteriori bound
// on its floating-point backward error.
class CholmodFactor : public CholmodDecompositionWithOrdering<SparseMatrix> {
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
  // 2 |x_i x_j| <= x_i^2 + x_j^2). Row by row: rho[i] >= sum_j |E_ij| for
  // every original index i. O(nnz(L)), on the factor in place.
  void RowBackwardErrorBounds(std::vector<double>* rho);
  // After a successful factorization: a copy of the factor for fast solves
  // with r x N right-hand sides.
  SparseCholeskyFactor ExtractFactor();
  // Frees the numeric factor and keeps the symbolic analysis, which the
  // next factorize() reuses (e.g. once ExtractFactor() has copied it).
  void ReleaseNumericFactor();
  // Whether a numeric factor is held (a factorization succeeded and was
  // not released).
  bool HasNumericFactor() const {
    return m_cholmodFactor != nullptr && m_factorizationIsOk;
  }
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
template <typename Matrix>
void ConfigureCholmod(CholmodLayout layout,
                      CholmodDecompositionWithOrdering<Matrix>* factor) {
  factor->setMode(layout == CholmodLayout::kSimplicial
                      ? Eigen::CholmodSimplicialLLt
                      : Eigen::CholmodSupernodalLLt);
  cholmod_common& common = factor->cholmod();
  if (layout == CholmodLayout::kAutomatic) {
    common.supernodal = CHOLMOD_AUTO;
    common.supernodal_switch = kSupernodalSwitch;
  }
  // A simplicial factorization is computed as LL^T (not LDL^T) iff final_ll.
  common.final_ll = 1;
  common.print = 0;
}

// The index sets of the unknowns (see the top of this file):
//   translation nodes  k = 0..n-1       pose translations t_k,
//                      k = n..n+L-1     landmark positions p_(k-n),
//                      k = n+L          t_w, iff world_translation;
//   rotation blocks    k = 0..n-1       pose rotations R_k (rotation indices
//                                       d*k .. d*k+d-1),
//                      k = n            R_w, iff world_rotation.
// world_rotation: the graph has priors; world_translation: a prior has a
// position term (tau > 0; rotation-only priors leave t_w unused). The gauge
// is the translation node fixed at 0 and eliminated from Lbar and Vbar: t_w
// when it exists, else t_0. Vertices (for fill-reducing orderings) are the
// translation nodes 0..n+L-1 plus, with priors, the world vertex n+L, which
// carries R_w and t_w (if present): a vertex has a translation unless it is
// the world without t_w, and a rotation unless it is a landmark.
struct ProblemLayout {
  ProblemLayout() = default;
  explicit ProblemLayout(const PoseGraph& graph);

  int dimension = 0, num_poses = 0, num_landmarks = 0;
  bool world_rotation = false, world_translation = false;

  int num_rotations() const { return num_poses + (world_rotation ? 1 : 0); }
  int num_translations() const {
    return num_poses + num_landmarks + (world_translation ? 1 : 0);
  }
  int num_vertices() const {
    return num_poses + num_landmarks + (world_rotation ? 1 : 0);
  }
  int landmark_node(int l) const { return num_poses + l; }
  // Valid iff world_translation / world_rotation.
  int world_translation_node() const { return num_poses + num_landmarks; }
  int world_rotation_block() const { return num_poses; }
  // The translation node fixed at 0.
  int gauge() const { return world_translation ? world_translation_node() : 0; }
  // Index of translation node k in Lbar / Vbar (-1 for the gauge).
  int reduced(int k) const {
    const int g = gauge();
    return k == g ? -1 : (k < g ? k : k - 1);
  }
  // The translation node of index r in Lbar / Vbar (reduced()'s inverse).
  int unreduced(int r) const { return r < gauge() ? r : r + 1; }
  // The vertex of translation node k (its own index) and of rotation block k.
  int vertex_of_rotation(int k) const {
    return k < num_poses ? k : num_poses + num_landmarks;
  }
  // The translation node / rotation block of vertex v, or -1.
  int translation_of_vertex(int v) const {
    return v < num_poses + num_landmarks || world_translation ? v : -1;
  }
  int rotation_of_vertex(int v) const {
    return v < num_poses ? v
                         : (v == num_poses + num_landmarks ? num_poses : -1);
  }
};

// The data matrix M of the objective as a sum of terms, one
// visit(block, row, column, value) per term, with values computed in
// `Scalar` from the measurements (double, or DoubleDouble for the
// high-precision certificate) and the precisions of the weighted problem
// (measurement_weights.h; empty weights: the graph's own). Blocks and their
// indices (ProblemLayout):
//   kTranslation:   L(W^tau), translation nodes (row, column);
//   kCoupling:      V, translation node row, rotation column d*k + a;
//   kRotation:      L(G^rho), rotation indices;
//   kRotationSigma: Sigma~, rotation indices (D = L(G^rho) + Sigma~).
// The symmetric blocks get both (row, column) and (column, row) of every
// off-diagonal term. Within a block, entries are the sums of their terms in
// visiting order (so assembling from these terms reproduces SESyncProblem's
// matrices bitwise). The relative pose measurements come first, then the
// landmark measurements (translation terms from pose i to node n + l with
// t~ = z, tau = nu), then the priors (edges from w: rotation terms between
// R_w and R_i with R~ if kappa > 0, translation terms from t_w to t_i with
// t~ = g if tau > 0). Weights apply to every term (measurement_weights.h). The
// terms visited, and so the sparsity pattern, do not depend on the weights:
// a zero weight visits exact zeros.
enum class DataBlock { kTranslation, kCoupling, kRotation, kRotationSigma };

namespace data_terms {

// The translation half tau ||t_dst - t_src - R_src t~||^2 of an edge from
// translation node `src` (rotation block `src_rotation`) to node `dst`.
template <typename Scalar, typename Visit, typename Vector>
void VisitTranslationTerm(int d, int src, int src_rotation, int dst,
                          const Vector& t, double precision, Visit& visit) {
  const Scalar tau(precision);
  for (int a = 0; a < d; ++a) {
    for (int b = 0; b < d; ++b) {
      visit(DataBlock::kRotationSigma, d * src_rotation + a,
            d * src_rotation + b, tau * Scalar(t(a)) * Scalar(t(b)));
    }
    const Scalar v = tau * Scalar(t(a));
    visit(DataBlock::kCoupling, dst, d * src_rotation + a, v);
    visit(DataBlock::kCoupling, src, d * src_rotation + a, -v);
  }
  visit(DataBlock::kTranslation, src, src, tau);
  visit(DataBlock::kTranslation, dst, dst, tau);
  visit(DataBlock::kTranslation, src, dst, -tau);
  visit(DataBlock::kTranslation, dst, src, -tau);
}

// The rotation half kappa ||R_dst - R_src R~||_F^2 between rotation blocks.
template <typename Scalar, typename Visit, typename Matrix>
void VisitRotationTerm(int d, int src, int dst, const Matrix& R,
                       double precision, Visit& visit) {
  const Scalar kappa(precision);
  for (int a = 0; a < d; ++a) {
    visit(DataBlock::kRotation, d * src + a, d * src + a, kappa);
    visit(DataBlock::kRotation, d * dst + a, d * dst + a, kappa);
    for (int b = 0; b < d; ++b) {
      const Scalar r = -kappa * Scalar(R(a, b));
      visit(DataBlock::kRotation, d * src + a, d * dst + b, r);
      visit(DataBlock::kRotation, d * dst + b, d * src + a, r);
    }
  }
}

}  // namespace data_terms

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
  // Landmark measurements: pose i -> translation node n + l.
  const ProblemLayout layout(graph);
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    data_terms::VisitTranslationTerm<Scalar>(
        d, o.i, o.i, layout.landmark_node(o.l), o.z,
        WeightedPrecision(o, weights, LandmarkTerm(graph, q)), visit);
  }
  // Priors: edges from the world pose w to pose i.
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    const PosePrior& p = graph.priors[q];
    const Precisions w = WeightedPrecisions(p, weights, PriorTerm(graph, q));
    if (p.has_rotation()) {
      data_terms::VisitRotationTerm<Scalar>(d, layout.world_rotation_block(),
                                            p.i, p.R, w.kappa, visit);
    }
    if (p.has_position()) {
      data_terms::VisitTranslationTerm<Scalar>(
          d, layout.world_translation_node(), layout.world_rotation_block(),
          p.i, p.t, w.tau, visit);
    }
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
  // With `background_lbar` and num_threads > 1, Lbar's symbolic analysis
  // and factorization run on another thread after the constructor returns,
  // and every member that needs the factor (ok(), MultiplyQ(),
  // RecoverTranslations(), LbarRowBackwardErrors(), LbarIsSupernodal(),
  // UpdateWeights()) waits for it: for a caller with work that needs only
  // the assembled matrices and the ordering (the chordal initialization).
  explicit SESyncProblem(const PoseGraph& graph, int num_threads = 1,
                         MeasurementWeights weights = {},
                         bool background_lbar = false);
  // The background factorization holds `this`.
  SESyncProblem(SESyncProblem&&) = delete;
  SESyncProblem& operator=(SESyncProblem&&) = delete;

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

  bool ok() const {
    AwaitLbar();
    return ok_;
  }
  int dimension() const { return d_; }
  // The index sets (ProblemLayout). Below, n is num_rotations() (the number
  // of d x d blocks of Q: the poses, plus R_w with priors) and N is
  // num_translations() (poses, landmarks, t_w); without landmarks and
  // priors both are the number of poses.
  const ProblemLayout& layout() const { return layout_; }
  int num_rotations() const { return n_; }
  int num_translations() const { return layout_.num_translations(); }
  int num_threads() const { return num_threads_; }

  // YQ = Y * Q for Y of size r x dn. O(m r) plus one Cholesky solve.
  void MultiplyQ(const Eigen::MatrixXd& Y, Eigen::MatrixXd* YQ) const;
  // Multiply-adds of MultiplyQ() per row of Y: the entries of D, of Vbar
  // (twice) and of Lbar's factor (two triangular solves). From the patterns,
  // so the same on every run and machine, unlike a measured time.
  double MultiplyQCost() const;

  // Optimal translations (d x N, eq. 21: every translation node, landmarks
  // included) for the rotations R (d x dn), with the gauge node at 0.
  Eigen::MatrixXd RecoverTranslations(const Eigen::MatrixXd& R) const;

  // D = L(G^rho) + Sigma~ (dn x dn, both triangles stored).
  const SparseMatrix& D() const { return D_; }
  // Vbar: V without the gauge node's row ((N-1) x dn, rows in
  // ProblemLayout::reduced order).
  const SparseMatrix& Vbar() const { return Vbar_; }
  // Lbar: L(W^tau) without the gauge node's row and column (both triangles
  // stored).
  const SparseMatrix& Lbar() const { return Lbar_; }
  // The rotational connection Laplacian L(G^rho) alone (dn x dn).
  const SparseMatrix& RotationLaplacian() const { return Lrho_; }
  // A fill-reducing ordering of the vertices (ProblemLayout: poses,
  // landmarks, the world) from the pattern of M collapsed to vertices:
  // ordering[k] = vertex eliminated k-th.
  const std::vector<int>& vertex_ordering() const { return vertex_ordering_; }
  // The flop count of a Cholesky factorization of that collapsed pattern in
  // this ordering per nonzero of its factor (CHOLMOD's symbolic analysis): a
  // factorization's cost in solves of its factor, up to a constant, for any
  // matrix with the vertices' pattern in blocks (K, the Newton system).
  double vertex_flops_per_entry() const { return vertex_flops_per_entry_; }
  // Row-wise bounds on the backward error of Lbar's Cholesky factorization
  // (CholmodFactor::RowBackwardErrorBounds), in Lbar's row order: the scale
  // of the round-off that factorizations of matrices containing Lbar make
  // in its rows. O(nnz) per call.
  std::vector<double> LbarRowBackwardErrors() const;
  // Whether CHOLMOD chose the supernodal layout for Lbar's factor (heavy
  // fill: large maps, 3D lattices).
  bool LbarIsSupernodal() const {
    AwaitLbar();
    return lbar_factor_ != nullptr && lbar_factor_->IsSupernodal();
  }

  // Bounds on the rounding of the matrices as stored against their exact
  // values from the measurements (ForEachDataTerm), per row of
  // M = [L(W^tau) -V; -V^T D]: sum_j |stored M_ij - exact M_ij| over the row
  // (gamma_{k+1} times the sum of the row's |terms|, k its number of terms).
  // Translation rows by translation node (size N), rotation rows (size dn).
  const std::vector<double>& translation_row_rounding() const {
    return translation_row_rounding_;
  }
  const std::vector<double>& rotation_row_rounding() const {
    return rotation_row_rounding_;
  }

 private:
  // The values of every matrix and the rounding bounds from the current
  // weights (the patterns are the same for all weights).
  void Assemble();
  // Numeric factorization of Lbar (symbolic analysis done); sets ok_.
  void FactorizeLbar();
  // Waits for a background factorization of Lbar, if one is running.
  void AwaitLbar() const {
    if (lbar_pending_.valid()) lbar_pending_.wait();
  }

  const PoseGraph* graph_ = nullptr;
  ProblemLayout layout_;
  MeasurementWeights weights_;
  int d_ = 0, n_ = 0, num_threads_ = 1;
  std::vector<double> translation_row_rounding_, rotation_row_rounding_;
  bool ok_ = false;
  SparseMatrix D_, Lrho_, Vbar_, VbarT_, minus_Vbar_, Lbar_;
  std::unique_ptr<CholmodFactor> lbar_factor_;
  SparseCholeskyFactor lbar_solver_;  // The same factor, for MultiplyQ.
  std::vector<int> vertex_ordering_;
  double vertex_flops_per_entry_ = 0;
  // The background factorization of Lbar (declared last: destroyed, i.e.
  // joined, first).
  std::shared_future<void> lbar_pending_;
};

// tr(Lambda) = sum_i tr(Lambda_i) for the d x d blocks of Lambda (d x dn).
double BlockDiagonalTrace(const Eigen::MatrixXd& Lambda, int d);

// out_i = V_i * Lambda_i for the d x d blocks Lambda (d x dn) and the r x d
// blocks V_i of V (r x dn); large products split by blocks over up to
// `num_threads` threads (the same results for any count).
void BlockDiagonalMultiply(const Eigen::MatrixXd& V,
                           const Eigen::MatrixXd& Lambda, int d,
                           Eigen::MatrixXd* out, int num_threads = 1);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_SESYNC_PROBLEM_H_
