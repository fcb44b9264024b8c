#include "ceres_sesync/internal/sparse_cholesky_factor.h"

#include <algorithm>

#include "ceres_sesync/internal/parallel.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {

SparseCholeskyFactor::SparseCholeskyFactor(const cholmod_factor* factor,
                                           cholmod_common* common) {
  cholmod_factor* L =
      cholmod_copy_factor(const_cast<cholmod_factor*>(factor), common);
  CHECK(L != nullptr) << "out of memory copying the Cholesky factor";
  // Simplicial, LL^T, packed, monotonic: plain compressed columns, each
  // starting with its diagonal entry.
  CHECK(cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0,
                              /*to_packed=*/1, /*to_monotonic=*/1, L, common))
      << "cholmod_change_factor failed";
  n_ = static_cast<int>(L->n);
  const int* p = static_cast<const int*>(L->p);
  const int* row = static_cast<const int*>(L->i);
  const double* x = static_cast<const double*>(L->x);
  const int* perm = static_cast<const int*>(L->Perm);
  column_start_.resize(n_ + 1);
  inverse_diagonal_.resize(n_);
  permutation_.resize(n_);
  values_.reserve(p[n_] - n_);
  row_index_.reserve(p[n_] - n_);
  for (int j = 0; j < n_; ++j) {
    column_start_[j] = static_cast<int>(values_.size());
    CHECK_EQ(row[p[j]], j) << "factor column without leading diagonal";
    inverse_diagonal_[j] = 1.0 / x[p[j]];
    for (int k = p[j] + 1; k < p[j + 1]; ++k) {
      values_.push_back(x[k]);
      row_index_.push_back(row[k]);
    }
    permutation_[j] = perm != nullptr ? perm[j] : j;
  }
  column_start_[n_] = static_cast<int>(values_.size());
  cholmod_free_factor(&L, common);
}

// Column j of W is the r-vector w_j. Forward: L Z = W^T column by column
// (z_j = w_j / l_jj, then w_i -= l_ij z_j below the diagonal); backward:
// L^T X = Z (x_j = (z_j - sum_i l_ij x_i) / l_jj).
template <int R>
void SparseCholeskyFactor::SolveInPlace(int r, double* w) const {
  using Vector = Eigen::Matrix<double, R, 1>;
  using Map = Eigen::Map<Vector>;
  const int* start = column_start_.data();
  const int* row = row_index_.data();
  const double* value = values_.data();
  for (int j = 0; j < n_; ++j) {
    Map w_j(w + static_cast<std::ptrdiff_t>(j) * r, r);
    w_j *= inverse_diagonal_[j];
    for (int k = start[j]; k < start[j + 1]; ++k) {
      Map(w + static_cast<std::ptrdiff_t>(row[k]) * r, r) -= value[k] * w_j;
    }
  }
  Vector sum(r);
  for (int j = n_ - 1; j >= 0; --j) {
    Map w_j(w + static_cast<std::ptrdiff_t>(j) * r, r);
    sum = w_j;
    for (int k = start[j]; k < start[j + 1]; ++k) {
      sum -= value[k] * Map(w + static_cast<std::ptrdiff_t>(row[k]) * r, r);
    }
    w_j = sum * inverse_diagonal_[j];
  }
}

void SparseCholeskyFactor::SolvePermuted(int r, double* w) const {
  switch (r) {
    case 1:
      return SolveInPlace<1>(r, w);
    case 2:
      return SolveInPlace<2>(r, w);
    case 3:
      return SolveInPlace<3>(r, w);
    case 4:
      return SolveInPlace<4>(r, w);
    case 5:
      return SolveInPlace<5>(r, w);
    case 6:
      return SolveInPlace<6>(r, w);
    default:
      return SolveInPlace<Eigen::Dynamic>(r, w);
  }
}

void SparseCholeskyFactor::SolveRows(const Eigen::MatrixXd& B,
                                     Eigen::MatrixXd* X,
                                     int num_threads) const {
  SolveRowsTail(B, 0, X, num_threads);
}

void SparseCholeskyFactor::SolveRowsTail(const Eigen::MatrixXd& B, int offset,
                                         Eigen::MatrixXd* X,
                                         int num_threads) const {
  CHECK_EQ(offset + B.cols(), n_);
  const int r = static_cast<int>(B.rows());
  X->resize(r, B.cols());
  const double work = 4.0 * r * (values_.size() + n_);
  const int parts = std::min(r, ThreadsFor(num_threads, work));
  // Each part solves its own rows in a private contiguous workspace:
  // W = B P^T (with zero leading columns), solved, then X = W P.
  ParallelParts(parts, [&](int part, int num_parts) {
    const int row = PartBegin(r, part, num_parts);
    const int rows = PartBegin(r, part + 1, num_parts) - row;
    Eigen::MatrixXd W(rows, n_);
    for (int k = 0; k < n_; ++k) {
      const int source = permutation_[k] - offset;
      if (source >= 0) {
        W.col(k) = B.col(source).segment(row, rows);
      } else {
        W.col(k).setZero();
      }
    }
    SolvePermuted(rows, W.data());
    for (int k = 0; k < n_; ++k) {
      const int target = permutation_[k] - offset;
      if (target >= 0) X->col(target).segment(row, rows) = W.col(k);
    }
  });
}

}  // namespace ceres_sesync::internal
