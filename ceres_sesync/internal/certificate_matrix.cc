#include "ceres_sesync/internal/certificate_matrix.h"

#include <algorithm>
#include <limits>

#include "glog/logging.h"

namespace ceres_sesync::internal {

using Triplet = Eigen::Triplet<double>;

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

CertificateMatrix::CertificateMatrix(const SESyncProblem& problem)
    : d_(problem.dimension()),
      n_(problem.num_poses()),
      translation_size_(problem.num_poses() - 1),
      rotation_size_(problem.dimension() * problem.num_poses()) {
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
  ConfigureCholmod(CholmodLayout::kAutomatic, &factor_);
  factor_.AnalyzePatternWithOrdering(K_, BlockOrdering(problem));
}

bool CertificateMatrix::Factorize(const Eigen::MatrixXd& Lambda, double c,
                                  bool bound_backward_error) {
  std::copy(base_values_.begin(), base_values_.end(), K_.valuePtr());
  const int d = d_;
  int k = 0;
  for (int i = 0; i < n_; ++i) {
    for (int b = 0; b < d; ++b) {
      for (int a = b; a < d; ++a) {
        double& value = K_.valuePtr()[block_entry_[k++]];
        value -= Lambda(a, d * i + b);
        if (a == b) value += c;
      }
    }
  }
  factor_.factorize(K_);
  if (factor_.info() != Eigen::Success) return false;
  if (!bound_backward_error) {
    backward_error_ = proven_shift_ = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  backward_error_ = factor_.BackwardErrorBound();
  proven_shift_ = c + backward_error_;
  VLOG(1) << "K_c factorized: c " << c << " backward error " << backward_error_;
  return true;
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
