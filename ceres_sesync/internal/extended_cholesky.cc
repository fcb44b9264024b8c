// The SIMD kernels pass GCC vector types between always-inlined functions
// only; the ABI note about passing them by value does not apply.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

#include "ceres_sesync/internal/extended_cholesky.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <type_traits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/tree_split.h"
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

// ---- The simplicial reference ---------------------------------------------

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

// ---- Dense kernels of the supernodal factorization ------------------------
//
// In double the kernels are the same loops with one FMA per product and no
// low parts (Tile below), and a pivot's column is divided by it.
//
// Double-double matrices are stored as two column-major arrays of doubles
// (high and low parts) with a common leading dimension, so that W
// consecutive rows load as one W-lane vector. The update kernel applies
// SubtractProducts to each entry over the inner index in increasing order,
// in blocks of kMaxProducts that depend only on the call; the lanes of a
// vector are independent entries, so the vectorized and the portable
// instantiations compute bitwise the same results.

// Lanes: the portable scalar, and 4 doubles (AVX2), with the operations
// SubtractProductParts takes.
struct ScalarLanes : DoubleOps {
  using Real = double;
  static constexpr int kWidth = 1;
  [[gnu::always_inline]] static Real Load(const double* p) { return *p; }
  [[gnu::always_inline]] static void Store(double* p, Real v) { *p = v; }
  [[gnu::always_inline]] static Real Broadcast(const double* p) { return *p; }
};

// 4 lanes as a GCC/Clang vector type: plain code (inlined into functions
// compiled for AVX2 + FMA, where each operation is one instruction).
typedef double Vector4 __attribute__((vector_size(32)));

struct Lanes4 {
  using Real = Vector4;
  static constexpr int kWidth = 4;
  [[gnu::always_inline]] static Real Load(const double* p) {
    Real v;
    std::memcpy(&v, p, sizeof(v));
    return v;
  }
  [[gnu::always_inline]] static void Store(double* p, Real v) {
    std::memcpy(p, &v, sizeof(v));
  }
  [[gnu::always_inline]] static Real Broadcast(const double* p) {
    const double x = *p;
    return Real{x, x, x, x};
  }
  [[gnu::always_inline]] static Real Add(Real a, Real b) { return a + b; }
  [[gnu::always_inline]] static Real Sub(Real a, Real b) { return a - b; }
  // Lane by lane; one vfmadd with FMA enabled.
  [[gnu::always_inline]] static Real Fma(Real a, Real b, Real c) {
    Real r;
    for (int i = 0; i < kWidth; ++i) r[i] = std::fma(a[i], b[i], c[i]);
    return r;
  }
  // a + b and a - b as a 1 + b and a 1 - b: the same rounding, on the FMA
  // units (the additions alone would saturate the adder units).
  [[gnu::always_inline]] static Real FmaAdd(Real a, Real b) {
    return Fma(a, Real{1, 1, 1, 1}, b);
  }
  [[gnu::always_inline]] static Real FmaSub(Real a, Real b) {
    return Fma(a, Real{1, 1, 1, 1}, -b);
  }
};

// C(i, j) <- C(i, j) - sum_l A(i, l) B(j, l), l = 0 .. k-1 in order, for
// 0 <= j < n and j <= i < m (m >= n): row i of A and of C and row j of B are
// the same local index space, as for the rows of a supernode. Every entry
// is computed by SubtractProducts over l = 0..K-1, K..2K-1, ...
// (K = kMaxProducts; the blocks restart at l = 0 in every call). Entries
// above the diagonal in the leading rows of each block of columns
// (j0 <= i < j) are computed as well, from and into C's storage there, which
// the callers never read.
struct UpdateBlock {
  const double *a_hi, *a_lo;
  int lda;
  const double *b_hi, *b_lo;
  int ldb;
  double *c_hi, *c_lo;
  int ldc;
  int m, n, k;
};

constexpr int kInnerChunk = 32 * kMaxProducts;  // l per pass (cache reuse).
constexpr int kRowChunk = 128;                  // Rows per pass.
constexpr int kColumnBlock = 4;                 // Columns per tile (at most).
static_assert(kInnerChunk % kMaxProducts == 0, "blocks must not straddle");

// A kRows W x kColumns tile of C (at c, leading dimension ldc) minus `count`
// products of A's rows (at a: A(i, l) = a[i + l lda]) and B's (b[j + l ldb]),
// in blocks of kMaxProducts from the first: the accumulators stay in
// registers.
template <class Lanes, int kRows, int kColumns>
[[gnu::always_inline]] inline void UpdateTile(const double* a_hi,
                                              const double* a_lo, int lda,
                                              const double* b_hi,
                                              const double* b_lo, int ldb,
                                              double* c_hi, double* c_lo,
                                              int ldc, int count) {
  using Real = typename Lanes::Real;
  constexpr int W = Lanes::kWidth;
  Real T[kRows][kColumns], t[kRows][kColumns];
#pragma GCC unroll 4
  for (int c = 0; c < kColumns; ++c) {
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) {
      T[r][c] = Lanes::Load(c_hi + r * W + c * ldc);
      t[r][c] = Lanes::Load(c_lo + r * W + c * ldc);
    }
  }
  for (int lb = 0; lb < count; lb += kMaxProducts) {
    const int le = std::min(count, lb + kMaxProducts);
    for (int l = lb; l < le; ++l) {
      Real x_hi[kRows], x_lo[kRows];
#pragma GCC unroll 4
      for (int r = 0; r < kRows; ++r) {
        x_hi[r] = Lanes::Load(a_hi + l * lda + r * W);
        x_lo[r] = Lanes::Load(a_lo + l * lda + r * W);
      }
#pragma GCC unroll 4
      for (int c = 0; c < kColumns; ++c) {
        const Real y_hi = Lanes::Broadcast(b_hi + l * ldb + c);
        const Real y_lo = Lanes::Broadcast(b_lo + l * ldb + c);
#pragma GCC unroll 4
        for (int r = 0; r < kRows; ++r) {
          SubtractProductParts<Lanes>(x_hi[r], x_lo[r], y_hi, y_lo, &T[r][c],
                                      &t[r][c]);
        }
      }
    }
#pragma GCC unroll 4
    for (int c = 0; c < kColumns; ++c) {
#pragma GCC unroll 4
      for (int r = 0; r < kRows; ++r) {
        RenormalizeParts<Lanes>(&T[r][c], &t[r][c]);
      }
    }
  }
#pragma GCC unroll 4
  for (int c = 0; c < kColumns; ++c) {
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) {
      Lanes::Store(c_hi + r * W + c * ldc, T[r][c]);
      Lanes::Store(c_lo + r * W + c * ldc, t[r][c]);
    }
  }
}

// p + at for the low parts of double-double data; null in double, which
// has none.
template <bool kExtended, typename T>
[[gnu::always_inline]] inline T* LowPart(T* p, long long at) {
  return kExtended ? p + at : nullptr;
}

// The same in double: C(i, j) <- C(i, j) - A(i, l) B(j, l) for l = 0 ..
// count - 1 in order, one FMA (a single rounding) per product.
template <class Lanes, int kRows, int kColumns>
[[gnu::always_inline]] inline void UpdateTileDouble(const double* a, int lda,
                                                    const double* b, int ldb,
                                                    double* c, int ldc,
                                                    int count) {
  using Real = typename Lanes::Real;
  constexpr int W = Lanes::kWidth;
  Real T[kRows][kColumns];
#pragma GCC unroll 4
  for (int j = 0; j < kColumns; ++j) {
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) T[r][j] = Lanes::Load(c + r * W + j * ldc);
  }
  for (int l = 0; l < count; ++l) {
    Real x[kRows];
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) x[r] = Lanes::Load(a + l * lda + r * W);
#pragma GCC unroll 4
    for (int j = 0; j < kColumns; ++j) {
      const Real y = -Lanes::Broadcast(b + l * ldb + j);
#pragma GCC unroll 4
      for (int r = 0; r < kRows; ++r) T[r][j] = Lanes::Fma(x[r], y, T[r][j]);
    }
  }
#pragma GCC unroll 4
  for (int j = 0; j < kColumns; ++j) {
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) Lanes::Store(c + r * W + j * ldc, T[r][j]);
  }
}

// One tile in either arithmetic (the low parts are unused in double).
template <class Lanes, bool kExtended, int kRows, int kColumns>
[[gnu::always_inline]] inline void Tile(const double* a_hi, const double* a_lo,
                                        int lda, const double* b_hi,
                                        const double* b_lo, int ldb,
                                        double* c_hi, double* c_lo, int ldc,
                                        int count) {
  if constexpr (kExtended) {
    UpdateTile<Lanes, kRows, kColumns>(a_hi, a_lo, lda, b_hi, b_lo, ldb, c_hi,
                                       c_lo, ldc, count);
  } else {
    UpdateTileDouble<Lanes, kRows, kColumns>(a_hi, lda, b_hi, ldb, c_hi, ldc,
                                             count);
  }
}

// Columns j0 .. j0 + kColumns - 1, rows [max(j0, i0), i1), l in [l0, l1):
// tiles of kRows vectors (several independent accumulators per column hide
// the latency of each one's chain), then single vectors; the last rows
// (fewer than W) are copied into zero-padded buffers for one more vector
// tile (lanes are independent: the same operations as on their own).
template <class Lanes, bool kExtended, int kColumns>
[[gnu::always_inline]] inline void UpdateColumns(const UpdateBlock& u, int j0,
                                                 int i0, int i1, int l0,
                                                 int l1) {
  constexpr int W = Lanes::kWidth;
  constexpr int kRows = kColumns >= 3 ? 2 : 4;
  const int count = l1 - l0;
  const long long a0 = static_cast<long long>(l0) * u.lda;
  const long long b0 = static_cast<long long>(l0) * u.ldb + j0;
  const double* b_hi = u.b_hi + b0;
  const double* b_lo = kExtended ? u.b_lo + b0 : nullptr;
  const long long c0 = static_cast<long long>(j0) * u.ldc;
  auto lo = [](auto* p, long long at) { return LowPart<kExtended>(p, at); };
  int i = std::max(i0, j0);
  for (; i + kRows * W <= i1; i += kRows * W) {
    Tile<Lanes, kExtended, kRows, kColumns>(
        u.a_hi + a0 + i, lo(u.a_lo, a0 + i), u.lda, b_hi, b_lo, u.ldb,
        u.c_hi + c0 + i, lo(u.c_lo, c0 + i), u.ldc, count);
  }
  for (; i + W <= i1; i += W) {
    Tile<Lanes, kExtended, 1, kColumns>(
        u.a_hi + a0 + i, lo(u.a_lo, a0 + i), u.lda, b_hi, b_lo, u.ldb,
        u.c_hi + c0 + i, lo(u.c_lo, c0 + i), u.ldc, count);
  }
  const int rest = i1 - i;
  if (rest > 0) {
    double pa_hi[kInnerChunk * W], pa_lo[kExtended ? kInnerChunk * W : 1];
    double pc_hi[kColumns * W], pc_lo[kExtended ? kColumns * W : 1];
    for (int l = 0; l < count; ++l) {
      for (int r = 0; r < W; ++r) {
        const bool in = r < rest;
        const long long q = a0 + static_cast<long long>(l) * u.lda + i + r;
        pa_hi[l * W + r] = in ? u.a_hi[q] : 0;
        if constexpr (kExtended) pa_lo[l * W + r] = in ? u.a_lo[q] : 0;
      }
    }
    for (int c = 0; c < kColumns; ++c) {
      for (int r = 0; r < W; ++r) {
        const bool in = r < rest;
        const long long q = c0 + static_cast<long long>(c) * u.ldc + i + r;
        pc_hi[c * W + r] = in ? u.c_hi[q] : 0;
        if constexpr (kExtended) pc_lo[c * W + r] = in ? u.c_lo[q] : 0;
      }
    }
    Tile<Lanes, kExtended, 1, kColumns>(pa_hi, pa_lo, W, b_hi, b_lo, u.ldb,
                                        pc_hi, pc_lo, W, count);
    for (int c = 0; c < kColumns; ++c) {
      for (int r = 0; r < rest; ++r) {
        const long long q = c0 + static_cast<long long>(c) * u.ldc + i + r;
        u.c_hi[q] = pc_hi[c * W + r];
        if constexpr (kExtended) u.c_lo[q] = pc_lo[c * W + r];
      }
    }
  }
}

template <class Lanes, bool kExtended>
[[gnu::always_inline]] inline void Update(const UpdateBlock& u) {
  for (int l0 = 0; l0 < u.k; l0 += kInnerChunk) {
    const int l1 = std::min(u.k, l0 + kInnerChunk);
    for (int i0 = 0; i0 < u.m; i0 += kRowChunk) {
      const int i1 = std::min(u.m, i0 + kRowChunk);
      for (int j0 = 0; j0 < std::min(u.n, i1); j0 += kColumnBlock) {
        switch (std::min(kColumnBlock, u.n - j0)) {
          case 4:
            UpdateColumns<Lanes, kExtended, 4>(u, j0, i0, i1, l0, l1);
            break;
          case 3:
            UpdateColumns<Lanes, kExtended, 3>(u, j0, i0, i1, l0, l1);
            break;
          case 2:
            UpdateColumns<Lanes, kExtended, 2>(u, j0, i0, i1, l0, l1);
            break;
          default:
            UpdateColumns<Lanes, kExtended, 1>(u, j0, i0, i1, l0, l1);
        }
      }
    }
  }
}

// x(i) <- x(i) * y for i < m (DoubleDouble's operator*, lane by lane).
template <class Lanes>
[[gnu::always_inline]] inline void Scale(int m, double* x_hi, double* x_lo,
                                         double y_hi, double y_lo) {
  using Real = typename Lanes::Real;
  constexpr int W = Lanes::kWidth;
  const Real yh = Lanes::Broadcast(&y_hi), yl = Lanes::Broadcast(&y_lo);
  int i = 0;
  for (; i + W <= m; i += W) {
    Real r_hi, r_lo;
    MultiplyParts<Lanes>(Lanes::Load(x_hi + i), Lanes::Load(x_lo + i), yh, yl,
                         &r_hi, &r_lo);
    Lanes::Store(x_hi + i, r_hi);
    Lanes::Store(x_lo + i, r_lo);
  }
  for (; i < m; ++i) {
    MultiplyParts<ScalarLanes>(x_hi[i], x_lo[i], y_hi, y_lo, x_hi + i,
                               x_lo + i);
  }
}

// x(i) <- x(i) / y for i < m (double, correctly rounded).
template <class Lanes>
[[gnu::always_inline]] inline void Divide(int m, double* x, double y) {
  constexpr int W = Lanes::kWidth;
  const typename Lanes::Real v = Lanes::Broadcast(&y);
  int i = 0;
  for (; i + W <= m; i += W) Lanes::Store(x + i, Lanes::Load(x + i) / v);
  for (; i < m; ++i) x[i] /= y;
}

void UpdatePortable(const UpdateBlock& u) { Update<ScalarLanes, true>(u); }
void UpdateDoublePortable(const UpdateBlock& u) {
  Update<ScalarLanes, false>(u);
}
void DividePortable(int m, double* x, double y) {
  Divide<ScalarLanes>(m, x, y);
}
void ScalePortable(int m, double* x_hi, double* x_lo, double y_hi,
                   double y_lo) {
  Scale<ScalarLanes>(m, x_hi, x_lo, y_hi, y_lo);
}

#if defined(__x86_64__) || defined(__i386__)
__attribute__((target("avx2,fma"))) void UpdateAvx2(const UpdateBlock& u) {
  Update<Lanes4, true>(u);
}
__attribute__((target("avx2,fma"))) void UpdateDoubleAvx2(
    const UpdateBlock& u) {
  Update<Lanes4, false>(u);
}
__attribute__((target("avx2,fma"))) void DivideAvx2(int m, double* x,
                                                    double y) {
  Divide<Lanes4>(m, x, y);
}
__attribute__((target("avx2,fma"))) void ScaleAvx2(int m, double* x_hi,
                                                   double* x_lo, double y_hi,
                                                   double y_lo) {
  Scale<Lanes4>(m, x_hi, x_lo, y_hi, y_lo);
}
bool HaveAvx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#else
void UpdateAvx2(const UpdateBlock& u) { UpdatePortable(u); }
void UpdateDoubleAvx2(const UpdateBlock& u) { UpdateDoublePortable(u); }
void DivideAvx2(int m, double* x, double y) { DividePortable(m, x, y); }
void ScaleAvx2(int m, double* x_hi, double* x_lo, double y_hi, double y_lo) {
  ScalePortable(m, x_hi, x_lo, y_hi, y_lo);
}
bool HaveAvx2() { return false; }
#endif

// The kernels of one instruction set.
struct Kernels {
  void (*update)(const UpdateBlock&);
  void (*scale)(int m, double* x_hi, double* x_lo, double y_hi, double y_lo);
  void (*update_double)(const UpdateBlock&);  // Only the high parts.
  void (*divide)(int m, double* x, double y);
  // The update of either arithmetic.
  template <bool kExtended>
  auto Update() const {
    return kExtended ? update : update_double;
  }
};

// Factors one supernode in place after all updates from below: its nrows x
// ncols block X (column-major, leading dimension nrows, hi/lo parts), with
// the diagonal block on top. Panels of kPanel columns: each panel first
// receives the update of the supernode's earlier columns (one large
// Update), then its columns are finished one by one (the update of the
// panel's earlier columns, the pivot, the scaling). Returns false on a pivot
// that is not positive or not safe.
constexpr int kPanel = 32;

// Supernodes of at least this many columns take their updates in column
// ranges on several threads (the top separators of nested dissection).
constexpr int kMinColumnSplit = 64;

template <bool kExtended>
bool FactorSupernode(const Kernels& kernels, int nrows, int ncols, double* hi,
                     double* lo) {
  const int ld = nrows;
  // Entry (i, j) of the block, high and low parts (none in double).
  auto at_hi = [ld](double* x, int i, int j) {
    return x + i + static_cast<long long>(j) * ld;
  };
  auto at = [ld](double* x, int i, int j) {
    return LowPart<kExtended>(x, i + static_cast<long long>(j) * ld);
  };
  const auto update = kernels.Update<kExtended>();
  for (int c0 = 0; c0 < ncols; c0 += kPanel) {
    const int c1 = std::min(ncols, c0 + kPanel);
    if (c0 > 0) {
      update({hi + c0, at(lo, c0, 0), ld, hi + c0, at(lo, c0, 0), ld,
              at_hi(hi, c0, c0), at(lo, c0, c0), ld, nrows - c0, c1 - c0, c0});
    }
    for (int j = c0; j < c1; ++j) {
      double* x_hi = at_hi(hi, 0, j);
      if (j > c0) {
        update({at_hi(hi, j, c0), at(lo, j, c0), ld, at_hi(hi, j, c0),
                at(lo, j, c0), ld, x_hi + j, at(lo, j, j), ld, nrows - j, 1,
                j - c0});
      }
      if constexpr (kExtended) {
        double* x_lo = at(lo, 0, j);
        const DoubleDouble d(x_hi[j], x_lo[j]);
        if (!(d.hi > 0) || !Safe(d)) return false;
        const DoubleDouble l_jj = Sqrt(d);
        const DoubleDouble inverse = Reciprocal(l_jj);
        x_hi[j] = l_jj.hi;
        x_lo[j] = l_jj.lo;
        kernels.scale(nrows - j - 1, x_hi + j + 1, x_lo + j + 1, inverse.hi,
                      inverse.lo);
      } else {
        // Higham's Algorithm 10.2 step for step: l_jj = sqrt(d), then
        // l_ij = (a_ij - sum) / l_jj, each correctly rounded.
        const double d = x_hi[j];
        if (!(d > 0) || !Safe(DoubleDouble(d))) return false;
        x_hi[j] = std::sqrt(d);
        kernels.divide(nrows - j - 1, x_hi + j + 1, x_hi[j]);
      }
    }
  }
  return true;
}

}  // namespace

DoubleDoubleCholesky::DoubleDoubleCholesky(const Options& options)
    : options_(options),
      vectorized_(options.supernodal && options.vectorize && HaveAvx2()),
      symbolic_(std::make_shared<const Symbolic>()) {}

void DoubleDoubleCholesky::Analyze(int n, std::vector<int> column_start,
                                   std::vector<int> row_index,
                                   const std::vector<int>& block_start) {
  auto fresh = std::make_shared<Symbolic>();
  Symbolic& sym = *fresh;
  sym.n = n;
  sym.column_start = std::move(column_start);
  sym.row_index = std::move(row_index);
  CHECK_EQ(static_cast<int>(sym.column_start.size()), n + 1);
  if (block_start.empty()) {
    AnalyzeColumns(&sym);
    if (options_.supernodal) AnalyzeSupernodes(options_, nullptr, &sym);
    SetSymbolic(std::move(fresh));
    return;
  }
  CHECK(block_start.front() == 0 && block_start.back() == n);
  BlockPattern blocks;
  blocks.block_start = block_start;
  const int num_blocks = static_cast<int>(block_start.size()) - 1;
  blocks.block_of.resize(n);
  for (int b = 0; b < num_blocks; ++b) {
    CHECK_LT(block_start[b], block_start[b + 1]);
    std::fill(blocks.block_of.begin() + block_start[b],
              blocks.block_of.begin() + block_start[b + 1], b);
  }
  // Block C's rows from its first column; every column of C must then hold
  // exactly those blocks whole and C's rows up to the diagonal.
  std::vector<int> mark(num_blocks, -1);
  blocks.start.assign(1, 0);
  for (int c = 0; c < num_blocks; ++c) {
    mark[c] = c;
    const int first = block_start[c];
    for (int p = sym.column_start[first]; p < sym.column_start[first + 1];
         ++p) {
      const int b = blocks.block_of[sym.row_index[p]];
      if (mark[b] != c) {
        mark[b] = c;
        blocks.rows.push_back(b);
      }
    }
    std::sort(blocks.rows.begin() + blocks.start.back(), blocks.rows.end());
    int above = 0;
    for (int q = blocks.start.back(); q < static_cast<int>(blocks.rows.size());
         ++q) {
      above += block_start[blocks.rows[q] + 1] - block_start[blocks.rows[q]];
    }
    blocks.start.push_back(static_cast<int>(blocks.rows.size()));
    for (int j = first; j < block_start[c + 1]; ++j) {
      CHECK_EQ(sym.column_start[j + 1] - sym.column_start[j],
               above + (j - first + 1))
          << "column " << j << ": the pattern is not block-full";
      for (int p = sym.column_start[j]; p < sym.column_start[j + 1]; ++p) {
        const int i = sym.row_index[p];
        CHECK(i <= j && mark[blocks.block_of[i]] == c)
            << "column " << j << ": the pattern is not block-full";
      }
    }
  }
  AnalyzeColumns(blocks, &sym);
  if (options_.supernodal) AnalyzeSupernodes(options_, &blocks, &sym);
  SetSymbolic(std::move(fresh));
}

void DoubleDoubleCholesky::AnalyzeColumns(Symbolic* symbolic) {
  Symbolic& sym = *symbolic;
  const int n = sym.n;
  // Elimination tree (Liu's algorithm with path compression through
  // `ancestor`).
  sym.parent.assign(n, -1);
  std::vector<int> ancestor(n, -1);
  for (int k = 0; k < n; ++k) {
    for (int p = sym.column_start[k]; p < sym.column_start[k + 1]; ++p) {
      for (int i = sym.row_index[p]; i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) sym.parent[i] = k;
        i = next;
      }
    }
  }
  // Column counts of L by one symbolic up-looking pass (every row's reach).
  std::vector<int> count(n, 1), mark(n, -1);
  sym.row_count.assign(n, 1);
  for (int k = 0; k < n; ++k) {
    mark[k] = k;
    for (int p = sym.column_start[k]; p < sym.column_start[k + 1]; ++p) {
      for (int i = sym.row_index[p]; mark[i] != k; i = sym.parent[i]) {
        mark[i] = k;
        ++count[i];
        ++sym.row_count[k];
      }
    }
  }
  sym.factor_start.assign(n + 1, 0);
  sym.flops = 0;
  for (int k = 0; k < n; ++k) {
    sym.factor_start[k + 1] = sym.factor_start[k] + count[k];
    sym.flops += 0.5 * count[k] * static_cast<double>(count[k]);
  }
}

void DoubleDoubleCholesky::AnalyzeColumns(const BlockPattern& blocks,
                                          Symbolic* symbolic) {
  // The same results by blocks. In a block-full pattern eliminated block by
  // block, column j's parent is j + 1 inside its block and the first column
  // of the block tree's parent for a block's last column; column (X, jj)
  // (jj-th of block X's s_X) has s_X - jj entries of X and, whole, every
  // block whose row reach passes X: the blocks of X's structure. Row i =
  // (k, ii) has ii + 1 entries in k's columns and s_X in every block X of
  // its reach.
  Symbolic& sym = *symbolic;
  const int n = sym.n;
  const std::vector<int>& block_start = blocks.block_start;
  const int num_blocks = static_cast<int>(block_start.size()) - 1;
  auto size = [&](int b) { return block_start[b + 1] - block_start[b]; };
  std::vector<int> parent(num_blocks, -1), ancestor(num_blocks, -1);
  for (int k = 0; k < num_blocks; ++k) {
    for (int q = blocks.start[k]; q < blocks.start[k + 1]; ++q) {
      for (int i = blocks.rows[q]; i != -1 && i < k;) {
        const int next = ancestor[i];
        ancestor[i] = k;
        if (next == -1) parent[i] = k;
        i = next;
      }
    }
  }
  std::vector<int> below(num_blocks, 0), reach(num_blocks, 0),
      mark(num_blocks, -1);
  for (int k = 0; k < num_blocks; ++k) {
    mark[k] = k;
    for (int q = blocks.start[k]; q < blocks.start[k + 1]; ++q) {
      for (int i = blocks.rows[q]; mark[i] != k; i = parent[i]) {
        mark[i] = k;
        below[i] += size(k);
        reach[k] += size(i);
      }
    }
  }
  sym.parent.resize(n);
  sym.row_count.resize(n);
  sym.factor_start.assign(n + 1, 0);
  sym.flops = 0;
  for (int b = 0; b < num_blocks; ++b) {
    const int first = block_start[b], last = block_start[b + 1] - 1;
    for (int j = first; j <= last; ++j) {
      sym.parent[j] = j < last         ? j + 1
                      : parent[b] >= 0 ? block_start[parent[b]]
                                       : -1;
      sym.row_count[j] = 1 + (j - first) + reach[b];
      const int count = last - j + 1 + below[b];
      sym.factor_start[j + 1] = sym.factor_start[j] + count;
      sym.flops += 0.5 * count * static_cast<double>(count);
    }
  }
}

void DoubleDoubleCholesky::ShareAnalysis(const DoubleDoubleCholesky& other) {
  CHECK(!other.symbolic_->column_start.empty()) << "no analysis to share";
  CHECK(options_.supernodal && other.options_.supernodal)
      << "only supernodal analyses are shared";
  CHECK_EQ(options_.min_split_flops, other.options_.min_split_flops);
  SetSymbolic(other.symbolic_);
}

void DoubleDoubleCholesky::SetSymbolic(std::shared_ptr<const Symbolic> sym) {
  symbolic_ = std::move(sym);
  // The simplicial factorization fills L's rows and values; the supernodal
  // one keeps L in its dense blocks instead, with the rows per supernode.
  const int entries = options_.supernodal ? 0 : symbolic_->factor_start.back();
  factor_row_.assign(entries, 0);
  factor_value_.assign(entries, DoubleDouble());
  super_hi_.clear();
  super_lo_.clear();
  factorized_ = false;
}

void DoubleDoubleCholesky::AnalyzeSupernodes(const Options& options,
                                             const BlockPattern* blocks,
                                             Symbolic* symbolic) {
  Symbolic& sym = *symbolic;
  const int n = sym.n;
  // A's lower triangle by columns: the values of column i of L (entries
  // (k, i), k >= i), by column (sym.scatter_start), with their rows.
  sym.scatter_start.assign(n + 1, 0);
  for (int k = 0; k < n; ++k) {
    for (int p = sym.column_start[k]; p < sym.column_start[k + 1]; ++p) {
      ++sym.scatter_start[sym.row_index[p] + 1];
    }
  }
  for (int i = 0; i < n; ++i) sym.scatter_start[i + 1] += sym.scatter_start[i];
  std::vector<int> lower_row(sym.row_index.size());
  sym.scatter_source.resize(sym.row_index.size());
  {
    std::vector<int> next(sym.scatter_start.begin(),
                          sym.scatter_start.end() - 1);
    for (int k = 0; k < n; ++k) {
      for (int p = sym.column_start[k]; p < sym.column_start[k + 1]; ++p) {
        const int slot = next[sym.row_index[p]]++;
        lower_row[slot] = k;
        sym.scatter_source[slot] = p;
      }
    }
  }
  // Fundamental supernodes: column j + 1 continues column j's supernode iff
  // it is j's parent and has j's pattern minus j (then their counts differ
  // by one: the pattern of j minus j is contained in its parent's).
  auto count = [&](int j) {
    return sym.factor_start[j + 1] - sym.factor_start[j];
  };
  sym.super_start.push_back(0);
  for (int j = 1; j < n; ++j) {
    if (!(sym.parent[j - 1] == j && count(j - 1) == count(j) + 1)) {
      sym.super_start.push_back(j);
    }
  }
  if (n > 0) sym.super_start.push_back(n);
  const int num_super = static_cast<int>(sym.super_start.size()) - 1;
  sym.column_super.resize(n);
  for (int s = 0; s < num_super; ++s) {
    for (int j = sym.super_start[s]; j < sym.super_start[s + 1]; ++j) {
      sym.column_super[j] = s;
    }
  }
  std::vector<int> super_parent(num_super, -1);
  for (int s = 0; s < num_super; ++s) {
    const int up = sym.parent[sym.super_start[s + 1] - 1];
    if (up >= 0) super_parent[s] = sym.column_super[up];
  }
  // The rows of each supernode, without forming L's pattern column by
  // column: its columns, then the rows below them of A's columns in it and
  // of its children's rows beyond their columns (Davis, "Direct Methods",
  // Ch. 4: the pattern of column j is A's column j and the patterns of its
  // elimination-tree children, minus the rows above j), sorted. Children
  // have lower indices, so they are complete when their parent's turn
  // comes. O(nnz(A) + sum of the supernodes' row counts) instead of
  // O(nnz(L)).
  std::vector<int> child_head(num_super, -1), child_next(num_super, -1);
  for (int s = num_super - 1; s >= 0; --s) {
    const int up = super_parent[s];
    if (up >= 0) {
      child_next[s] = child_head[up];
      child_head[up] = s;
    }
  }
  long long total_rows = 0;
  for (int s = 0; s < num_super; ++s) total_rows += count(sym.super_start[s]);
  sym.super_row.reserve(total_rows);
  std::vector<int> mark(blocks ? 0 : n, -1);
  // By blocks: the same rows, blockwise (a supernode is a run of whole
  // blocks: inside a block each column continues the last), from the
  // blocks' lower pattern and the children's blocks below theirs.
  std::vector<int> lower_start, lower_block, block_mark, super_block,
      super_block_start;
  if (blocks) {
    const int num_blocks = static_cast<int>(blocks->block_start.size()) - 1;
    lower_start.assign(num_blocks + 1, 0);
    for (int b : blocks->rows) ++lower_start[b + 1];
    for (int b = 0; b < num_blocks; ++b) lower_start[b + 1] += lower_start[b];
    lower_block.resize(blocks->rows.size());
    std::vector<int> next(lower_start.begin(), lower_start.end() - 1);
    for (int k = 0; k < num_blocks; ++k) {
      for (int q = blocks->start[k]; q < blocks->start[k + 1]; ++q) {
        lower_block[next[blocks->rows[q]]++] = k;
      }
    }
    block_mark.assign(num_blocks, -1);
    super_block_start.assign(1, 0);
  }
  sym.super_row_start.assign(1, 0);
  sym.super_value_start.assign(1, 0);
  for (int s = 0; s < num_super; ++s) {
    const int first = sym.super_start[s], last = sym.super_start[s + 1];
    const int ncols = last - first;
    if (blocks) {
      const int b0 = blocks->block_of[first], b1 = blocks->block_of[last - 1];
      CHECK(blocks->block_start[b0] == first &&
            blocks->block_start[b1 + 1] == last)
          << "supernode " << s << " splits a block";
      for (int b = b0; b <= b1; ++b) {
        block_mark[b] = s;
        super_block.push_back(b);
      }
      const size_t below = super_block.size();
      auto add = [&](int k) {
        if (block_mark[k] != s) {
          block_mark[k] = s;
          super_block.push_back(k);
        }
      };
      for (int b = b0; b <= b1; ++b) {
        for (int q = lower_start[b]; q < lower_start[b + 1]; ++q) {
          add(lower_block[q]);
        }
      }
      for (int c = child_head[s]; c != -1; c = child_next[c]) {
        const int own = blocks->block_of[sym.super_start[c + 1] - 1] -
                        blocks->block_of[sym.super_start[c]] + 1;
        for (int t = super_block_start[c] + own; t < super_block_start[c + 1];
             ++t) {
          add(super_block[t]);
        }
      }
      std::sort(super_block.begin() + below, super_block.end());
      super_block_start.push_back(static_cast<int>(super_block.size()));
      for (int j = first; j < last; ++j) sym.super_row.push_back(j);
      for (size_t t = below; t < super_block.size(); ++t) {
        const int k = super_block[t];
        for (int i = blocks->block_start[k]; i < blocks->block_start[k + 1];
             ++i) {
          sym.super_row.push_back(i);
        }
      }
    } else {
      for (int j = first; j < last; ++j) {
        mark[j] = s;
        sym.super_row.push_back(j);
      }
      const size_t below = sym.super_row.size();
      for (int j = first; j < last; ++j) {
        for (int q = sym.scatter_start[j]; q < sym.scatter_start[j + 1]; ++q) {
          const int k = lower_row[q];
          if (mark[k] != s) {
            mark[k] = s;
            sym.super_row.push_back(k);
          }
        }
      }
      for (int c = child_head[s]; c != -1; c = child_next[c]) {
        const int c_cols = sym.super_start[c + 1] - sym.super_start[c];
        for (int t = sym.super_row_start[c] + c_cols;
             t < sym.super_row_start[c + 1]; ++t) {
          const int k = sym.super_row[t];
          if (mark[k] != s) {
            mark[k] = s;
            sym.super_row.push_back(k);
          }
        }
      }
      std::sort(sym.super_row.begin() + below, sym.super_row.end());
    }
    sym.super_row_start.push_back(static_cast<int>(sym.super_row.size()));
    const long long nrows = sym.super_row_start[s + 1] - sym.super_row_start[s];
    CHECK_EQ(nrows, count(first)) << "supernode " << s << ": its rows and "
                                  << "the column count disagree";
    sym.super_value_start.push_back(sym.super_value_start.back() +
                                    nrows * ncols);
  }
  // The split for parallel factorization (tree_split.h), weighted by the
  // work each supernode's factorization step does: left-looking, column j's
  // update of its row at position p (diagonal 0) of its c rows costs c - p
  // multiply-adds, done when the supernode holding that row is factored. In
  // supernode s (nrows rows, ncols columns) that is nrows - t for its row at
  // position t, from each of its columns at or left of t: (t + 1) (nrows - t)
  // for s itself (t < ncols), ncols (nrows - t) for the supernode of a row
  // below. (Integers: the sums are exact in any order.)
  sym.super_bin.clear();
  if (sym.flops >= options.min_split_flops) {
    std::vector<double> work(num_super, 0.0);
    for (int s = 0; s < num_super; ++s) {
      const int ncols = sym.super_start[s + 1] - sym.super_start[s];
      const int begin = sym.super_row_start[s];
      const int nrows = sym.super_row_start[s + 1] - begin;
      for (int t = 0; t < nrows; ++t) {
        const double remaining = nrows - t;
        if (t < ncols) {
          work[s] += (t + 1.0) * remaining;
        } else {
          work[sym.column_super[sym.super_row[begin + t]]] += ncols * remaining;
        }
      }
    }
    const TreeSplit split = SplitTree(super_parent, work, kTreeSplitBins,
                                      /*max_critical_fraction=*/0.85);
    VLOG(2) << "double-double factorization: top " << split.top_weight << " of "
            << split.total_weight << " multiply-adds, heaviest bin "
            << split.heaviest_bin << (split.bin.empty() ? " (not split)" : "");
    sym.super_bin = split.bin;
  }
  // Where each input value goes: entry (k, i), k >= i, of A is in column i
  // of L, in supernode s = sym.column_super[i], at the position of row k. Each
  // column is filled by the thread that factors it, right before its
  // updates (FactorizeSupernodal).
  sym.scatter_destination.resize(sym.row_index.size());
  std::vector<int> position(n, -1);
  for (int s = 0; s < num_super; ++s) {
    const int first = sym.super_start[s];
    const int nrows = sym.super_row_start[s + 1] - sym.super_row_start[s];
    const int* rows = sym.super_row.data() + sym.super_row_start[s];
    for (int t = 0; t < nrows; ++t) position[rows[t]] = t;
    for (int j = first; j < sym.super_start[s + 1]; ++j) {
      for (int q = sym.scatter_start[j]; q < sym.scatter_start[j + 1]; ++q) {
        sym.scatter_destination[q] = sym.super_value_start[s] +
                                     static_cast<long long>(j - first) * nrows +
                                     position[lower_row[q]];
      }
    }
  }
}

template <typename Value>
bool DoubleDoubleCholesky::FactorizeSupernodal(
    const std::vector<Value>& values,
    std::chrono::steady_clock::time_point deadline) {
  const Symbolic& sym = *symbolic_;
  constexpr bool kExtended = std::is_same_v<Value, DoubleDouble>;
  const int num_super = num_supernodes();
  const Kernels kernels =
      vectorized_ ? Kernels{UpdateAvx2, ScaleAvx2, UpdateDoubleAvx2, DivideAvx2}
                  : Kernels{UpdatePortable, ScalePortable, UpdateDoublePortable,
                            DividePortable};
  const auto update_kernel = kernels.Update<kExtended>();
  // The dense blocks, kept as the factor: allocated once per analysis and
  // left unwritten here. Each column is zeroed and filled with its values
  // by the thread that factors it (fill_columns below), so that the first
  // touch of fresh pages, which costs more than this whole loop on the
  // virtual machines measured, is spread over the threads.
  factor_value_.clear();
  HugePageVector<double>& super_hi = super_hi_;
  HugePageVector<double>& super_lo = super_lo_;
  const size_t entries = static_cast<size_t>(supernodal_entries());
  if (super_hi.size() != entries) {
    HugePageVector<double>().swap(super_hi);
    super_hi.resize(entries);  // Default-initialized: not written.
  }
  if (super_lo.size() != (kExtended ? entries : 0)) {
    HugePageVector<double>().swap(super_lo);
    super_lo.resize(kExtended ? entries : 0);
  }
  auto lo = [](auto* p, long long at) { return LowPart<kExtended>(p, at); };
  // Zeros columns c0 .. c1 - 1 of supernode s (nrows rows, values s_hi and
  // s_lo) and scatters A's values into them.
  auto fill_columns = [&](int s, int c0, int c1, int nrows, double* s_hi,
                          double* s_lo) {
    const int first = sym.super_start[s];
    std::fill(s_hi + static_cast<long long>(c0) * nrows,
              s_hi + static_cast<long long>(c1) * nrows, 0.0);
    if constexpr (kExtended) {
      std::fill(s_lo + static_cast<long long>(c0) * nrows,
                s_lo + static_cast<long long>(c1) * nrows, 0.0);
    }
    for (int q = sym.scatter_start[first + c0];
         q < sym.scatter_start[first + c1]; ++q) {
      if constexpr (kExtended) {
        // Renormalized (the same value): the kernels' bounds assume it.
        const DoubleDouble& value = values[sym.scatter_source[q]];
        const DoubleDouble v = dd::TwoSum(value.hi, value.lo);
        super_hi[sym.scatter_destination[q]] = v.hi;
        super_lo[sym.scatter_destination[q]] = v.lo;
      } else {
        super_hi[sym.scatter_destination[q]] = values[sym.scatter_source[q]];
      }
    }
  };
  // Left-looking: supernode d, once factored, waits in the list of the
  // supernode holding its next row below the ones already applied
  // (pointer[d]), which it updates when that one's turn comes. With a split
  // (sym.super_bin), each bin keeps lists of its own (a bin's supernodes
  // update only their ancestors: in the bin or in the top), which are
  // joined, in bin order, for the top's turn.
  const int num_bins = this->num_bins();
  std::vector<std::vector<int>> heads(num_bins + 1,
                                      std::vector<int>(num_super, -1));
  std::vector<int> next(num_super, -1), pointer(num_super, 0);
  const bool has_deadline =
      deadline != std::chrono::steady_clock::time_point::max();
  std::atomic<bool> stop(false), timed_out(false);
  // Scratch of one thread's updates.
  struct Scratch {
    std::vector<int> relative;
    std::vector<double> work_hi, work_lo;
  };
  // Subtracts from supernode s (values s_hi/s_lo, nrows rows, the positions
  // of its rows in `position`) the products of supernode d's rows p1 .. p2 - 1
  // (rows of s's columns) with d's rows p1 .. end. Every entry of s receives
  // the same operations in the same order whatever the range [p1, p2) it is
  // updated in: splitting one update into column ranges changes nothing.
  auto update = [&](int d, int p1, int p2, const std::vector<int>& position,
                    double* s_hi, double* s_lo, int nrows, Scratch* scratch) {
    const int d_nrows = sym.super_row_start[d + 1] - sym.super_row_start[d];
    const int* d_rows = sym.super_row.data() + sym.super_row_start[d];
    const int m = d_nrows - p1, n = p2 - p1;
    const double* d_hi = super_hi.data() + sym.super_value_start[d] + p1;
    const double* d_lo = lo(super_lo.data(), sym.super_value_start[d] + p1);
    const int k = sym.super_start[d + 1] - sym.super_start[d];
    // The target rows of d's rows p1.. are contiguous in s (positions
    // increase with the rows): update s in place; otherwise gather the
    // target entries, update, scatter.
    const int r0 = position[d_rows[p1]];
    if (position[d_rows[d_nrows - 1]] - r0 == m - 1) {
      const long long at = r0 + static_cast<long long>(r0) * nrows;
      update_kernel({d_hi, d_lo, d_nrows, d_hi, d_lo, d_nrows, s_hi + at,
                     lo(s_lo, at), nrows, m, n, k});
      return;
    }
    std::vector<int>& relative = scratch->relative;
    std::vector<double>& work_hi = scratch->work_hi;
    std::vector<double>& work_lo = scratch->work_lo;
    relative.resize(m);
    for (int i = 0; i < m; ++i) relative[i] = position[d_rows[p1 + i]];
    const size_t size = static_cast<size_t>(m) * n;
    if (work_hi.size() < size) work_hi.resize(size);
    if (kExtended && work_lo.size() < size) work_lo.resize(size);
    for (int j = 0; j < n; ++j) {
      const long long t = static_cast<long long>(relative[j]) * nrows;
      const double* t_hi = s_hi + t;
      double* w_hi = work_hi.data() + static_cast<size_t>(j) * m;
      // Zeros above the diagonal where the kernel computes unused entries
      // (from the start of j's block of columns).
      for (int i = j - j % kColumnBlock; i < j; ++i) w_hi[i] = 0;
      for (int i = j; i < m; ++i) w_hi[i] = t_hi[relative[i]];
      if constexpr (kExtended) {
        const double* t_lo = s_lo + t;
        double* w_lo = work_lo.data() + static_cast<size_t>(j) * m;
        for (int i = j - j % kColumnBlock; i < j; ++i) w_lo[i] = 0;
        for (int i = j; i < m; ++i) w_lo[i] = t_lo[relative[i]];
      }
    }
    update_kernel({d_hi, d_lo, d_nrows, d_hi, d_lo, d_nrows, work_hi.data(),
                   lo(work_lo.data(), 0), m, m, n, k});
    for (int j = 0; j < n; ++j) {
      const long long t = static_cast<long long>(relative[j]) * nrows;
      double* t_hi = s_hi + t;
      const double* w_hi = work_hi.data() + static_cast<size_t>(j) * m;
      for (int i = j; i < m; ++i) t_hi[relative[i]] = w_hi[i];
      if constexpr (kExtended) {
        double* t_lo = s_lo + t;
        const double* w_lo = work_lo.data() + static_cast<size_t>(j) * m;
        for (int i = j; i < m; ++i) t_lo[relative[i]] = w_lo[i];
      }
    }
  };
  // Factors the supernodes s with sym.super_bin[s] == bin (all if unsplit) in
  // increasing order, with the lists `head`, on `threads` threads: wide
  // supernodes (the top separators, which receive most updates) take their
  // updates in column ranges, one per thread. False if stopped or on a
  // failed pivot (which stops the other bins too).
  auto factor = [&](int bin, std::vector<int>* head_list, int threads) {
    std::vector<int>& head = *head_list;
    std::vector<int> position(sym.n, -1), list;
    std::vector<Scratch> scratch(threads);
    for (int s = 0; s < num_super; ++s) {
      if (num_bins > 0 && sym.super_bin[s] != bin) continue;
      if (stop.load(std::memory_order_relaxed)) return false;
      if (has_deadline && std::chrono::steady_clock::now() > deadline) {
        timed_out = true;
        stop = true;
        return false;
      }
      const int first = sym.super_start[s], last = sym.super_start[s + 1];
      const int ncols = last - first;
      const int nrows = sym.super_row_start[s + 1] - sym.super_row_start[s];
      const int* rows = sym.super_row.data() + sym.super_row_start[s];
      double* s_hi = super_hi.data() + sym.super_value_start[s];
      double* s_lo = lo(super_lo.data(), sym.super_value_start[s]);
      for (int t = 0; t < nrows; ++t) position[rows[t]] = t;
      // The updates: supernode d's rows p1 = pointer[d] .. p2 - 1 are in
      // s's columns.
      list.clear();
      for (int d = head[s]; d != -1; d = next[d]) list.push_back(d);
      auto rows_in_s = [&](int d) {
        const int d_nrows = sym.super_row_start[d + 1] - sym.super_row_start[d];
        const int* d_rows = sym.super_row.data() + sym.super_row_start[d];
        int p2 = pointer[d];
        while (p2 < d_nrows && d_rows[p2] < last) ++p2;
        return p2;
      };
      const int parts = ncols >= kMinColumnSplit ? threads : 1;
      ParallelParts(parts, [&](int part, int num_parts) {
        // Columns first + c0 .. first + c1 - 1, about equal shares of the
        // lower trapezoid (column j has nrows - j entries).
        auto column_begin = [&](int q) {
          if (q == num_parts) return ncols;
          const double area = (2.0 * nrows - ncols) * ncols * q / num_parts;
          // Largest c with c (2 nrows - c) <= area.
          const double c =
              nrows - std::sqrt(std::max(
                          0.0, static_cast<double>(nrows) * nrows - area));
          return std::clamp(static_cast<int>(c), 0, ncols);
        };
        const int c0 = column_begin(part), c1 = column_begin(part + 1);
        fill_columns(s, c0, c1, nrows, s_hi, s_lo);
        for (int d : list) {
          const int* d_rows = sym.super_row.data() + sym.super_row_start[d];
          const int p1 = pointer[d], p2 = rows_in_s(d);
          const int q1 =
              std::lower_bound(d_rows + p1, d_rows + p2, first + c0) - d_rows;
          const int q2 =
              std::lower_bound(d_rows + q1, d_rows + p2, first + c1) - d_rows;
          if (q1 < q2) {
            update(d, q1, q2, position, s_hi, s_lo, nrows, &scratch[part]);
          }
        }
      });
      // Each d waits next for the supernode of its first row beyond s.
      head[s] = -1;
      for (int d : list) {
        const int d_nrows = sym.super_row_start[d + 1] - sym.super_row_start[d];
        const int* d_rows = sym.super_row.data() + sym.super_row_start[d];
        const int p2 = rows_in_s(d);
        pointer[d] = p2;
        if (p2 < d_nrows) {
          const int target = sym.column_super[d_rows[p2]];
          next[d] = head[target];
          head[target] = d;
        }
      }
      if (!FactorSupernode<kExtended>(kernels, nrows, ncols, s_hi, s_lo)) {
        stop = true;
        return false;
      }
      pointer[s] = ncols;
      if (ncols < nrows) {
        const int target = sym.column_super[rows[ncols]];
        next[s] = head[target];
        head[target] = s;
      }
    }
    return true;
  };
  bool ok = true;
  if (num_bins > 0) {
    bool bin_ok[kTreeSplitBins];
    ParallelParts(std::min(options_.num_threads, num_bins),
                  [&](int part, int parts) {
                    for (int b = part; b < num_bins; b += parts) {
                      bin_ok[b] = factor(b, &heads[b], 1);
                    }
                  });
    ok = std::all_of(bin_ok, bin_ok + num_bins, [](bool b) { return b; });
    // The top's lists: bin 0's, then bin 1's, ... (every supernode still
    // waiting in a bin's lists waits for a top supernode).
    std::vector<int>& top_head = heads[num_bins];
    for (int s = num_super - 1; ok && s >= 0; --s) {
      if (sym.super_bin[s] != -1) continue;
      for (int b = num_bins - 1; b >= 0; --b) {
        int d = heads[b][s];
        if (d == -1) continue;
        while (next[d] != -1) d = next[d];
        next[d] = top_head[s];
        top_head[s] = heads[b][s];
      }
    }
    ok = ok && factor(-1, &top_head, options_.num_threads);
  } else {
    ok = factor(0, &heads[0], options_.num_threads);
  }
  timed_out_ = timed_out;
  return ok;
}

bool DoubleDoubleCholesky::Factorize(
    const std::vector<double>& values,
    std::chrono::steady_clock::time_point deadline) {
  return FactorizeValues(values, deadline);
}

void DoubleDoubleCholesky::ReleaseNumericFactor() {
  HugePageVector<double>().swap(super_hi_);
  HugePageVector<double>().swap(super_lo_);
  std::vector<DoubleDouble>().swap(factor_value_);
  factorized_ = false;
}

bool DoubleDoubleCholesky::Factorize(
    const std::vector<DoubleDouble>& values,
    std::chrono::steady_clock::time_point deadline) {
  return FactorizeValues(values, deadline);
}

template <typename Value>
bool DoubleDoubleCholesky::FactorizeValues(
    const std::vector<Value>& values,
    std::chrono::steady_clock::time_point deadline) {
  const Symbolic& sym = *symbolic_;
  constexpr bool kExtended = std::is_same_v<Value, DoubleDouble>;
  CHECK_EQ(values.size(), sym.row_index.size());
  timed_out_ = false;
  extended_factor_ = kExtended;
  for (const Value& v : values) {
    if (!Safe(DoubleDouble(v))) return factorized_ = false;
  }
  if constexpr (kExtended) {
    if (!options_.supernodal) {
      std::vector<int> fill(sym.n);
      factorized_ = FactorizeRows(
          sym.n, sym.column_start.data(), sym.row_index.data(), values.data(),
          sym.parent.data(), sym.factor_start.data(), factor_row_.data(),
          factor_value_.data(), fill.data());
      return factorized_;
    }
  } else {
    CHECK(options_.supernodal) << "double: the supernodal scheme only";
  }
  factorized_ = FactorizeSupernodal(values, deadline);
  return factorized_;
}

void DoubleDoubleCholesky::RowBackwardErrorBounds(
    std::vector<double>* rho) const {
  const Symbolic& sym = *symbolic_;
  CHECK(factorized_);
  // v_i = sum_j (|L| |L^T|)_ij = sum_c |L_ic| s_c with s_c the column sums
  // of |L|. Every |L| value is rounded up (AbsUpperBound), and a computed sum
  // of m nonnegative doubles is within gamma_m (double) of the exact one, so
  // the factor (1 + 1e-6) covers the rounding of this computation for up to
  // 10^9 terms (gamma_{10^9} < 1.2e-7).
  std::vector<double> column_sum(sym.n, 0.0), v(sym.n, 0.0);
  double max_pivot = 1;  // For the underflow term below.
  for (int c = 0; c < sym.n; ++c) {
    ForEachEntry(c, [&](int row, const DoubleDouble& l) {
      if (row == c) max_pivot = std::max(max_pivot, l.AbsUpperBound());
      column_sum[c] += l.AbsUpperBound();
    });
  }
  for (int c = 0; c < sym.n; ++c) {
    ForEachEntry(c, [&](int row, const DoubleDouble& l) {
      v[row] += l.AbsUpperBound() * column_sum[c];
    });
  }
  // Underflow: every entry is computed with at most max_count + 2
  // operations, each erring by at most kUnderflowError absolutely, scaled by
  // the pivot l_jj it is multiplied with (the backward error of l_ij is
  // l_jj times its forward error).
  const int max_count =
      sym.n > 0 ? *std::max_element(sym.row_count.begin(), sym.row_count.end())
                : 0;
  const double underflow_per_entry =
      (max_count + 2.0) * kUnderflowError * max_pivot * (1 + 1e-6);
  rho->resize(sym.n);
  for (int i = 0; i < sym.n; ++i) {
    const double entries =
        sym.row_count[i] + (sym.factor_start[i + 1] - sym.factor_start[i]);
    const double m = sym.row_count[i] + 1;
    const double gamma =
        extended_factor_ ? DoubleDoubleGamma(m) : DoubleGamma(m);
    (*rho)[i] = gamma * v[i] * (1 + 1e-6) + entries * underflow_per_entry;
  }
}

const HugePageVector<int>& DoubleDoubleCholesky::factor_row() const {
  const Symbolic& sym = *symbolic_;
  if (options_.supernodal && factor_row_.empty() && sym.n > 0) {
    factor_row_.resize(sym.factor_start[sym.n]);
    for (int c = 0; c < sym.n; ++c) {
      const int s = sym.column_super[c], jj = c - sym.super_start[s];
      std::copy(sym.super_row.begin() + sym.super_row_start[s] + jj,
                sym.super_row.begin() + sym.super_row_start[s + 1],
                factor_row_.begin() + sym.factor_start[c]);
    }
  }
  return factor_row_;
}

const std::vector<DoubleDouble>& DoubleDoubleCholesky::factor_value() const {
  const Symbolic& sym = *symbolic_;
  if (options_.supernodal && factorized_ && factor_value_.empty()) {
    factor_value_.resize(sym.factor_start[sym.n]);
    for (int c = 0; c < sym.n; ++c) {
      int t = 0;
      ForEachEntry(c, [&](int, const DoubleDouble& l) {
        factor_value_[sym.factor_start[c] + t++] = l;
      });
    }
  }
  return factor_value_;
}

void DoubleDoubleCholesky::ForEachSupernode(
    const std::function<void(int, int, const int*, int, const double*)>& f)
    const {
  const Symbolic& sym = *symbolic_;
  CHECK(factorized_ && options_.supernodal);
  for (int s = 0; s < num_supernodes(); ++s) {
    f(sym.super_start[s], sym.super_start[s + 1] - sym.super_start[s],
      sym.super_row.data() + sym.super_row_start[s],
      sym.super_row_start[s + 1] - sym.super_row_start[s],
      super_hi_.data() + sym.super_value_start[s]);
  }
}

PermutedPattern PermuteSymmetricPattern(int n, const int* outer,
                                        const int* inner,
                                        const std::vector<int>& position) {
  PermutedPattern p;
  p.column_start.assign(n + 1, 0);
  for (int c = 0; c < n; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      if (inner[q] < c) continue;
      ++p.column_start[std::max(position[inner[q]], position[c]) + 1];
    }
  }
  for (int k = 0; k < n; ++k) p.column_start[k + 1] += p.column_start[k];
  std::vector<int> next(p.column_start.begin(), p.column_start.end() - 1);
  p.row_index.resize(p.column_start[n]);
  p.slot.assign(outer[n], -1);
  for (int c = 0; c < n; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      if (inner[q] < c) continue;
      const int pr = position[inner[q]], pc = position[c];
      const int slot = next[std::max(pr, pc)]++;
      p.row_index[slot] = std::min(pr, pc);
      p.slot[q] = slot;
    }
  }
  return p;
}

PermutedPattern PermuteSymmetricBlockPattern(
    int n, const int* outer, const int* inner, const std::vector<int>& position,
    const std::vector<int>& block_start) {
  CHECK(!block_start.empty() && block_start.front() == 0 &&
        block_start.back() == n);
  const int num_blocks = static_cast<int>(block_start.size()) - 1;
  std::vector<int> block_of(n);
  for (int b = 0; b < num_blocks; ++b) {
    std::fill(block_of.begin() + block_start[b],
              block_of.begin() + block_start[b + 1], b);
  }
  // 1. The block pairs (hi >= lo) of the entries, one per run of a column's
  // entries in the same pair; slot holds each entry's pair until step 5.
  PermutedPattern p;
  p.slot.assign(outer[n], -1);
  std::vector<int> pair_hi, pair_lo;
  auto for_each_entry = [&](auto&& f) {
    for (int c = 0; c < n; ++c) {
      for (int q = outer[c]; q < outer[c + 1]; ++q) {
        if (inner[q] < c) continue;
        const int pr = position[inner[q]], pc = position[c];
        f(q, std::min(pr, pc), std::max(pr, pc));
      }
    }
  };
  int last_hi = -1, last_lo = -1;
  for_each_entry([&](int q, int lo, int hi) {
    const int b_hi = block_of[hi], b_lo = block_of[lo];
    if (b_hi != last_hi || b_lo != last_lo) {
      pair_hi.push_back(last_hi = b_hi);
      pair_lo.push_back(last_lo = b_lo);
    }
    p.slot[q] = static_cast<int>(pair_hi.size()) - 1;
  });
  // 2. The pairs by block column.
  const int num_pairs = static_cast<int>(pair_hi.size());
  std::vector<int> pair_start(num_blocks + 1, 0), by_column(num_pairs);
  for (int b : pair_hi) ++pair_start[b + 1];
  for (int b = 0; b < num_blocks; ++b) pair_start[b + 1] += pair_start[b];
  {
    std::vector<int> next(pair_start.begin(), pair_start.end() - 1);
    for (int k = 0; k < num_pairs; ++k) by_column[next[pair_hi[k]]++] = k;
  }
  // 3. Block column C's rows R < C ascending, the scalar rows above each
  // (offset; C's own rows follow them), each pair's offset, the columns'
  // starts.
  std::vector<int> row_start(1, 0), rows, seen(num_blocks, -1),
      offset(num_blocks), pair_offset(num_pairs);
  p.column_start.assign(n + 1, 0);
  for (int c = 0; c < num_blocks; ++c) {
    const size_t first = rows.size();
    for (int t = pair_start[c]; t < pair_start[c + 1]; ++t) {
      const int r = pair_lo[by_column[t]];
      if (r != c && seen[r] != c) {
        seen[r] = c;
        rows.push_back(r);
      }
    }
    std::sort(rows.begin() + first, rows.end());
    int above = 0;
    for (size_t t = first; t < rows.size(); ++t) {
      offset[rows[t]] = above;
      above += block_start[rows[t] + 1] - block_start[rows[t]];
    }
    offset[c] = above;
    for (int t = pair_start[c]; t < pair_start[c + 1]; ++t) {
      pair_offset[by_column[t]] = offset[pair_lo[by_column[t]]];
    }
    row_start.push_back(static_cast<int>(rows.size()));
    for (int j = block_start[c]; j < block_start[c + 1]; ++j) {
      p.column_start[j + 1] =
          p.column_start[j] + above + (j - block_start[c]) + 1;
    }
  }
  // 4. The rows: the blocks above, whole, then C's up to the diagonal.
  p.row_index.resize(p.column_start[n]);
  for (int c = 0; c < num_blocks; ++c) {
    for (int j = block_start[c]; j < block_start[c + 1]; ++j) {
      int at = p.column_start[j];
      for (int t = row_start[c]; t < row_start[c + 1]; ++t) {
        for (int i = block_start[rows[t]]; i < block_start[rows[t] + 1]; ++i) {
          p.row_index[at++] = i;
        }
      }
      for (int i = block_start[c]; i <= j; ++i) p.row_index[at++] = i;
    }
  }
  // 5. Each entry's place: its pair's offset in its column.
  for_each_entry([&](int q, int lo, int hi) {
    p.slot[q] = p.column_start[hi] + pair_offset[p.slot[q]] +
                (lo - block_start[block_of[lo]]);
  });
  return p;
}

}  // namespace ceres_sesync::internal
