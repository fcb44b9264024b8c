#include "ceres_sesync/internal/sesync_problem.h"

#include <algorithm>
#include <cmath>
#include <future>
#include <utility>
#include <vector>

#include "ceres_sesync/internal/double_double.h"
#include "ceres_sesync/internal/openmp_teams.h"
#include "ceres_sesync/internal/parallel.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {

using Triplet = Eigen::Triplet<double>;

namespace {

// out (+)= Y A for Y of size r x k and the compressed-column A (k x N): each
// output column is a sparse combination of columns of Y (contiguous
// r-vectors). Several times faster than Eigen's dense * sparse product for
// the small r of the staircase.
template <int R>
void MultiplyBySparseKernel(const Eigen::MatrixXd& Y, const SparseMatrix& A,
                            bool accumulate, int begin, int end,
                            Eigen::MatrixXd* out) {
  using Vector = Eigen::Matrix<double, R, 1>;
  using ConstMap = Eigen::Map<const Vector>;
  const int r = static_cast<int>(Y.rows());
  const int* start = A.outerIndexPtr();
  const int* row = A.innerIndexPtr();
  const double* value = A.valuePtr();
  const double* y = Y.data();
  Vector sum(r);
  for (int j = begin; j < end; ++j) {
    sum.setZero();
    for (int k = start[j]; k < start[j + 1]; ++k) {
      sum +=
          value[k] * ConstMap(y + static_cast<std::ptrdiff_t>(row[k]) * r, r);
    }
    Eigen::Map<Vector> out_j(out->data() + static_cast<std::ptrdiff_t>(j) * r,
                             r);
    if (accumulate) {
      out_j += sum;
    } else {
      out_j = sum;
    }
  }
}

// Output columns are split into contiguous ranges, one per thread.
void MultiplyBySparse(const Eigen::MatrixXd& Y, const SparseMatrix& A,
                      bool accumulate, int num_threads, Eigen::MatrixXd* out) {
  DCHECK(A.isCompressed());
  if (!accumulate) out->resize(Y.rows(), A.cols());
  const int cols = static_cast<int>(A.cols());
  const int parts =
      ThreadsFor(num_threads, 2.0 * Y.rows() * (A.nonZeros() + cols));
  ParallelParts(parts, [&](int part, int num_parts) {
    const int begin = PartBegin(cols, part, num_parts);
    const int end = PartBegin(cols, part + 1, num_parts);
    switch (Y.rows()) {
      case 2:
        return MultiplyBySparseKernel<2>(Y, A, accumulate, begin, end, out);
      case 3:
        return MultiplyBySparseKernel<3>(Y, A, accumulate, begin, end, out);
      case 4:
        return MultiplyBySparseKernel<4>(Y, A, accumulate, begin, end, out);
      case 5:
        return MultiplyBySparseKernel<5>(Y, A, accumulate, begin, end, out);
      case 6:
        return MultiplyBySparseKernel<6>(Y, A, accumulate, begin, end, out);
      default:
        return MultiplyBySparseKernel<Eigen::Dynamic>(Y, A, accumulate, begin,
                                                      end, out);
    }
  });
}

}  // namespace

namespace {

// Calls visit(row, column, value) for every stored entry of the lower
// triangle of the LL^T factor L (permuted indices), in place: supernodal
// (dense column blocks; entries above a block's diagonal are skipped) or
// simplicial (column j: nz[j] entries from p[j], packed or not).
template <typename Visit>
void ForEachFactorEntry(const cholmod_factor& L, Visit visit) {
  const double* x = static_cast<const double*>(L.x);
  if (L.is_super) {
    const auto* super = static_cast<const int*>(L.super);
    const auto* pi = static_cast<const int*>(L.pi);
    const auto* px = static_cast<const int*>(L.px);
    const auto* s = static_cast<const int*>(L.s);
    for (size_t k = 0; k < L.nsuper; ++k) {
      const int rows = pi[k + 1] - pi[k];
      for (int j = 0; j < super[k + 1] - super[k]; ++j) {
        const double* column = x + px[k] + static_cast<size_t>(j) * rows;
        for (int i = j; i < rows; ++i) {
          visit(s[pi[k] + i], super[k] + j, column[i]);
        }
      }
    }
    return;
  }
  const auto* p = static_cast<const int*>(L.p);
  const auto* nz = static_cast<const int*>(L.nz);
  const auto* row = static_cast<const int*>(L.i);
  for (size_t j = 0; j < L.n; ++j) {
    const int end = p[j] + nz[j];
    for (int k = p[j]; k < end; ++k) visit(row[k], static_cast<int>(j), x[k]);
  }
}

}  // namespace

void CholmodFactor::RowBackwardErrorBounds(std::vector<double>* rho) {
  CHECK(m_cholmodFactor != nullptr && m_factorizationIsOk);
  const cholmod_factor& L = *m_cholmodFactor;
  CHECK(L.is_ll) << "the backward error bound is for LL^T factors";
  const int n = static_cast<int>(L.n);
  std::vector<double> column_sum(n, 0.0), v(n, 0.0);
  std::vector<int> row_count(n, 0);
  ForEachFactorEntry(L, [&](int i, int j, double value) {
    column_sum[j] += std::abs(value);
    ++row_count[i];
  });
  ForEachFactorEntry(L, [&](int i, int j, double value) {
    v[i] += std::abs(value) * column_sum[j];
  });
  // Entry (i, j) of L L^T sums at most min(k_i, k_j) products (k_i = stored
  // entries in row i), so row i of the error is bounded by gamma_{k_i + 1} v_i.
  // The factor (1 + 1e-6) covers the rounding of computing v (sums of up to
  // 10^9 nonnegative terms, each within gamma_{10^9} < 1.2e-7).
  const int* perm = static_cast<const int*>(L.Perm);
  rho->assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    (*rho)[perm ? perm[i] : i] =
        DoubleGamma(row_count[i] + 1) * v[i] * (1 + 1e-6);
  }
}

SparseCholeskyFactor CholmodFactor::ExtractFactor() {
  return SparseCholeskyFactor(m_cholmodFactor, &cholmod());
}

void CholmodFactor::ReleaseNumericFactor() {
  if (!HasNumericFactor()) return;
  cholmod_factor* L = m_cholmodFactor;
  CHECK(cholmod_change_factor(CHOLMOD_PATTERN, L->is_ll, L->is_super,
                              /*to_packed=*/true, /*to_monotonic=*/true, L,
                              &cholmod()))
      << "cholmod_change_factor failed";
  m_factorizationIsOk = false;
}

std::vector<int> CholmodFactor::Ordering() const {
  CHECK(m_cholmodFactor != nullptr);
  const int* perm = static_cast<const int*>(m_cholmodFactor->Perm);
  return std::vector<int>(perm, perm + m_cholmodFactor->n);
}

bool CholmodFactor::IsSupernodal() const {
  CHECK(m_cholmodFactor != nullptr);
  return m_cholmodFactor->is_super;
}

namespace {

// The pattern of M collapsed to vertices (ProblemLayout): the terms of
// L(W^tau), plus, with landmarks or priors, those of V and L(G^rho), which
// are not all in it, and the diagonal. The terms, and so the pattern, do not
// depend on the weights.
std::vector<Triplet> VertexPattern(const PoseGraph& graph,
                                   const ProblemLayout& layout) {
  const int d = graph.dimension;
  const bool more = graph.has_landmarks_or_priors();
  std::vector<Triplet> pattern;
  pattern.reserve(4 *
                  (graph.measurements.size() +
                   graph.landmark_measurements.size() + graph.priors.size()));
  ForEachDataTerm<double>(
      graph, [&](DataBlock block, int row, int col, double /*value*/) {
        switch (block) {
          case DataBlock::kTranslation:
            pattern.emplace_back(row, col, 1.0);
            return;
          case DataBlock::kCoupling:
            if (more) {
              const int b = layout.vertex_of_rotation(col / d);
              pattern.emplace_back(row, b, 1.0);
              pattern.emplace_back(b, row, 1.0);
            }
            return;
          case DataBlock::kRotation:
            if (more) {
              pattern.emplace_back(layout.vertex_of_rotation(row / d),
                                   layout.vertex_of_rotation(col / d), 1.0);
            }
            return;
          case DataBlock::kRotationSigma:
            return;
        }
      });
  if (more) {
    for (int k = 0; k < layout.num_vertices(); ++k) {
      pattern.emplace_back(k, k, 1.0);
    }
  }
  return pattern;
}

// One fill-reducing ordering of the vertices (on VertexPattern) serves Lbar
// and the augmented matrices of certificate_matrix.h, whose (d+1)-blocks
// multiply its flops by about (d+1)^3 / 2. AMD is cheap; on large maps
// nested dissection (METIS) costs more to compute but leaves much less
// fill: measured on a 50,000-pose 2D city walk, 2.5x fewer flops (1.2x on
// city10000 and a 27,000-pose cube). So METIS is tried when the predicted
// flops of the augmented matrix exceed 2e4 per pose (about where its ~7 us
// per pose, measured on large cities, pays off) on maps of at least
// kMinNestedDissectionVertices, and kept if it predicts fewer flops. Below
// that size its gain is small and did not pay for its cost (~2.5 us per
// vertex there): sphere2500 and torus3D (the only
// shared datasets above 2e4 per pose) got 11% and 19% fewer flops, and
// their solves were 8% slower in all (one thread); from 2x10^4 poses on,
// cities get 2.1-3x fewer. The first
// analysis is AMD alone: CHOLMOD's default would itself go on to METIS
// when AMD's fill is heavy, which then ran twice (10^6-pose city: 9.9 s
// for that analysis, 7.8 s for the second METIS).
constexpr int kMinNestedDissectionVertices = 10000;

// The ordering, and CHOLMOD's flop count of the vertex pattern's factor
// under it per nonzero of that factor.
struct VertexOrderingResult {
  std::vector<int> ordering;
  double flops_per_entry = 0;
};

VertexOrderingResult VertexOrdering(const PoseGraph& graph,
                                    const ProblemLayout& layout) {
  const int num_vertices = layout.num_vertices();
  if (num_vertices == 1) return {{0}, 0};
  const std::vector<Triplet> vertex_pattern = VertexPattern(graph, layout);
  SparseMatrix pattern(num_vertices, num_vertices);
  pattern.setFromTriplets(vertex_pattern.begin(), vertex_pattern.end());
  CholmodFactor analysis;
  ConfigureCholmod(CholmodLayout::kSimplicial, &analysis);
  analysis.cholmod().nmethods = 1;
  analysis.cholmod().method[0].ordering = CHOLMOD_AMD;
  analysis.analyzePattern(pattern);
  VertexOrderingResult result{analysis.Ordering(), 0};
  const double block_flops = std::pow(graph.dimension + 1.0, 3) / 2;
  const double flops = analysis.cholmod().fl;
  result.flops_per_entry = flops / std::max(1.0, analysis.cholmod().lnz);
  if (num_vertices >= kMinNestedDissectionVertices &&
      flops * block_flops > 2e4 * num_vertices) {
    CholmodFactor nested;
    ConfigureCholmod(CholmodLayout::kSimplicial, &nested);
    cholmod_common& common = nested.cholmod();
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_METIS;
    nested.analyzePattern(pattern);
    if (nested.info() == Eigen::Success && nested.cholmod().fl < flops) {
      result.ordering = nested.Ordering();
      result.flops_per_entry =
          common.fl / std::max(1.0, static_cast<double>(common.lnz));
    }
    VLOG(1) << "vertex ordering: AMD " << flops << " flops, METIS "
            << nested.cholmod().fl;
  }
  return result;
}

}  // namespace

ProblemLayout::ProblemLayout(const PoseGraph& graph)
    : dimension(graph.dimension),
      num_poses(graph.num_poses),
      num_landmarks(graph.num_landmarks),
      world_rotation(!graph.priors.empty()) {
  for (const PosePrior& p : graph.priors) {
    world_translation = world_translation || p.has_position();
  }
}

SESyncProblem::SESyncProblem(const PoseGraph& graph, int num_threads,
                             MeasurementWeights weights, bool background_lbar)
    : graph_(&graph),
      layout_(graph),
      weights_(std::move(weights)),
      d_(graph.dimension),
      n_(layout_.num_rotations()),
      num_threads_(std::max(1, num_threads)) {
  CHECK(weights_.empty() || weights_.size() == NumWeightedTerms(graph));
  const ProblemLayout& layout = layout_;
  const int N = layout.num_translations();
  // The ordering depends on the pattern alone: with a second thread it is
  // computed while Assemble() computes the values (10^5-pose city: ~0.7 s
  // each, the AMD and METIS analyses and the assembly; below ~5000 vertices
  // both take a few ms, not worth a thread).
  if (num_threads_ > 1 && layout.num_vertices() >= 5000) {
    std::future<VertexOrderingResult> ordering =
        std::async(std::launch::async,
                   [&graph, &layout] { return VertexOrdering(graph, layout); });
    Assemble();
    VertexOrderingResult result = ordering.get();
    vertex_ordering_ = std::move(result.ordering);
    vertex_flops_per_entry_ = result.flops_per_entry;
  } else {
    Assemble();
    VertexOrderingResult result = VertexOrdering(graph, layout);
    vertex_ordering_ = std::move(result.ordering);
    vertex_flops_per_entry_ = result.flops_per_entry;
  }
  if (layout.num_vertices() == 1) {
    ok_ = true;
    return;
  }
  if (N == 1) {  // Nothing to factorize (one pose, rotation priors only).
    ok_ = true;
    return;
  }
  std::vector<int> lbar_ordering;
  lbar_ordering.reserve(N - 1);
  for (int vertex : vertex_ordering_) {
    const int node = layout.translation_of_vertex(vertex);
    if (node >= 0 && layout.reduced(node) >= 0) {
      lbar_ordering.push_back(layout.reduced(node));
    }
  }
  // Supernodal where Lbar's fill is heavy (10^6-pose city: 3.3 s, and the
  // data stage 32.7 -> 25.7 s against simplicial); the products with Q use
  // the extracted copy either way.
  auto factorize = [this, ordering = std::move(lbar_ordering)]() mutable {
    lbar_factor_ = std::make_unique<CholmodFactor>();
    ConfigureCholmod(CholmodLayout::kAutomatic, lbar_factor_.get());
    lbar_factor_->AnalyzePatternWithOrdering(Lbar_, std::move(ordering));
    FactorizeLbar();
  };
  if (background_lbar && num_threads_ > 1) {
    lbar_pending_ = std::async(std::launch::async, std::move(factorize));
  } else {
    factorize();
  }
}

void SESyncProblem::Assemble() {
  const PoseGraph& graph = *graph_;
  const int d = d_, n = n_, N = layout_.num_translations();
  std::vector<Triplet> lrho, sigma, v, lw;
  const size_t m = graph.measurements.size() + graph.priors.size();
  const size_t m_t = m + graph.landmark_measurements.size();
  lrho.reserve(m * (2 * d + 2 * d * d));
  sigma.reserve(m_t * d * d);
  v.reserve(2 * m_t * d);
  lw.reserve(4 * m_t);
  // Per row of M: the sum of |terms| and their number, for the rounding
  // bounds. Rows of D carry the terms of L(G^rho) and Sigma~ plus one more
  // rounding (their sum). Exact zeros (the terms of zero weights) carry no
  // rounding and are not counted, so the bounds of a problem with weights
  // in {0, 1} are those of its weight-1 measurements alone.
  std::vector<double> t_abs(N, 0.0), r_abs(d * n, 0.0);
  std::vector<int> t_count(N, 0), r_count(d * n, 0);
  ForEachDataTerm<double>(
      graph, weights_, [&](DataBlock block, int row, int col, double value) {
        const int term = value != 0 ? 1 : 0;
        switch (block) {
          case DataBlock::kTranslation:
            lw.emplace_back(row, col, value);
            t_abs[row] += std::abs(value);
            t_count[row] += term;
            return;
          case DataBlock::kCoupling:  // M has -V at (row, col) and (col, row).
            v.emplace_back(row, col, value);
            t_abs[row] += std::abs(value);
            t_count[row] += term;
            r_abs[col] += std::abs(value);
            r_count[col] += term;
            return;
          case DataBlock::kRotation:
            lrho.emplace_back(row, col, value);
            break;
          case DataBlock::kRotationSigma:
            sigma.emplace_back(row, col, value);
            break;
        }
        r_abs[row] += std::abs(value);
        r_count[row] += term;
      });
  // Each stored entry is a sum of at most k rounded terms (a product of up
  // to three doubles: two roundings each) plus one rounding of the sum
  // L(G^rho) + Sigma~: within gamma_{k+3} of its exact value, k bounded by
  // the row's terms. The factor (1 + 1e-6) covers this computation's own
  // rounding.
  auto bound = [](int count, double abs_sum) {
    return DoubleGamma(count + 3) * abs_sum * (1 + 1e-6);
  };
  translation_row_rounding_.resize(N);
  for (int i = 0; i < N; ++i)
    translation_row_rounding_[i] = bound(t_count[i], t_abs[i]);
  rotation_row_rounding_.resize(d * n);
  for (int i = 0; i < d * n; ++i)
    rotation_row_rounding_[i] = bound(r_count[i], r_abs[i]);
  // setFromTriplets and the sparse sums below keep explicit zeros, so the
  // patterns depend on the graph only.
  Lrho_.resize(d * n, d * n);
  Lrho_.setFromTriplets(lrho.begin(), lrho.end());
  SparseMatrix sigma_matrix(d * n, d * n);
  sigma_matrix.setFromTriplets(sigma.begin(), sigma.end());
  D_ = Lrho_ + sigma_matrix;

  // Drop the gauge node (t_0 = 0, or t_w = 0 with position priors) from the
  // translational blocks.
  const ProblemLayout& layout = layout_;
  std::vector<Triplet> vbar, lbar;
  for (const Triplet& t : v) {
    const int row = layout.reduced(t.row());
    if (row >= 0) vbar.emplace_back(row, t.col(), t.value());
  }
  for (const Triplet& t : lw) {
    const int row = layout.reduced(t.row()), col = layout.reduced(t.col());
    if (row >= 0 && col >= 0) lbar.emplace_back(row, col, t.value());
  }
  Vbar_.resize(N - 1, d * n);
  Vbar_.setFromTriplets(vbar.begin(), vbar.end());
  VbarT_ = Vbar_.transpose();
  minus_Vbar_ = -Vbar_;
  D_.makeCompressed();
  VbarT_.makeCompressed();
  minus_Vbar_.makeCompressed();
  Lbar_.resize(N - 1, N - 1);
  Lbar_.setFromTriplets(lbar.begin(), lbar.end());
}

void SESyncProblem::FactorizeLbar() {
  lbar_factor_->factorize(Lbar_);
  ok_ = lbar_factor_->info() == Eigen::Success;
  if (ok_) lbar_solver_ = lbar_factor_->ExtractFactor();
  LOG_IF(ERROR, !ok_) << "Cholesky factorization of the reduced translational "
                         "Laplacian failed";
}

bool SESyncProblem::UpdateWeights(MeasurementWeights weights) {
  CHECK(weights.empty() || weights.size() == NumWeightedTerms(*graph_));
  AwaitLbar();
  weights_ = std::move(weights);
  const Eigen::Index nnz_D = D_.nonZeros(), nnz_V = Vbar_.nonZeros(),
                     nnz_L = Lbar_.nonZeros();
  Assemble();
  // The patterns are functions of the graph alone (see Assemble()).
  CHECK(D_.nonZeros() == nnz_D && Vbar_.nonZeros() == nnz_V &&
        Lbar_.nonZeros() == nnz_L)
      << "re-weighting changed a sparsity pattern";
  if (Lbar_.rows() == 0) return ok_ = true;
  FactorizeLbar();
  return ok_;
}

void SESyncProblem::MultiplyQ(const Eigen::MatrixXd& Y,
                              Eigen::MatrixXd* YQ) const {
  AwaitLbar();
  MultiplyBySparse(Y, D_, /*accumulate=*/false, num_threads_, YQ);
  if (Lbar_.rows() == 0) return;
  Eigen::MatrixXd P, Z;  // P = Y Vbar^T (r x (n-1)), Z = P Lbar^{-1}.
  MultiplyBySparse(Y, VbarT_, /*accumulate=*/false, num_threads_, &P);
  lbar_solver_.SolveRows(P, &Z, num_threads_);
  MultiplyBySparse(Z, minus_Vbar_, /*accumulate=*/true, num_threads_, YQ);
}

double SESyncProblem::MultiplyQCost() const {
  AwaitLbar();
  return static_cast<double>(D_.nonZeros()) + 2.0 * Vbar_.nonZeros() +
         2.0 * (Lbar_.rows() == 0 ? 0 : lbar_solver_.stored_entries());
}

std::vector<double> SESyncProblem::LbarRowBackwardErrors() const {
  AwaitLbar();
  std::vector<double> rho;
  if (Lbar_.rows() > 0) lbar_factor_->RowBackwardErrorBounds(&rho);
  return rho;
}

double BlockDiagonalTrace(const Eigen::MatrixXd& Lambda, int d) {
  double trace = 0;
  for (int i = 0; i < Lambda.cols(); ++i) trace += Lambda(i % d, i);
  return trace;
}

Eigen::MatrixXd SESyncProblem::RecoverTranslations(
    const Eigen::MatrixXd& R) const {
  const int N = layout_.num_translations();
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(d_, N);
  if (N == 1) return T;
  AwaitLbar();
  const Eigen::MatrixXd rhs = Vbar_ * R.transpose();  // (N-1) x d
  const Eigen::MatrixXd reduced = lbar_factor_->solve(rhs).transpose();
  for (int k = 0; k < N; ++k) {
    if (layout_.reduced(k) >= 0) T.col(k) = reduced.col(layout_.reduced(k));
  }
  return T;
}

namespace {

template <int R, int D>
void BlockDiagonalKernel(const Eigen::MatrixXd& V,
                         const Eigen::MatrixXd& Lambda, int d, int begin,
                         int end, Eigen::MatrixXd* out) {
  using Block = Eigen::Matrix<double, R, D>;
  using Small = Eigen::Matrix<double, D, D>;
  const int r = static_cast<int>(V.rows());
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = begin; i < end; ++i) {
    Eigen::Map<Block>(out->data() + i * stride, r, d).noalias() =
        Eigen::Map<const Block>(V.data() + i * stride, r, d)
            .lazyProduct(Eigen::Map<const Small>(
                Lambda.data() + static_cast<std::ptrdiff_t>(i) * d * d, d, d));
  }
}

template <int D>
void BlockDiagonalDispatch(const Eigen::MatrixXd& V,
                           const Eigen::MatrixXd& Lambda, int d, int begin,
                           int end, Eigen::MatrixXd* out) {
  if constexpr (D != Eigen::Dynamic) {
    switch (V.rows()) {
      case D:
        return BlockDiagonalKernel<D, D>(V, Lambda, d, begin, end, out);
      case D + 1:
        return BlockDiagonalKernel<D + 1, D>(V, Lambda, d, begin, end, out);
      case D + 2:
        return BlockDiagonalKernel<D + 2, D>(V, Lambda, d, begin, end, out);
      case D + 3:
        return BlockDiagonalKernel<D + 3, D>(V, Lambda, d, begin, end, out);
    }
  }
  BlockDiagonalKernel<Eigen::Dynamic, D>(V, Lambda, d, begin, end, out);
}

}  // namespace

void BlockDiagonalMultiply(const Eigen::MatrixXd& V,
                           const Eigen::MatrixXd& Lambda, int d,
                           Eigen::MatrixXd* out, int num_threads) {
  DCHECK(out != &V);
  out->resize(V.rows(), V.cols());
  const int n = static_cast<int>(V.cols() / d);
  ParallelParts(ThreadsForPass(num_threads, static_cast<double>(V.size())),
                [&](int part, int parts) {
                  const int begin = PartBegin(n, part, parts);
                  const int end = PartBegin(n, part + 1, parts);
                  if (d == 2) {
                    BlockDiagonalDispatch<2>(V, Lambda, d, begin, end, out);
                  } else if (d == 3) {
                    BlockDiagonalDispatch<3>(V, Lambda, d, begin, end, out);
                  } else {
                    BlockDiagonalDispatch<Eigen::Dynamic>(V, Lambda, d, begin,
                                                          end, out);
                  }
                });
}

}  // namespace ceres_sesync::internal
