#include "ceres_sesync/internal/extended_cholesky.h"

#include <algorithm>
#include <cmath>

#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

// Inputs and pivots are kept within [2^-900, 2^900] in magnitude (or zero),
// so that no reciprocal overflows; an operation that underflows on the way
// errs by at most 2^-1070 in absolute terms, which RowBackwardErrorBounds()
// adds (Higham's model with underflow, eq. 2.8).
constexpr double kSmallestSafeValue = 0x1p-900;
constexpr double kLargestSafeValue = 0x1p900;
constexpr double kUnderflowError = 0x1p-1070;

bool Safe(const DoubleDouble& x) {
  const double a = std::abs(x.hi);
  return a == 0 || (a >= kSmallestSafeValue && a <= kLargestSafeValue);
}

// The numerical phase, cloned for CPUs with and without FMA instructions (the
// FMA is std::fma either way, so results are identical; the clone only makes
// it an instruction instead of a library call).
__attribute__((target_clones("fma", "default"))) bool FactorizeRows(
    int n, const int* column_start, const int* row_index,
    const DoubleDouble* values, const int* parent, const int* factor_start,
    int* factor_row, DoubleDouble* factor_value, int* fill) {
  std::vector<DoubleDouble> y(n);
  std::vector<DoubleDouble> inverse_diagonal(n);
  std::vector<int> pattern(n), mark(n, -1);
  std::fill(fill, fill + n, 0);
  for (int k = 0; k < n; ++k) {
    // Nonzero pattern of row k of L: the elimination-tree reach of A(:, k),
    // in topological order, and A(0:k, k) scattered into y.
    int top = n;
    mark[k] = k;
    DoubleDouble d;
    for (int p = column_start[k]; p < column_start[k + 1]; ++p) {
      int i = row_index[p];
      if (i == k) {
        d = values[p];
        continue;
      }
      y[i] = values[p];
      int len = 0;
      for (; mark[i] != k; i = parent[i]) {
        pattern[len++] = i;
        mark[i] = k;
      }
      while (len > 0) pattern[--top] = pattern[--len];
    }
    // Row k: l_ki = (a_ki - sum_{j<i} l_kj l_ij) / l_ii in topological order.
    for (; top < n; ++top) {
      const int i = pattern[top];
      const DoubleDouble l_ki = y[i] * inverse_diagonal[i];
      y[i] = DoubleDouble();
      const int begin = factor_start[i] + 1;  // Below the diagonal.
      const int end = factor_start[i] + fill[i];
      for (int p = begin; p < end; ++p) {
        DoubleDouble& target = y[factor_row[p]];
        target = AccumulateSubtract(target, factor_value[p] * l_ki);
      }
      d = AccumulateSubtract(d, l_ki * l_ki);
      const int q = factor_start[i] + fill[i]++;
      factor_row[q] = k;
      factor_value[q] = l_ki;
    }
    if (!(d.hi > 0) || !Safe(d)) return false;
    const DoubleDouble l_kk = Sqrt(d);
    const int q = factor_start[k] + fill[k]++;
    factor_row[q] = k;
    factor_value[q] = l_kk;
    inverse_diagonal[k] = Reciprocal(l_kk);
  }
  return true;
}

}  // namespace

void DoubleDoubleCholesky::Analyze(int n, std::vector<int> column_start,
                                   std::vector<int> row_index) {
  n_ = n;
  column_start_ = std::move(column_start);
  row_index_ = std::move(row_index);
  CHECK_EQ(static_cast<int>(column_start_.size()), n + 1);
  // Elimination tree (Liu's algorithm with path compression through
  // `ancestor`).
  parent_.assign(n, -1);
  std::vector<int> ancestor(n, -1);
  for (int k = 0; k < n; ++k) {
    for (int p = column_start_[k]; p < column_start_[k + 1]; ++p) {
      for (int i = row_index_[p]; i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) parent_[i] = k;
        i = next;
      }
    }
  }
  // Column counts of L by one symbolic up-looking pass (every row's reach).
  std::vector<int> count(n, 1), mark(n, -1);
  row_count_.assign(n, 1);
  for (int k = 0; k < n; ++k) {
    mark[k] = k;
    for (int p = column_start_[k]; p < column_start_[k + 1]; ++p) {
      for (int i = row_index_[p]; mark[i] != k; i = parent_[i]) {
        mark[i] = k;
        ++count[i];
        ++row_count_[k];
      }
    }
  }
  factor_start_.assign(n + 1, 0);
  flops_ = 0;
  for (int k = 0; k < n; ++k) {
    factor_start_[k + 1] = factor_start_[k] + count[k];
    flops_ += 0.5 * count[k] * static_cast<double>(count[k]);
  }
  factor_row_.resize(factor_start_[n]);
  factor_value_.resize(factor_start_[n]);
  factorized_ = false;
}

bool DoubleDoubleCholesky::Factorize(const std::vector<DoubleDouble>& values) {
  CHECK_EQ(values.size(), row_index_.size());
  for (const DoubleDouble& v : values) {
    if (!Safe(v)) return factorized_ = false;
  }
  std::vector<int> fill(n_);
  factorized_ =
      FactorizeRows(n_, column_start_.data(), row_index_.data(), values.data(),
                    parent_.data(), factor_start_.data(), factor_row_.data(),
                    factor_value_.data(), fill.data());
  return factorized_;
}

void DoubleDoubleCholesky::RowBackwardErrorBounds(
    std::vector<double>* rho) const {
  CHECK(factorized_);
  // v_i = sum_j (|L| |L^T|)_ij = sum_c |L_ic| s_c with s_c the column sums
  // of |L|. Every |L| value is rounded up (AbsUpperBound), and a computed sum
  // of m nonnegative doubles is within gamma_m (double) of the exact one, so
  // the factor (1 + 1e-6) covers the rounding of this computation for up to
  // 10^9 terms (gamma_{10^9} < 1.2e-7).
  std::vector<double> column_sum(n_, 0.0), v(n_, 0.0);
  for (int c = 0; c < n_; ++c) {
    for (int p = factor_start_[c]; p < factor_start_[c + 1]; ++p) {
      column_sum[c] += factor_value_[p].AbsUpperBound();
    }
  }
  for (int c = 0; c < n_; ++c) {
    for (int p = factor_start_[c]; p < factor_start_[c + 1]; ++p) {
      v[factor_row_[p]] += factor_value_[p].AbsUpperBound() * column_sum[c];
    }
  }
  // Underflow: every entry is computed with at most max_count + 2
  // operations, each erring by at most kUnderflowError absolutely, scaled by
  // the pivot l_jj it is multiplied with (the backward error of l_ij is
  // l_jj times its forward error).
  int max_count = 0;
  double max_pivot = 1;
  for (int c = 0; c < n_; ++c) {
    max_count = std::max(max_count, row_count_[c]);
    max_pivot =
        std::max(max_pivot, factor_value_[factor_start_[c]].AbsUpperBound());
  }
  const double underflow_per_entry =
      (max_count + 2.0) * kUnderflowError * max_pivot * (1 + 1e-6);
  rho->resize(n_);
  for (int i = 0; i < n_; ++i) {
    const double entries =
        row_count_[i] + (factor_start_[i + 1] - factor_start_[i]);
    (*rho)[i] = DoubleDoubleGamma(row_count_[i] + 1) * v[i] * (1 + 1e-6) +
                entries * underflow_per_entry;
  }
}

}  // namespace ceres_sesync::internal
