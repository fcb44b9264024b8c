#include "ceres_sesync/internal/certificate_matrix.h"

#include <algorithm>
#include <limits>

#include "glog/logging.h"

namespace ceres_sesync::internal {

using Triplet = Eigen::Triplet<double>;
constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

namespace {

// A fill-reducing ordering of K from one of the pose graph: K has the pattern
// of the translational Laplacian with every vertex expanded into its
// translation (absent for vertex 0) and d rotation unknowns, so ordering the
// n vertices (1 / (d+1)^2 of K's entries) and expanding gives K's ordering at
// a fraction of the cost of ordering K itself.
std::vector<int> BlockOrdering(const SESyncProblem& problem) {
  const int n = problem.num_poses(), d = problem.dimension();
  const int t0 = n - 1;
  std::vector<int> ordering;
  ordering.reserve(t0 + d * n);
  for (int v : problem.vertex_ordering()) {
    if (v > 0) ordering.push_back(v - 1);
    for (int a = 0; a < d; ++a) ordering.push_back(t0 + d * v + a);
  }
  return ordering;
}

}  // namespace

CertificateMatrix::CertificateMatrix(const SESyncProblem& problem,
                                     bool strict_round_off)
    : strict_round_off_(strict_round_off),
      d_(problem.dimension()),
      n_(problem.num_poses()),
      translation_size_(problem.num_poses() - 1),
      rotation_size_(problem.dimension() * problem.num_poses()) {
  CHECK_LE(d_, 3);  // Assemble's row sums.
  const int t0 = translation_size_, d = d_;
  std::vector<Triplet> triplets;
  const SparseMatrix& L = problem.Lbar();
  const SparseMatrix& V = problem.Vbar();
  const SparseMatrix& D = problem.D();
  triplets.reserve(L.nonZeros() + V.nonZeros() + D.nonZeros() + n_ * d * d);
  for (int k = 0; k < L.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
      if (it.row() >= it.col())
        triplets.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (int k = 0; k < V.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(V, k); it; ++it) {
      triplets.emplace_back(t0 + it.col(), it.row(), -it.value());
    }
  }
  for (int k = 0; k < D.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(D, k); it; ++it) {
      if (it.row() >= it.col()) {
        triplets.emplace_back(t0 + it.row(), t0 + it.col(), it.value());
      }
    }
  }
  // Structural zeros for the full lower triangle of every diagonal block.
  for (int i = 0; i < n_; ++i) {
    for (int b = 0; b < d; ++b) {
      for (int a = b; a < d; ++a) {
        triplets.emplace_back(t0 + d * i + a, t0 + d * i + b, 0.0);
      }
    }
  }
  const int size = t0 + rotation_size_;
  K_.resize(size, size);
  K_.setFromTriplets(triplets.begin(), triplets.end());
  K_.makeCompressed();
  base_values_.assign(K_.valuePtr(), K_.valuePtr() + K_.nonZeros());
  translation_diagonal_.reserve(t0);
  for (int j = 0; j < t0; ++j) {
    // Lower triangle, sorted rows: the diagonal leads its column.
    const int k = K_.outerIndexPtr()[j];
    CHECK_EQ(K_.innerIndexPtr()[k], j);
    translation_diagonal_.push_back(k);
    max_translation_diagonal_ =
        std::max(max_translation_diagonal_, std::abs(base_values_[k]));
  }
  block_entry_.reserve(n_ * d * (d + 1) / 2);
  for (int i = 0; i < n_; ++i) {
    for (int b = 0; b < d; ++b) {
      const int col = t0 + d * i + b;
      const int* begin = K_.innerIndexPtr() + K_.outerIndexPtr()[col];
      const int* end = K_.innerIndexPtr() + K_.outerIndexPtr()[col + 1];
      for (int a = b; a < d; ++a) {
        const int* pos = std::lower_bound(begin, end, t0 + d * i + a);
        block_entry_.push_back(static_cast<int>(pos - K_.innerIndexPtr()));
      }
    }
  }
  // The translation rows of K's factor carry round-off of the size of
  // Lbar's own factorization (4-25x its bound on the benchmark datasets).
  if (strict_round_off_) translation_shift_ = 64 * problem.LbarBackwardError();
  ConfigureCholmod(CholmodLayout::kAutomatic, &factor_);
  factor_.AnalyzePatternWithOrdering(K_, BlockOrdering(problem));
}

void CertificateMatrix::Assemble(const Eigen::MatrixXd& Lambda, double c,
                                 double translation_shift,
                                 double* rotation_rounding) {
  std::copy(base_values_.begin(), base_values_.end(), K_.valuePtr());
  for (int k : translation_diagonal_) K_.valuePtr()[k] -= translation_shift;
  const int d = d_;
  double max_row = 0;
  int k = 0;
  for (int i = 0; i < n_; ++i) {
    double row_sum[3] = {0, 0, 0};
    for (int b = 0; b < d; ++b) {
      for (int a = b; a < d; ++a) {
        double& value = K_.valuePtr()[block_entry_[k++]];
        value -= Lambda(a, d * i + b);
        if (a == b) value += c;
        row_sum[a] += std::abs(value);
        if (a != b) row_sum[b] += std::abs(value);
      }
    }
    for (int a = 0; a < d; ++a) max_row = std::max(max_row, row_sum[a]);
  }
  // Two roundings per entry (- Lambda, + c): each assembled entry is within
  // 2u (|entry| + c) of its exact value (4u to cover second-order terms);
  // Gershgorin over the d x d blocks.
  *rotation_rounding = 4 * kUnitRoundoff * (max_row + c);
}

bool CertificateMatrix::Factorize(const Eigen::MatrixXd& Lambda, double c,
                                  bool bound_backward_error) {
  if (!bound_backward_error) {
    double unused;
    Assemble(Lambda, c, 0, &unused);
    factorized_shift_ = 0;
    factor_.factorize(K_);
    backward_error_ = proven_shift_ = std::numeric_limits<double>::quiet_NaN();
    return factor_.info() == Eigen::Success;
  }
  // Strict: with K' = K_c - diag(mu I, 0) factorized, the backward error
  // bounds give K' + diag(h I, t I) >= 0 (CholmodFactor::BackwardErrorBound,
  // plus the rounding of the assembly). If h <= mu, then
  // [Lbar, -Vbar; -Vbar^T, D - Lambda + (c + t) I] >= 0, whose Schur
  // complement is S + (c + t) I: lambda_min(S) >= -(c + t), with no error
  // amplified through Lbar^{-1}. mu starts from 64x Lbar's own error bound
  // and grows to twice any bound h that exceeded it. Default (mu = 0): the
  // same bounds, max(h, t) added to c, which proves K_c + max(h, t) I >= 0.
  for (int attempt = 0; attempt < 3; ++attempt) {
    const double mu = strict_round_off_ ? translation_shift_ : 0;
    double rotation_rounding = 0;
    Assemble(Lambda, c, mu, &rotation_rounding);
    factorized_shift_ = mu;
    factor_.factorize(K_);
    if (factor_.info() != Eigen::Success) return false;
    double head = 0, tail = 0;
    factor_.BackwardErrorBound(translation_size_, &head, &tail);
    head += 4 * kUnitRoundoff * (max_translation_diagonal_ + mu);
    tail += rotation_rounding;
    if (!strict_round_off_ || head <= mu) {
      backward_error_ = strict_round_off_ ? tail : std::max(head, tail);
      proven_shift_ = c + backward_error_;
      VLOG(1) << "K_c factorized: c " << c << " backward error "
              << backward_error_ << " (translation rows " << head << ", shift "
              << mu << ")";
      return true;
    }
    translation_shift_ = 2 * head;
  }
  LOG(WARNING) << "certificate matrix: the translation block's round-off "
                  "bound did not settle; no proof from this factorization";
  return false;
}

void CertificateMatrix::SolveShifted(const Eigen::VectorXd& y,
                                     Eigen::VectorXd* x) const {
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(K_.rows());
  rhs.tail(rotation_size_) = y;
  *x = factor_.solve(rhs).tail(rotation_size_);
}

void CertificateMatrix::SolveShifted(const Eigen::MatrixXd& Y,
                                     Eigen::MatrixXd* X) const {
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(K_.rows(), Y.cols());
  rhs.bottomRows(rotation_size_) = Y;
  *X = factor_.solve(rhs).bottomRows(rotation_size_);
}

}  // namespace ceres_sesync::internal
