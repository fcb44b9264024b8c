// Sparse Cholesky factorization A = L L^T in double-double arithmetic
// (double_double.h), with a rigorous bound on its backward error: the proof
// engine for certificates that double precision cannot resolve. The same
// supernodal scheme also runs in double (Factorize() with double values),
// with the same bound in double's unit roundoff: the certificate matrix's
// factorizations for solves and double proofs (certificate_matrix.h).
//
// Every computed entry obeys the componentwise backward-error bound of Higham
// ("Accuracy and Stability of Numerical Algorithms", 2nd ed., Thm. 10.3 with
// Lemma 8.4: any summation order) in any arithmetic satisfying the standard
// model (or the Cray-style model of double_double.h):
//
//   L L^T = A + E,   |E| <= gamma_{k+1} |L| |L^T|,
//
// with k the number of stored entries of the row and gamma the double-double
// gamma (kDoubleDoubleUnitRoundoff ~ 3.9e-31). A factorization that completes
// therefore proves A + E positive semidefinite, i.e. A + diag(rho) >= 0 for
// the Gershgorin row sums rho_i >= sum_j |E_ij| returned by
// RowBackwardErrorBounds().
//
// Two numerical schemes compute each l_ij = (a_ij - sum_k l_ik l_jk) / l_jj
// (l_jj = sqrt(a_jj - sum_k l_jk^2)) over the nonzero terms, in different
// orders of summation, so the bound holds for both:
//  - supernodal (the default): left-looking over supernodes, i.e. sets of
//    consecutive columns with the same pattern below their diagonal block,
//    stored as dense column-major blocks (Ng and Peyton, SIAM J. Sci. Comput.
//    14(5), 1993; Davis, "Direct Methods for Sparse Linear Systems", SIAM
//    2006, Ch. 4). Each supernode receives the updates of the supernodes
//    below it, C -= A B^T, then factors its diagonal block and scales its
//    off-diagonal block, in panels of columns. The inner products run in
//    SubtractProducts steps (double_double.h: one renormalization per 8
//    products, within the same Cray-style model), vectorized over rows with
//    AVX2+FMA when the CPU has them: bitwise the same results as the
//    portable code, since each entry sees the same operations in the same
//    order and the lanes are independent entries.
//  - simplicial: the up-looking (row by row) scheme (Davis Ch. 4), kept as
//    the reference (double-double only).
// Results do not depend on the machine (std::fma is correctly rounded in
// hardware or in software; the file is compiled with -ffp-contract=off).
//
// The matrix is given already permuted (the caller chooses the fill-reducing
// ordering), as the upper triangle in compressed columns.

#ifndef CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_
#define CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_

#include <chrono>
#include <functional>
#include <memory>
#include <vector>

#include "ceres_sesync/internal/double_double.h"
#include "ceres_sesync/internal/huge_page_allocator.h"
#include "ceres_sesync/internal/tree_split.h"

namespace ceres_sesync::internal {

class DoubleDoubleCholesky {
 public:
  struct Options {
    // Supernodal (dense kernels) or the simplicial up-looking reference.
    bool supernodal = true;
    // Use the SIMD kernels when the CPU has AVX2 and FMA. The results are
    // bitwise identical either way (tests compare); false is for testing.
    bool vectorize = true;
    // Threads of the supernodal factorization: large elimination trees are
    // split (tree_split.h) into bins of subtrees, factored concurrently, and
    // their top, whose wide supernodes take their updates in column ranges
    // over the threads. The split depends on the matrix only: the results
    // are bitwise the same for every thread count.
    int num_threads = 1;
    // Factorizations of fewer multiply-adds (sum over columns of count^2 /
    // 2) are not split: a few milliseconds, where threads cost more than
    // they save. Tests lower it to split small matrices.
    double min_split_flops = 4e6;
  };

  DoubleDoubleCholesky() : DoubleDoubleCholesky(Options()) {}
  explicit DoubleDoubleCholesky(const Options& options);

  // Symbolic analysis of the n x n pattern: column k of the upper triangle
  // holds the rows row_index[column_start[k] .. column_start[k+1]) (each
  // <= k, no duplicates; the diagonal must be present). O(nnz(L)).
  //
  // With `block_start` (0 = block_start[0] < ... < block_start.back() = n),
  // the columns form consecutive blocks and the pattern must be block-full:
  // where two blocks share an entry they share all (the diagonal blocks
  // full), as in matrices of d x d blocks per pose in an ordering that keeps
  // each pose's unknowns together. The analysis is then that of the same
  // scalar pattern, with the elimination tree, the counts and the
  // supernodes' rows computed on the blocks (the maps of the values stay
  // per entry: kitti_00's analyses take ~16% less time).
  // CHECK-fails on a pattern that is not block-full.
  void Analyze(int n, std::vector<int> column_start, std::vector<int> row_index,
               const std::vector<int>& block_start = {});
  // Uses `other`'s analysis (supernodal, the same min_split_flops) instead
  // of running Analyze() again on the same pattern: the analysis is
  // immutable and shared, the numeric factors stay separate. Costs O(1).
  void ShareAnalysis(const DoubleDoubleCholesky& other);

  // Numerical factorization with values[p] the entry row_index[p] of the
  // pattern. Returns false if a pivot is not positive (A is not positive
  // definite, up to the backward error) or if a value is so small that the
  // arithmetic could underflow (then nothing is proven).
  // With a `deadline`, the factorization stops (returns false, timed_out())
  // when it passes, checked between supernodes.
  bool Factorize(const std::vector<DoubleDouble>& values,
                 std::chrono::steady_clock::time_point deadline =
                     std::chrono::steady_clock::time_point::max());
  // The same in double (supernodal only): the same schedule and kernels
  // with one FMA per product, l_jj = sqrt(.) and l_ij = (.) / l_jj
  // correctly rounded (Higham's Algorithm 10.2 in some order of summation),
  // so RowBackwardErrorBounds() then gives the double bound gamma_{k+1}
  // |L| |L^T|. Half the memory of the double-double factor and, measured,
  // ~1/5 its time.
  bool Factorize(const std::vector<double>& values,
                 std::chrono::steady_clock::time_point deadline =
                     std::chrono::steady_clock::time_point::max());
  // The last Factorize() stopped at its deadline.
  bool timed_out() const { return timed_out_; }
  // Whether the last Factorize() was the double-double one.
  bool extended() const { return extended_factor_; }
  // Frees the numeric factor (the dense blocks); the analysis is kept.
  void ReleaseNumericFactor();
  // After a successful supernodal Factorize(): f(first, ncols, rows, nrows,
  // values) for every supernode in order: columns first .. first + ncols -
  // 1, their rows rows[0 .. nrows) (the columns, then the rows below them,
  // ascending) and the nrows x ncols block of L, column-major, high parts
  // only (for SparseCholeskyFactor's supernodal constructor).
  void ForEachSupernode(const std::function<void(int, int, const int*, int,
                                                 const double*)>& f) const;

  // After a successful Factorize(): rho_i >= sum_j |E_ij| for every row i
  // (permuted order), with the rounding of this computation itself covered.
  void RowBackwardErrorBounds(std::vector<double>* rho) const;

  int size() const { return symbolic_->n; }
  // Entries of L (after Analyze()).
  long long factor_nonzeros() const {
    return symbolic_->factor_start.empty() ? 0 : symbolic_->factor_start.back();
  }
  // After a successful Factorize(): L in compressed columns (each column's
  // diagonal first, then its rows in increasing order). The supernodal
  // scheme keeps L in its dense blocks: factor_value() copies it out on its
  // first call after a factorization (for inspection and tests).
  const std::vector<int>& factor_start() const {
    return symbolic_->factor_start;
  }
  // The supernodal scheme keeps L's rows per supernode: factor_row() lists
  // them by column on its first call after Analyze().
  const HugePageVector<int>& factor_row() const;
  const std::vector<DoubleDouble>& factor_value() const;
  // Multiply-adds of one factorization: sum over columns of count^2 / 2.
  double flops() const { return symbolic_->flops; }
  // After Analyze(), supernodal: the supernodes and their stored entries
  // (dense blocks, including the explicit zeros of merged supernodes and
  // the unused upper triangles of the diagonal blocks).
  // Supernode s holds columns supernode_start()[s] .. [s + 1] - 1.
  const std::vector<int>& supernode_start() const {
    return symbolic_->super_start;
  }
  int num_supernodes() const {
    return symbolic_->super_start.empty()
               ? 0
               : static_cast<int>(symbolic_->super_start.size()) - 1;
  }
  long long supernodal_entries() const {
    return symbolic_->super_value_start.empty()
               ? 0
               : symbolic_->super_value_start.back();
  }
  // After Analyze(): bins of the parallel factorization (0: not split).
  int num_bins() const {
    return symbolic_->super_bin.empty() ? 0 : kTreeSplitBins;
  }
  // Whether Factorize() uses the SIMD kernels.
  bool vectorized() const { return vectorized_; }

 private:
  // The symbolic analysis: everything Analyze() computes from the pattern,
  // immutable once built and shared by the objects that factor it
  // (ShareAnalysis()).
  struct Symbolic {
    int n = 0;
    std::vector<int> column_start, row_index;  // The upper triangle of A.
    std::vector<int> parent;                   // Elimination tree.
    std::vector<int> factor_start;             // Column pointers of L.
    std::vector<int> row_count;                // Entries per row of L.
    double flops = 0;
    // Supernodes: columns super_start[s] .. super_start[s+1] - 1, rows
    // super_row[super_row_start[s] ..] (increasing, its columns first),
    // values (column-major, leading dimension = its row count) at
    // super_value_start[s] in the dense blocks of FactorizeSupernodal().
    std::vector<int> super_start, super_row_start, super_row;
    std::vector<long long> super_value_start;
    std::vector<int> column_super;  // Supernode of each column.
    // Bin of each supernode (-1: top) of the parallel factorization, or
    // empty.
    std::vector<int> super_bin;
    // Input values by the column of L they are in: those of column j are
    // scatter_source[q] for q in scatter_start[j] .. scatter_start[j+1] - 1,
    // at block entry scatter_destination[q].
    std::vector<int> scatter_start, scatter_source;
    std::vector<long long> scatter_destination;
  };
  // The block pattern of a block-full Analyze(): block C's rows R < C (in
  // increasing order) at rows[start[C] ..], and the block of each column.
  struct BlockPattern {
    std::vector<int> block_start, start, rows, block_of;
  };
  // The elimination tree, counts and flops of the pattern, scalar or by its
  // blocks.
  static void AnalyzeColumns(Symbolic* symbolic);
  static void AnalyzeColumns(const BlockPattern& blocks, Symbolic* symbolic);
  static void AnalyzeSupernodes(const Options& options,
                                const BlockPattern* blocks, Symbolic* symbolic);
  // Installs an analysis and drops any numeric factor.
  void SetSymbolic(std::shared_ptr<const Symbolic> symbolic);
  // f(row, value) for every entry of column c of L in order (the diagonal
  // first), in either layout.
  template <typename F>
  void ForEachEntry(int c, F&& f) const {
    const Symbolic& sym = *symbolic_;
    if (!options_.supernodal) {
      for (int p = sym.factor_start[c]; p < sym.factor_start[c + 1]; ++p) {
        f(factor_row_[p], factor_value_[p]);
      }
      return;
    }
    const int s = sym.column_super[c], jj = c - sym.super_start[s];
    const int* rows = sym.super_row.data() + sym.super_row_start[s];
    const int nrows = sym.super_row_start[s + 1] - sym.super_row_start[s];
    const long long at =
        sym.super_value_start[s] + static_cast<long long>(jj) * nrows;
    const double* hi = super_hi_.data() + at;
    if (!extended_factor_) {
      for (int t = jj; t < nrows; ++t) f(rows[t], DoubleDouble(hi[t]));
      return;
    }
    const double* lo = super_lo_.data() + at;
    for (int t = jj; t < nrows; ++t) f(rows[t], DoubleDouble(hi[t], lo[t]));
  }
  // Both Factorize(); Value: DoubleDouble or double.
  template <typename Value>
  bool FactorizeValues(const std::vector<Value>& values,
                       std::chrono::steady_clock::time_point deadline);
  template <typename Value>
  bool FactorizeSupernodal(const std::vector<Value>& values,
                           std::chrono::steady_clock::time_point deadline);

  Options options_;
  bool vectorized_ = false;
  // Empty until Analyze() or ShareAnalysis().
  std::shared_ptr<const Symbolic> symbolic_;
  // Row indices of L (simplicial; for the supernodal scheme a copy made by
  // factor_row() on demand).
  mutable HugePageVector<int> factor_row_;
  // Values of L (simplicial; for the supernodal scheme a copy made by
  // factor_value() on demand).
  mutable std::vector<DoubleDouble> factor_value_;
  // The supernodal scheme's dense blocks (see Symbolic::super_value_start),
  // which hold L after a successful factorization.
  HugePageVector<double> super_hi_, super_lo_;
  bool factorized_ = false;
  bool extended_factor_ = true;  // The last factorization's arithmetic.
  bool timed_out_ = false;
};

// The input of DoubleDoubleCholesky::Analyze() for a symmetric n x n matrix A
// permuted to P A P^T: A is given in compressed columns (outer, inner, both
// triangles or only the lower one; entries above the diagonal are skipped)
// and P by position[i] = the pivot (row of P A P^T) of A's row i. Entry
// (r >= c) of A goes to column max(position[r], position[c]) and row
// min(..) of the upper triangle; slot[q] is where A's stored entry q goes
// (in row_index and so in the values Factorize() takes), -1 for a skipped
// one. Rows within a column are in no particular order (Analyze() needs
// none). O(n + nnz(A)).
struct PermutedPattern {
  std::vector<int> column_start, row_index, slot;
};
// The same, completed to the block-full pattern of the blocks block_start
// (in pivot order: see Analyze()): the pattern gains the explicit zeros that
// make every block pair with an entry whole. Rows within a column ascend.
PermutedPattern PermuteSymmetricBlockPattern(
    int n, const int* outer, const int* inner, const std::vector<int>& position,
    const std::vector<int>& block_start);
PermutedPattern PermuteSymmetricPattern(int n, const int* outer,
                                        const int* inner,
                                        const std::vector<int>& position);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_EXTENDED_CHOLESKY_H_
