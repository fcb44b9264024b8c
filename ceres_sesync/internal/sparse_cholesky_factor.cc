#include "ceres_sesync/internal/sparse_cholesky_factor.h"

#include <algorithm>
#include <functional>
#include <numeric>
#include <type_traits>
#include <utility>

#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/tree_split.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

// Calls column(j, diagonal, rows, values) for j = 0 .. n-1 with column j of
// the LL^T factor L: its diagonal entry and its entries below the diagonal
// (ascending rows), read in place from a supernodal or simplicial factor.
template <typename Column>
void ForEachColumn(const cholmod_factor& L, Column column) {
  std::vector<int> rows;
  std::vector<double> values;
  const double* x = static_cast<const double*>(L.x);
  if (L.is_super) {
    const auto* super = static_cast<const int*>(L.super);
    const auto* pi = static_cast<const int*>(L.pi);
    const auto* px = static_cast<const int*>(L.px);
    const auto* s = static_cast<const int*>(L.s);
    for (size_t k = 0; k < L.nsuper; ++k) {
      const int height = pi[k + 1] - pi[k];
      const int* row = s + pi[k];
      for (int jj = 0; jj < super[k + 1] - super[k]; ++jj) {
        const int j = super[k] + jj;
        const double* col = x + px[k] + static_cast<size_t>(jj) * height;
        CHECK_EQ(row[jj], j) << "supernode without leading diagonal";
        rows.assign(row + jj + 1, row + height);
        values.assign(col + jj + 1, col + height);
        column(j, col[jj], &rows, &values);
      }
    }
    return;
  }
  const auto* p = static_cast<const int*>(L.p);
  const auto* nz = static_cast<const int*>(L.nz);
  const auto* row = static_cast<const int*>(L.i);
  for (int j = 0; j < static_cast<int>(L.n); ++j) {
    const int begin = p[j], end = p[j] + nz[j];
    CHECK(end > begin && row[begin] == j)
        << "factor column without leading diagonal";
    rows.assign(row + begin + 1, row + end);
    values.assign(x + begin + 1, x + end);
    column(j, x[begin], &rows, &values);
  }
}

}  // namespace

SparseCholeskyFactor::SparseCholeskyFactor(const cholmod_factor* factor,
                                           cholmod_common* common) {
  CHECK(factor != nullptr && factor->xtype == CHOLMOD_REAL)
      << "no real numeric factor";
  cholmod_factor* converted = nullptr;
  const cholmod_factor* L = factor;
  if (!factor->is_super && !factor->is_ll) {
    // Simplicial LDL^T: a converted copy (LL^T, packed).
    converted =
        cholmod_copy_factor(const_cast<cholmod_factor*>(factor), common);
    CHECK(converted != nullptr) << "out of memory copying the factor";
    CHECK(cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0,
                                /*to_packed=*/1, /*to_monotonic=*/1, converted,
                                common))
        << "cholmod_change_factor failed";
    L = converted;
  }
  const int n = static_cast<int>(L->n);
  const int* perm = static_cast<const int*>(L->Perm);
  std::vector<int> permutation(n);
  for (int j = 0; j < n; ++j) permutation[j] = perm != nullptr ? perm[j] : j;
  Build(std::move(permutation),
        [L](const ColumnVisitor& column) { ForEachColumn(*L, column); });
  if (converted != nullptr) cholmod_free_factor(&converted, common);
}

namespace {

// The stored values of a supernode of c columns and nrows rows given as
// its nrows x c block x (column-major): the triangle row by row with the
// reciprocal of each diagonal entry, then the rectangle row by row, each
// passed to store(value) in that order.
template <typename Store>
void StoreSupernodeValues(int c, int nrows, const double* x, Store&& store) {
  auto at = [x, nrows](int i, int k) {
    return x[i + static_cast<int64_t>(k) * nrows];
  };
  for (int k = 0; k < c; ++k) {
    for (int q = 0; q < k; ++q) store(at(k, q));
    store(1.0 / at(k, k));
  }
  for (int i = c; i < nrows; ++i) {
    for (int k = 0; k < c; ++k) store(at(i, k));
  }
}

}  // namespace

SparseCholeskyFactor::SparseCholeskyFactor(
    std::vector<int> permutation,
    const std::function<void(const SupernodeVisitor&)>& for_each_supernode) {
  n_ = static_cast<int>(permutation.size());
  permutation_ = std::move(permutation);
  // Two passes: the first counts what the second stores.
  int64_t num_values = 0, num_rows = 0, num_supernodes = 0;
  for_each_supernode([&](int, int c, const int*, int nrows, const double*) {
    const int64_t nb = nrows - c;
    num_values += static_cast<int64_t>(c) * (c + 1) / 2 + nb * c;
    num_rows += nb;
    ++num_supernodes;
  });
  values_.reserve(num_values);
  row_index_.reserve(num_rows);
  first_.reserve(num_supernodes + 1);
  rows_.reserve(num_supernodes);
  int next = 0;  // The first column of the next supernode.
  for_each_supernode(
      [&](int first, int c, const int* rows, int nrows, const double* x) {
        CHECK_EQ(first, next) << "supernodes out of order";
        next = first + c;
        first_.push_back(first);
        rows_.push_back(nrows - c);
        row_index_.insert(row_index_.end(), rows + c, rows + nrows);
        StoreSupernodeValues(c, nrows, x,
                             [this](double v) { values_.push_back(v); });
      });
  CHECK_EQ(next, n_) << "supernodes do not cover the columns";
  stored_entries_ = num_values;
  first_.push_back(n_);
  BuildSchedule();
}

void SparseCholeskyFactor::RefreshValues(
    const std::function<void(const SupernodeVisitor&)>& for_each_supernode) {
  CHECK(!single_precision()) << "RefreshValues() of a single-precision factor";
  size_t at = 0;
  int s = 0;
  for_each_supernode(
      [&](int first, int c, const int*, int nrows, const double* x) {
        CHECK(s < num_supernodes() && first_[s] == first &&
              first_[s + 1] - first == c && rows_[s] == nrows - c)
            << "RefreshValues() with other supernodes";
        ++s;
        StoreSupernodeValues(c, nrows, x,
                             [this, &at](double v) { values_[at++] = v; });
      });
  CHECK(s == num_supernodes() && at == values_.size())
      << "RefreshValues() with other supernodes";
}

void SparseCholeskyFactor::Build(
    std::vector<int> permutation,
    const std::function<void(const ColumnVisitor&)>& for_each_column) {
  n_ = static_cast<int>(permutation.size());
  permutation_ = std::move(permutation);
  // Two passes over L: the first counts what the second stores (so the
  // arrays are allocated once, at their final size).
  int64_t num_values = 0, num_rows = 0, num_supernodes = 0;
  for (const bool fill : {false, true}) {
    if (fill) {
      values_.reserve(num_values);
      row_index_.reserve(num_rows);
      first_.reserve(num_supernodes + 1);
      rows_.reserve(num_supernodes);
    }
    // The current supernode: columns j0 .. j0 + c - 1, the below-diagonal
    // rows of its first column (`pattern`), its columns' diagonals and values.
    int j0 = 0, c = 0;
    std::vector<int> pattern;
    std::vector<double> diagonal;
    std::vector<std::vector<double>> columns;
    std::vector<int> previous;  // Below-diagonal rows of column j - 1.
    auto flush = [&] {
      if (c == 0) return;
      // Column k's below rows are pattern[k..]: the triangle rows j0+k+1 ..
      // j0+c-1, then the rectangle rows pattern[c-1..].
      const int nb = static_cast<int>(pattern.size()) - (c - 1);
      const int64_t entries =
          static_cast<int64_t>(c) * (c + 1) / 2 + static_cast<int64_t>(nb) * c;
      if (!fill) {
        num_values += entries;
        num_rows += nb;
        ++num_supernodes;
      } else {
        first_.push_back(j0);
        rows_.push_back(nb);
        row_index_.insert(row_index_.end(), pattern.begin() + (c - 1),
                          pattern.end());
        for (int k = 0; k < c; ++k) {
          for (int q = 0; q < k; ++q) values_.push_back(columns[q][k - q - 1]);
          values_.push_back(1.0 / diagonal[k]);
        }
        for (int i = 0; i < nb; ++i) {
          for (int k = 0; k < c; ++k) {
            values_.push_back(columns[k][(c - 1 - k) + i]);
          }
        }
        stored_entries_ += entries;
      }
      c = 0;
      columns.clear();
      diagonal.clear();
    };
    for_each_column([&](int j, double diag, std::vector<int>* rows,
                        std::vector<double>* values) {
      // Sort by row (CHOLMOD's columns are sorted already; cheap to check),
      // then drop exact zeros: structural zeros of relaxed supernodes.
      if (!std::is_sorted(rows->begin(), rows->end())) {
        std::vector<int> order(rows->size());
        std::iota(order.begin(), order.end(), 0);
        std::sort(order.begin(), order.end(),
                  [&](int a, int b) { return (*rows)[a] < (*rows)[b]; });
        std::vector<int> r(rows->size());
        std::vector<double> v(rows->size());
        for (size_t k = 0; k < order.size(); ++k) {
          r[k] = (*rows)[order[k]];
          v[k] = (*values)[order[k]];
        }
        *rows = std::move(r);
        *values = std::move(v);
      }
      size_t kept = 0;
      for (size_t k = 0; k < rows->size(); ++k) {
        if ((*values)[k] != 0.0) {
          (*rows)[kept] = (*rows)[k];
          (*values)[kept] = (*values)[k];
          ++kept;
        }
      }
      rows->resize(kept);
      values->resize(kept);
      // Column j continues the supernode iff column j - 1's rows are {j}
      // and then exactly column j's rows.
      const bool joins =
          c > 0 && !previous.empty() && previous[0] == j &&
          previous.size() == rows->size() + 1 &&
          std::equal(rows->begin(), rows->end(), previous.begin() + 1);
      if (!joins) {
        flush();
        j0 = j;
        pattern = *rows;
      }
      ++c;
      diagonal.push_back(diag);
      if (fill) columns.push_back(*values);
      previous = *rows;
    });
    flush();
  }
  first_.push_back(n_);
  BuildSchedule();
}

void SparseCholeskyFactor::ConvertToSinglePrecision() {
  if (single_precision() || values_.empty()) return;
  values_float_.assign(values_.begin(), values_.end());
  std::vector<double>().swap(values_);
}

int64_t SparseCholeskyFactor::memory_bytes() const {
  return static_cast<int64_t>(values_.size()) * sizeof(double) +
         static_cast<int64_t>(values_float_.size()) * sizeof(float) +
         static_cast<int64_t>(row_index_.size() + first_.size() + rows_.size() +
                              permutation_.size() + order_.size() +
                              top_columns_.size()) *
             sizeof(int) +
         static_cast<int64_t>(value_begin_.size() + row_begin_.size()) *
             sizeof(int64_t);
}

int64_t SparseCholeskyFactor::top_entries() const {
  int64_t entries = 0;
  for (int k = num_bins() > 0 ? bin_end_.back() : 0;
       k < static_cast<int>(order_.size()); ++k) {
    const int64_t c = first_[order_[k] + 1] - first_[order_[k]];
    entries += c * (c + 1) / 2 + c * rows_[order_[k]];
  }
  return entries;
}

namespace {

// Factors with fewer stored entries are solved unsplit: a solve with r rows
// is ~4 r entries of work, below the parallel threshold of ThreadsFor() (1e7)
// for every r <= 10 here, where a split only adds bookkeeping.
constexpr int64_t kMinSplitEntries = 1 << 18;
// A split is kept only if its critical path (top + heaviest bin, in stored
// entries) is at most this fraction of the whole factor.
constexpr double kMaxSplitCriticalPath = 0.8;

}  // namespace

void SparseCholeskyFactor::BuildSchedule() {
  const int num_supernodes = static_cast<int>(rows_.size());
  value_begin_.resize(num_supernodes);
  row_begin_.resize(num_supernodes);
  std::vector<double> weight(num_supernodes);
  int64_t value_offset = 0, row_offset = 0;
  for (int s = 0; s < num_supernodes; ++s) {
    const int64_t c = first_[s + 1] - first_[s];
    value_begin_[s] = value_offset;
    row_begin_[s] = row_offset;
    const int64_t entries = c * (c + 1) / 2 + c * rows_[s];
    weight[s] = static_cast<double>(entries);
    value_offset += entries;
    row_offset += rows_[s];
  }
  // Unsplit: everything is top.
  order_.resize(num_supernodes);
  std::iota(order_.begin(), order_.end(), 0);
  bin_end_.clear();
  top_columns_.resize(n_);
  std::iota(top_columns_.begin(), top_columns_.end(), 0);
  if (stored_entries_ < kMinSplitEntries) return;

  // The supernodal elimination tree: the parent of s holds the first row
  // below s (the rows of a supernode are ascending and all beyond it, so
  // parents follow their children in the supernode order).
  std::vector<int> supernode_of(n_);
  for (int s = 0; s < num_supernodes; ++s) {
    std::fill(supernode_of.begin() + first_[s],
              supernode_of.begin() + first_[s + 1], s);
  }
  std::vector<int> parent(num_supernodes, -1);
  for (int s = 0; s < num_supernodes; ++s) {
    if (rows_[s] > 0) parent[s] = supernode_of[row_index_[row_begin_[s]]];
  }
  const TreeSplit split =
      SplitTree(parent, weight, kTreeSplitBins, kMaxSplitCriticalPath);
  VLOG(2) << "solve schedule: top " << split.top_weight << " of "
          << split.total_weight << " stored entries, heaviest bin "
          << split.heaviest_bin << (split.bin.empty() ? " (not split)" : "");
  if (split.bin.empty()) return;
  const std::vector<int>& bin = split.bin;

  // The schedule, and the bins' row indices of top rows redirected to their
  // accumulators.
  order_.clear();
  top_columns_.clear();
  for (int b = 0; b < kTreeSplitBins; ++b) {
    for (int s = 0; s < num_supernodes; ++s) {
      if (bin[s] == b) order_.push_back(s);
    }
    bin_end_.push_back(static_cast<int>(order_.size()));
  }
  std::vector<int> slot(n_, -1);
  for (int s = 0; s < num_supernodes; ++s) {
    if (bin[s] != -1) continue;
    order_.push_back(s);
    for (int j = first_[s]; j < first_[s + 1]; ++j) {
      slot[j] = static_cast<int>(top_columns_.size());
      top_columns_.push_back(j);
    }
  }
  const int num_top = static_cast<int>(top_columns_.size());
  for (int s = 0; s < num_supernodes; ++s) {
    if (bin[s] < 0) continue;
    int* rows = row_index_.data() + row_begin_[s];
    for (int i = 0; i < rows_[s]; ++i) {
      const int b = bin[supernode_of[rows[i]]];
      CHECK(b == bin[s] || b == -1) << "a bin's row in another bin";
      if (b == -1) rows[i] = n_ + bin[s] * num_top + slot[rows[i]];
    }
  }
}

namespace {

// One supernode of the solves on W (r rows, column j = the r-vector w_j at
// w + j * ld): columns j0 .. j0 + c - 1, `nb` rows `below`, values as
// documented in the header. C is c when fixed at compile time (then the
// supernode's r x c block of W is held in registers across its rows), else
// Eigen::Dynamic. Forward, L Z = W^T: z_k = (w_k - sum_q L(k, q) z_q) / L(k,
// k) within the supernode, then w_i -= sum_k L(i, k) z_k for every row i
// below. `scratch` holds r doubles (the row sums of a dynamic R, so that no
// supernode allocates).
template <typename Scalar, int R, int C>
EIGEN_ALWAYS_INLINE void ForwardSupernode(const Scalar* v, const int* below,
                                          int nb, int c, int r, int ld, int j0,
                                          double* w, double* scratch) {
  using Map = Eigen::Map<Eigen::Matrix<double, R, 1>>;
  auto column = [&](int j) {
    return Map(w + static_cast<std::ptrdiff_t>(j) * ld, r);
  };
  for (int k = 0; k < c; ++k) {
    Map w_k = column(j0 + k);
    for (int q = 0; q < k; ++q) {
      w_k -= static_cast<double>(v[q]) * column(j0 + q);
    }
    w_k *= static_cast<double>(v[k]);
    v += k + 1;
  }
  if constexpr (R != Eigen::Dynamic && C != Eigen::Dynamic) {
    const Eigen::Matrix<double, R, C> Z =
        Eigen::Map<const Eigen::Matrix<double, R, C>, 0, Eigen::OuterStride<>>(
            w + static_cast<std::ptrdiff_t>(j0) * ld, Eigen::OuterStride<>(ld));
    // The same operations in the same order as the generic loop below
    // (results must not depend on how the rows were split).
    if constexpr (C == 1) {
      for (int i = 0; i < nb; ++i) {
        column(below[i]) -= static_cast<double>(v[i]) * Z.col(0);
      }
    } else {
      for (int i = 0; i < nb; ++i, v += C) {
        Eigen::Matrix<double, R, 1> sum = static_cast<double>(v[0]) * Z.col(0);
        for (int k = 1; k < C; ++k) {
          sum += static_cast<double>(v[k]) * Z.col(k);
        }
        column(below[i]) -= sum;
      }
    }
  } else {
    auto rows = [&](auto&& sum) {
      for (int i = 0; i < nb; ++i, v += c) {
        sum = static_cast<double>(v[0]) * column(j0);
        for (int k = 1; k < c; ++k) {
          sum += static_cast<double>(v[k]) * column(j0 + k);
        }
        column(below[i]) -= sum;
      }
    };
    if constexpr (R == Eigen::Dynamic) {
      rows(Map(scratch, r));
    } else {
      rows(Eigen::Matrix<double, R, 1>());
    }
  }
}

// Backward, L^T X = Z, for the supernode whose values start at `v`: the rows
// below (already solved) are subtracted from its columns, then its triangle
// is solved from its last column.
template <typename Scalar, int R, int C>
EIGEN_ALWAYS_INLINE void BackwardSupernode(const Scalar* v, const int* below,
                                           int nb, int c, int r, int ld, int j0,
                                           double* w) {
  using Map = Eigen::Map<Eigen::Matrix<double, R, 1>>;
  auto column = [&](int j) {
    return Map(w + static_cast<std::ptrdiff_t>(j) * ld, r);
  };
  const Scalar* rectangle = v + static_cast<std::ptrdiff_t>(c) * (c + 1) / 2;
  if constexpr (R != Eigen::Dynamic && C != Eigen::Dynamic) {
    Eigen::Map<Eigen::Matrix<double, R, C>, 0, Eigen::OuterStride<>> block(
        w + static_cast<std::ptrdiff_t>(j0) * ld, Eigen::OuterStride<>(ld));
    Eigen::Matrix<double, R, C> sum = block;
    for (int i = 0; i < nb; ++i, rectangle += C) {
      const Map w_i = column(below[i]);
      for (int k = 0; k < C; ++k) {
        sum.col(k) -= static_cast<double>(rectangle[k]) * w_i;
      }
    }
    block = sum;
  } else {
    for (int i = 0; i < nb; ++i, rectangle += c) {
      const Map w_i = column(below[i]);
      for (int k = 0; k < c; ++k) {
        column(j0 + k) -= static_cast<double>(rectangle[k]) * w_i;
      }
    }
  }
  for (int k = c - 1; k >= 0; --k) {
    const Scalar* row = v + static_cast<std::ptrdiff_t>(k) * (k + 1) / 2;
    Map w_k = column(j0 + k);
    w_k *= static_cast<double>(row[k]);
    for (int q = 0; q < k; ++q) {
      column(j0 + q) -= static_cast<double>(row[q]) * w_k;
    }
  }
}

}  // namespace

template <typename Scalar, int R>
void SparseCholeskyFactor::Forward(const Scalar* values, int begin, int end,
                                   int r, int ld, double* w) const {
  constexpr int kDynamic = Eigen::Dynamic;
  using Map = Eigen::Map<Eigen::Matrix<double, R, 1>>;
  // Row sums of a dynamic R (fixed sizes live in registers).
  Eigen::VectorXd scratch(R == kDynamic ? r : 0);
  for (int k = begin; k < end; ++k) {
    const int s = order_[k];
    const int j0 = first_[s], c = first_[s + 1] - j0, nb = rows_[s];
    const Scalar* v = values + value_begin_[s];
    const int* below = row_index_.data() + row_begin_[s];
    if (c == 1) {  // The common case of sparse factors, kept tight.
      Map w_j(w + static_cast<std::ptrdiff_t>(j0) * ld, r);
      w_j *= static_cast<double>(v[0]);
      for (int i = 0; i < nb; ++i) {
        Map(w + static_cast<std::ptrdiff_t>(below[i]) * ld, r) -=
            static_cast<double>(v[1 + i]) * w_j;
      }
      continue;
    }
    switch (R == kDynamic ? 0 : c) {
      case 2:
        ForwardSupernode<Scalar, R, 2>(v, below, nb, c, r, ld, j0, w,
                                       scratch.data());
        break;
      case 3:
        ForwardSupernode<Scalar, R, 3>(v, below, nb, c, r, ld, j0, w,
                                       scratch.data());
        break;
      case 4:
        ForwardSupernode<Scalar, R, 4>(v, below, nb, c, r, ld, j0, w,
                                       scratch.data());
        break;
      default:
        ForwardSupernode<Scalar, R, kDynamic>(v, below, nb, c, r, ld, j0, w,
                                              scratch.data());
    }
  }
}

template <typename Scalar, int R>
void SparseCholeskyFactor::Backward(const Scalar* values, int begin, int end,
                                    int r, int ld, double* w) const {
  constexpr int kDynamic = Eigen::Dynamic;
  using Vector = Eigen::Matrix<double, R, 1>;
  using Map = Eigen::Map<Vector>;
  Eigen::VectorXd scratch(R == kDynamic ? r : 0);
  for (int k = end - 1; k >= begin; --k) {
    const int s = order_[k];
    const int j0 = first_[s], c = first_[s + 1] - j0, nb = rows_[s];
    const Scalar* v = values + value_begin_[s];
    const int* below = row_index_.data() + row_begin_[s];
    if (c == 1) {
      Map w_j(w + static_cast<std::ptrdiff_t>(j0) * ld, r);
      auto solve = [&](auto&& sum) {
        sum = w_j;
        for (int i = 0; i < nb; ++i) {
          sum -= static_cast<double>(v[1 + i]) *
                 Map(w + static_cast<std::ptrdiff_t>(below[i]) * ld, r);
        }
        w_j = sum * static_cast<double>(v[0]);
      };
      if constexpr (R == kDynamic) {
        solve(Map(scratch.data(), r));
      } else {
        solve(Vector());
      }
      continue;
    }
    switch (R == kDynamic ? 0 : c) {
      case 2:
        BackwardSupernode<Scalar, R, 2>(v, below, nb, c, r, ld, j0, w);
        break;
      case 3:
        BackwardSupernode<Scalar, R, 3>(v, below, nb, c, r, ld, j0, w);
        break;
      case 4:
        BackwardSupernode<Scalar, R, 4>(v, below, nb, c, r, ld, j0, w);
        break;
      default:
        BackwardSupernode<Scalar, R, kDynamic>(v, below, nb, c, r, ld, j0, w);
    }
  }
}

template <typename Scalar>
void SparseCholeskyFactor::SolvePhase(bool forward, const Scalar* values,
                                      int begin, int end, int r, int ld,
                                      double* w) const {
  auto run = [&](auto fixed_rows) {
    constexpr int R = decltype(fixed_rows)::value;
    if (forward) {
      Forward<Scalar, R>(values, begin, end, r, ld, w);
    } else {
      Backward<Scalar, R>(values, begin, end, r, ld, w);
    }
  };
  switch (r) {
    case 1:
      return run(std::integral_constant<int, 1>());
    case 2:
      return run(std::integral_constant<int, 2>());
    case 3:
      return run(std::integral_constant<int, 3>());
    case 4:
      return run(std::integral_constant<int, 4>());
    case 5:
      return run(std::integral_constant<int, 5>());
    case 6:
      return run(std::integral_constant<int, 6>());
    default:
      return run(std::integral_constant<int, Eigen::Dynamic>());
  }
}

void SparseCholeskyFactor::SolvePhase(bool forward, int begin, int end, int r,
                                      int ld, double* w) const {
  if (single_precision()) {
    SolvePhase(forward, values_float_.data(), begin, end, r, ld, w);
  } else {
    SolvePhase(forward, values_.data(), begin, end, r, ld, w);
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
  const int threads = ThreadsFor(num_threads, 4.0 * r * stored_entries_);
  const int num_bins = static_cast<int>(bin_end_.size());
  const int num_top = static_cast<int>(top_columns_.size());
  // W = B P^T (with zero leading columns), then the bins' accumulators.
  Eigen::MatrixXd W(r, n_ + num_bins * num_top);
  // Column copies as plain loops: r is small (the rank), and Eigen's
  // dynamic-length column assignment costs more in alignment handling than
  // the copy itself (measured: ~5% of a 2D dataset's solve).
  const std::ptrdiff_t ldr = r;
  for (int k = 0; k < n_; ++k) {
    const int source = permutation_[k] - offset;
    double* w = W.data() + k * ldr;
    if (source >= 0) {
      const double* b = B.data() + source * ldr;
      for (int i = 0; i < r; ++i) w[i] = b[i];
    } else {
      for (int i = 0; i < r; ++i) w[i] = 0.0;
    }
  }
  W.rightCols(num_bins * num_top).setZero();
  // Solves rows row .. row + rows - 1 of W over the supernodes order_[begin
  // .. end - 1]. When W's rows are split, each part works on a contiguous
  // copy of its rows of the columns the supernodes touch (for_each_column),
  // so that no two threads write to the same cache line.
  auto solve = [&](int begin, int end, bool forward, bool backward, int row,
                   int rows, auto&& for_each_column) {
    Eigen::MatrixXd part;
    double* w = W.data() + row;
    int ld = r;
    if (rows < r) {
      part.resize(rows, W.cols());  // Only the touched columns are set.
      for_each_column(
          [&](int j) { part.col(j) = W.col(j).segment(row, rows); });
      w = part.data();
      ld = rows;
    }
    if (forward) SolvePhase(/*forward=*/true, begin, end, rows, ld, w);
    if (backward) SolvePhase(/*forward=*/false, begin, end, rows, ld, w);
    if (rows < r) {
      for_each_column(
          [&](int j) { W.col(j).segment(row, rows) = part.col(j); });
    }
  };
  // The bins as (bin, row part) tasks over the threads: tasks touch disjoint
  // entries of W, and a row's arithmetic does not depend on the split.
  auto bins = [&](bool forward) {
    const int row_parts = std::clamp(threads / num_bins, 1, r);
    const int tasks = num_bins * row_parts;
    ParallelParts(std::min(threads, tasks), [&](int part, int parts) {
      for (int task = part; task < tasks; task += parts) {
        const int b = task / row_parts, p = task % row_parts;
        const int begin = b == 0 ? 0 : bin_end_[b - 1], end = bin_end_[b];
        const int row = PartBegin(r, p, row_parts);
        solve(begin, end, forward, !forward, row,
              PartBegin(r, p + 1, row_parts) - row, [&](auto&& f) {
                for (int k = begin; k < end; ++k) {
                  for (int j = first_[order_[k]]; j < first_[order_[k] + 1];
                       ++j) {
                    f(j);
                  }
                }
                for (int t = 0; t < num_top; ++t) f(n_ + b * num_top + t);
              });
      }
    });
  };
  if (num_bins > 0) {
    bins(/*forward=*/true);
    for (int t = 0; t < num_top; ++t) {
      for (int b = 0; b < num_bins; ++b) {
        W.col(top_columns_[t]) += W.col(n_ + b * num_top + t);
      }
    }
  }
  const int top_begin = num_bins > 0 ? bin_end_.back() : 0;
  const int top_end = static_cast<int>(order_.size());
  ParallelParts(std::min(r, threads), [&](int part, int parts) {
    const int row = PartBegin(r, part, parts);
    solve(top_begin, top_end, true, true, row,
          PartBegin(r, part + 1, parts) - row, [&](auto&& f) {
            for (int j : top_columns_) f(j);
          });
  });
  if (num_bins > 0) {
    for (int t = 0; t < num_top; ++t) {
      for (int b = 0; b < num_bins; ++b) {
        W.col(n_ + b * num_top + t) = W.col(top_columns_[t]);
      }
    }
    bins(/*forward=*/false);
  }
  for (int k = 0; k < n_; ++k) {
    const int target = permutation_[k] - offset;
    if (target < 0) continue;
    const double* w = W.data() + k * ldr;
    double* x = X->data() + target * ldr;
    for (int i = 0; i < r; ++i) x[i] = w[i];
  }
}

}  // namespace ceres_sesync::internal
