#include "ceres_sesync/internal/certificate_matrix.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

#include "Eigen/Eigenvalues"
#include "ceres_sesync/internal/double_double.h"
#include "ceres_sesync/internal/extended_cholesky.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {

using Triplet = Eigen::Triplet<double>;
constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

namespace {

// A fill-reducing ordering of K from one of the vertices: K has the pattern
// of M collapsed to vertices (the translational Laplacian of a pose graph)
// with every vertex expanded into its translation (absent for the gauge
// node and for a world vertex without t_w) and its d rotation unknowns
// (absent for landmarks), so ordering the vertices (about 1 / (d+1)^2 of K's
// entries) and expanding gives K's ordering at a fraction of the cost of
// ordering K itself. block_start: where each vertex's unknowns begin in it.
std::vector<int> BlockOrdering(const SESyncProblem& problem,
                               std::vector<int>* block_start) {
  const ProblemLayout& layout = problem.layout();
  const int n = problem.num_rotations(), d = problem.dimension();
  const int t0 = problem.num_translations() - 1;
  std::vector<int> ordering;
  ordering.reserve(t0 + d * n);
  block_start->assign(1, 0);
  for (int v : problem.vertex_ordering()) {
    const int node = layout.translation_of_vertex(v);
    if (node >= 0 && layout.reduced(node) >= 0) {
      ordering.push_back(layout.reduced(node));
    }
    const int block = layout.rotation_of_vertex(v);
    if (block >= 0) {
      for (int a = 0; a < d; ++a) ordering.push_back(t0 + d * block + a);
    }
    if (static_cast<int>(ordering.size()) > block_start->back()) {
      block_start->push_back(static_cast<int>(ordering.size()));
    }
  }
  return ordering;
}

}  // namespace

const char* ProofPrecisionName(ProofPrecision precision) {
  return precision == ProofPrecision::kDouble ? "double" : "double-double";
}

CertificateMatrix::CertificateMatrix(const SESyncProblem& problem)
    : problem_(problem),
      d_(problem.dimension()),
      n_(problem.num_rotations()),
      translation_size_(problem.num_translations() - 1),
      rotation_size_(problem.dimension() * problem.num_rotations()) {
  CHECK_LE(d_, 3);  // Assemble's row sums.
  const int t0 = translation_size_, d = d_;
  K_ = BaseMatrix();
  translation_diagonal_.reserve(t0);
  for (int j = 0; j < t0; ++j) {
    // Lower triangle, sorted rows: the diagonal leads its column.
    const int k = K_.outerIndexPtr()[j];
    CHECK_EQ(K_.innerIndexPtr()[k], j);
    translation_diagonal_.push_back(k);
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
  SetData(K_);
  std::vector<int> block_start;
  ordering_ = BlockOrdering(problem, &block_start);
  std::vector<int> permuted_start, permuted_row;
  InitializePermutedPattern(block_start, &permuted_start, &permuted_row);
  pattern_entries_ = permuted_start.back();
  DoubleDoubleCholesky::Options options;
  options.num_threads = problem_.num_threads();
  double_ = std::make_unique<DoubleDoubleCholesky>(options);
  double_->Analyze(static_cast<int>(K_.rows()), std::move(permuted_start),
                   std::move(permuted_row), block_start);
}

double CertificateMatrix::FactorizationCostInSolves(int r) const {
  // Two flops per multiply-add; the solves' cost: 4 r nnz(L).
  return 2 * double_->flops() /
         (4.0 * r * std::max<double>(1, double_->factor_nonzeros()));
}

double CertificateMatrix::factorization_flops() const {
  return double_->flops();
}

double CertificateMatrix::factor_nonzeros() const {
  return static_cast<double>(double_->factor_nonzeros());
}

bool CertificateMatrix::supernodal() const {
  return 2 * double_->flops() >=
         kSupernodalSwitch * std::max<double>(1, double_->factor_nonzeros());
}

SparseMatrix CertificateMatrix::BaseMatrix() const {
  // K's lower triangle column by column, straight into compressed storage
  // (a triplet list and its sort took 3.3 s on the 10^6-pose city): column
  // j < t0 holds Lbar's rows >= j, then -Vbar's row j at rows t0 + q;
  // column t0 + q (q = d i + b) holds its diagonal block's rows t0 + d i +
  // a, a >= b (structural zeros where D has none), then D's rows below the
  // block. Every source's columns are sorted, so the result is.
  const int t0 = translation_size_, d = d_;
  const SparseMatrix& L = problem_.Lbar();
  const SparseMatrix& D = problem_.D();
  const SparseMatrix Vt = problem_.Vbar().transpose();  // Row j: column j.
  const int size = t0 + rotation_size_;
  SparseMatrix K(size, size);
  std::vector<int> start(size + 1, 0);
  auto below = [](const SparseMatrix& A, int col, int row) {
    const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[col];
    const int* end = A.innerIndexPtr() + A.outerIndexPtr()[col + 1];
    return static_cast<int>(std::lower_bound(begin, end, row) -
                            A.innerIndexPtr());
  };
  for (int j = 0; j < t0; ++j) {
    start[j + 1] = start[j] + (L.outerIndexPtr()[j + 1] - below(L, j, j)) +
                   (Vt.outerIndexPtr()[j + 1] - Vt.outerIndexPtr()[j]);
  }
  for (int q = 0; q < rotation_size_; ++q) {
    const int block_end = q - q % d + d;
    start[t0 + q + 1] = start[t0 + q] + (block_end - q) +
                        (D.outerIndexPtr()[q + 1] - below(D, q, block_end));
  }
  K.resizeNonZeros(start[size]);
  int* outer = K.outerIndexPtr();
  int* inner = K.innerIndexPtr();
  double* value = K.valuePtr();
  std::copy(start.begin(), start.end(), outer);
  int p = 0;
  for (int j = 0; j < t0; ++j) {
    for (int k = below(L, j, j); k < L.outerIndexPtr()[j + 1]; ++k, ++p) {
      inner[p] = L.innerIndexPtr()[k];
      value[p] = L.valuePtr()[k];
    }
    for (int k = Vt.outerIndexPtr()[j]; k < Vt.outerIndexPtr()[j + 1];
         ++k, ++p) {
      inner[p] = t0 + Vt.innerIndexPtr()[k];
      value[p] = -Vt.valuePtr()[k];
    }
  }
  for (int q = 0; q < rotation_size_; ++q) {
    const int block_end = q - q % d + d;
    int k = below(D, q, q);
    const int k_end = D.outerIndexPtr()[q + 1];
    for (int row = q; row < block_end; ++row, ++p) {
      inner[p] = t0 + row;
      value[p] = 0.0;
      if (k < k_end && D.innerIndexPtr()[k] == row) {
        value[p] += D.valuePtr()[k++];  // + 0.0: as the triplets summed.
      }
    }
    for (; k < k_end; ++k, ++p) {
      inner[p] = t0 + D.innerIndexPtr()[k];
      value[p] = D.valuePtr()[k];
    }
  }
  CHECK_EQ(p, start[size]);
  return K;
}

void CertificateMatrix::SetData(const SparseMatrix& base) {
  const int t0 = translation_size_;
  base_values_.assign(base.valuePtr(), base.valuePtr() + base.nonZeros());
  data_rounding_.resize(base.rows());
  for (int k = 0; k < problem_.num_translations(); ++k) {
    const int j = problem_.layout().reduced(k);
    if (j >= 0) data_rounding_[j] = problem_.translation_row_rounding()[k];
  }
  for (int q = 0; q < rotation_size_; ++q) {
    data_rounding_[t0 + q] = problem_.rotation_row_rounding()[q];
  }
  // The translation rows of K's factor carry round-off of the size of
  // Lbar's own factorization in the same rows (measured, K's double bound
  // over Lbar's, row by row, on twelve maps up to 10^5 poses: median 6-19,
  // at most 27), so each row's first double shift is 64 times Lbar's bound
  // plus twice the data's rounding. The shifts adapt to the bounds they
  // meet.
  std::vector<double> lbar = problem_.LbarRowBackwardErrors();
  CHECK_EQ(static_cast<int>(lbar.size()), t0);
  double_shift_.resize(t0);
  double head = 0;
  for (int j = 0; j < t0; ++j) {
    double_shift_[j] = 64 * lbar[j] + 2 * data_rounding_[j];
    head = std::max(head, double_shift_[j]);
  }
  extended_shift_ = head * kDoubleDoubleUnitRoundoff / kUnitRoundoff;
}

void CertificateMatrix::Refresh() {
  const SparseMatrix base = BaseMatrix();
  const int size = static_cast<int>(K_.rows());
  CHECK(base.nonZeros() == K_.nonZeros() &&
        std::equal(base.outerIndexPtr(), base.outerIndexPtr() + size + 1,
                   K_.outerIndexPtr()) &&
        std::equal(base.innerIndexPtr(), base.innerIndexPtr() + K_.nonZeros(),
                   K_.innerIndexPtr()))
      << "certificate matrix: the problem's sparsity pattern changed";
  SetData(base);
}

CertificateMatrix::~CertificateMatrix() = default;

void CertificateMatrix::Assemble(const Eigen::MatrixXd& Lambda, double c,
                                 const std::vector<double>& mu,
                                 std::vector<double>* rounding) {
  std::copy(base_values_.begin(), base_values_.end(), K_.valuePtr());
  rounding->assign(K_.rows(), 0.0);
  // Lbar_jj - mu_j: one rounding.
  for (int j = 0; j < static_cast<int>(mu.size()); ++j) {
    double& value = K_.valuePtr()[translation_diagonal_[j]];
    (*rounding)[j] = 2 * kUnitRoundoff * (std::abs(value) + mu[j]);
    value -= mu[j];
  }
  const int d = d_, t0 = translation_size_;
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
    // Two roundings per entry (- Lambda, + c): each assembled entry is
    // within 2u (|entry| + c) of its exact value (4u to cover second-order
    // terms); Gershgorin over the d x d block.
    for (int a = 0; a < d; ++a) {
      (*rounding)[t0 + d * i + a] = 4 * kUnitRoundoff * (row_sum[a] + c);
    }
  }
}

double CertificateMatrix::PredictedSeconds(ProofPrecision precision) const {
  if (precision == ProofPrecision::kDouble) return last_double_seconds_;
  return last_extended_seconds_ > 0 ? last_extended_seconds_
                                    : 4.6 * last_double_seconds_;
}

bool CertificateMatrix::FactorizeDouble() {
  const auto start = std::chrono::steady_clock::now();
  ++double_factorizations_;
  solver_.reset();
  std::vector<double> values(pattern_entries_, 0.0);
  for (int q = 0; q < K_.nonZeros(); ++q) {
    values[permuted_index_[q]] = K_.valuePtr()[q];
  }
  double_factorized_ = double_->Factorize(values);
  last_double_seconds_ =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();
  double_completed_ = double_completed_ || double_factorized_;
  return double_factorized_;
}

bool CertificateMatrix::Factorize(const Eigen::MatrixXd& Lambda, double c) {
  std::vector<double> unused;
  factorized_shift_.clear();
  Assemble(Lambda, c, factorized_shift_, &unused);
  return FactorizeDouble();
}

void CertificateMatrix::ReleaseFactor() {
  double_->ReleaseNumericFactor();
  double_factorized_ = false;
  solver_.reset();
}

SparseCholeskyFactor CertificateMatrix::ExtractFactor() const {
  CHECK(double_factorized_) << "ExtractFactor() without a factor";
  return SparseCholeskyFactor(
      ordering_,
      [this](const SparseCholeskyFactor::SupernodeVisitor& supernode) {
        double_->ForEachSupernode(supernode);
      });
}

bool CertificateMatrix::Prove(const Eigen::MatrixXd& Lambda, double c,
                              ProofPrecision precision) {
  proven_shift_ = backward_error_ = std::numeric_limits<double>::infinity();
  timed_out_ = false;
  return precision == ProofPrecision::kDouble ? ProveDouble(Lambda, c)
                                              : ProveDoubleDouble(Lambda, c);
}

bool CertificateMatrix::SettleShift(double head, double* mu) const {
  if (head <= *mu) return true;
  *mu = 2 * head;  // Too small: the next attempt covers this bound twice.
  return false;
}

double CertificateMatrix::DoubleShiftCost(
    const Eigen::MatrixXd& offsets) const {
  return ShiftCost(double_shift_, offsets);
}

double CertificateMatrix::FactorShiftCost(
    const Eigen::MatrixXd& offsets) const {
  return ShiftCost(factorized_shift_, offsets);
}

double CertificateMatrix::ShiftCost(const std::vector<double>& shifts,
                                    const Eigen::MatrixXd& offsets) const {
  if (offsets.size() == 0 || shifts.empty()) return 0;
  CHECK_EQ(offsets.cols(), translation_size_);
  // S's near-null directions x_a (row a of the rotations, |x_a|^2 = n) move
  // translation row j by offsets(a, j): to first order the shift lowers
  // lambda_min(S) by the largest eigenvalue of C = sum_j mu_j o_j o_j^T / n
  // (d x d; the coordinates' cross terms count: up to d times the largest
  // diagonal entry where offsets are correlated, as from a corner).
  const Eigen::Map<const Eigen::VectorXd> mu(shifts.data(), translation_size_);
  const Eigen::MatrixXd C =
      offsets * mu.asDiagonal() * offsets.transpose() / n_;
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(C,
                                                        Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

Eigen::MatrixXd CertificateMatrix::TranslationOffsets(
    const Eigen::MatrixXd& T) const {
  const ProblemLayout& layout = problem_.layout();
  CHECK_EQ(T.cols(), problem_.num_translations());
  Eigen::MatrixXd offsets(T.rows(), translation_size_);
  const Eigen::VectorXd origin = T.col(layout.gauge());
  for (int k = 0; k < T.cols(); ++k) {
    const int j = layout.reduced(k);
    if (j >= 0) offsets.col(j) = T.col(k) - origin;
  }
  return offsets;
}

bool CertificateMatrix::ProveDouble(const Eigen::MatrixXd& Lambda, double c) {
  const int t0 = translation_size_;
  for (int attempt = 0; attempt < 3; ++attempt) {
    factorized_shift_ = double_shift_;
    std::vector<double> rounding, rho;
    Assemble(Lambda, c, factorized_shift_, &rounding);
    if (!FactorizeDouble()) return false;
    double_->RowBackwardErrorBounds(&rho);
    // Row i's bound, in K's order (overwriting rounding).
    std::vector<double>& bound = rounding;
    for (int i = 0; i < static_cast<int>(bound.size()); ++i) {
      bound[i] += rho[position_[i]] + data_rounding_[i];
    }
    // Row j of the translation block settles when its bound is within its
    // shift mu_j; a row that does not gets twice its bound next time.
    bool settled = true;
    for (int j = 0; j < t0; ++j) {
      settled = SettleShift(bound[j], &double_shift_[j]) && settled;
    }
    if (settled) {
      // The largest of a range of nonnegative values (0 if it is empty).
      auto largest = [](auto first, auto last) {
        return std::accumulate(first, last, 0.0, [](double a, double b) {
          return std::max(a, b);
        });
      };
      const double head = largest(bound.begin(), bound.begin() + t0);
      const double tail = largest(bound.begin() + t0, bound.end());
      const double largest_shift =
          largest(factorized_shift_.begin(), factorized_shift_.end());
      backward_error_ = tail;
      proven_shift_ = c + tail;
      // Next time start closer to what this one needed, row by row.
      for (int j = 0; j < t0; ++j) {
        double_shift_[j] =
            std::max(1.5 * bound[j], std::numeric_limits<double>::min());
      }
      VLOG(1) << "K_c proven (double): c " << c << " backward error " << tail
              << " (translation rows " << head << ", largest shift "
              << largest_shift << ")";
      return true;
    }
  }
  LOG(WARNING) << "certificate matrix: the translation block's round-off "
                  "bound did not settle; no proof from this factorization";
  return false;
}

void CertificateMatrix::InitializePermutedPattern(
    const std::vector<int>& block_start, std::vector<int>* permuted_start,
    std::vector<int>* permuted_row) {
  const int size = static_cast<int>(K_.rows());
  position_.resize(size);  // Original index -> pivot order.
  for (int k = 0; k < size; ++k) position_[ordering_[k]] = k;
  PermutedPattern pattern = PermuteSymmetricBlockPattern(
      size, K_.outerIndexPtr(), K_.innerIndexPtr(), position_, block_start);
  *permuted_start = std::move(pattern.column_start);
  *permuted_row = std::move(pattern.row_index);
  permuted_index_ = std::move(pattern.slot);
}

void CertificateMatrix::InitializeDoubleDouble() {
  DoubleDoubleCholesky::Options options;
  options.num_threads = problem_.num_threads();
  extended_ = std::make_unique<DoubleDoubleCholesky>(options);
  extended_->ShareAnalysis(*double_);
}

bool CertificateMatrix::ProveDoubleDouble(const Eigen::MatrixXd& Lambda,
                                          double c) {
  const auto begin = std::chrono::steady_clock::now();
  struct Timer {
    std::chrono::steady_clock::time_point begin;
    double* total;
    ~Timer() {
      *total += std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                              begin)
                    .count();
    }
  } timer{begin, &extended_time_s_};
  if (!extended_) InitializeDoubleDouble();
  const int size = static_cast<int>(K_.rows());
  const int t0 = translation_size_, d = d_;
  const int* outer = K_.outerIndexPtr();
  const int* inner = K_.innerIndexPtr();
  auto index = [&](int row, int col) {  // Value index of K_(row >= col).
    const int* pos =
        std::lower_bound(inner + outer[col], inner + outer[col + 1], row);
    DCHECK(pos != inner + outer[col + 1] && *pos == row);
    return static_cast<int>(pos - inner);
  };
  // K_c from the measurements (with the problem's weights, as doubles:
  // measurement_weights.h): the data terms in double-double (products
  // of two doubles exact, of three within 5u^2, sums within 3.2u^2) and
  // per-row sums of |terms| with their counts for the assembly's bound.
  // Translation nodes map to K's rows through ProblemLayout::reduced (the
  // gauge node, fixed at 0, has none), rotation indices q to t0 + q.
  std::vector<DoubleDouble> base(K_.nonZeros());
  std::vector<double> abs_sum(size, 0.0);
  std::vector<int> count(size, 0);
  const ProblemLayout& layout = problem_.layout();
  ForEachDataTerm<DoubleDouble>(
      problem_.graph(), problem_.weights(),
      [&](DataBlock block, int row, int col, const DoubleDouble& value) {
        const double magnitude = value.AbsUpperBound();
        // Exact zeros (zero weights) carry no rounding: not counted.
        const int term = value.hi != 0 || value.lo != 0 ? 1 : 0;
        switch (block) {
          case DataBlock::kTranslation: {
            const int r = layout.reduced(row), s = layout.reduced(col);
            if (r < 0 || s < 0) return;  // The gauge node: fixed at 0.
            abs_sum[r] += magnitude;
            count[r] += term;
            if (r >= s) base[index(r, s)] += value;
            return;
          }
          case DataBlock::kCoupling: {  // -V at (translation, rotation).
            const int r = layout.reduced(row), s = t0 + col;
            if (r < 0) return;
            abs_sum[r] += magnitude;
            count[r] += term;
            abs_sum[s] += magnitude;
            count[s] += term;
            base[index(s, r)] -= value;
            return;
          }
          case DataBlock::kRotation:
          case DataBlock::kRotationSigma: {
            const int r = t0 + row, s = t0 + col;
            abs_sum[r] += magnitude;
            count[r] += term;
            if (r >= s) base[index(r, s)] += value;
            return;
          }
        }
      });
  for (int attempt = 0; attempt < 3; ++attempt) {
    const double mu = extended_shift_;
    std::vector<DoubleDouble> values(pattern_entries_);
    std::vector<double> assembly_abs(abs_sum);
    std::vector<int> assembly_count(count);
    for (int q = 0; q < K_.nonZeros(); ++q)
      values[permuted_index_[q]] = base[q];
    for (int j = 0; j < t0; ++j) {
      DoubleDouble& v = values[permuted_index_[translation_diagonal_[j]]];
      v -= DoubleDouble(mu);
      assembly_abs[j] += mu;
      ++assembly_count[j];
    }
    int k = 0;
    for (int i = 0; i < n_; ++i) {
      for (int b = 0; b < d; ++b) {
        for (int a = b; a < d; ++a) {
          DoubleDouble& v = values[permuted_index_[block_entry_[k++]]];
          const double lambda = Lambda(a, d * i + b);
          v -= DoubleDouble(lambda);
          if (a == b) v += DoubleDouble(c);
          const int r = t0 + d * i + a, s = t0 + d * i + b;
          assembly_abs[r] += std::abs(lambda) + (a == b ? c : 0);
          assembly_count[r] += 2;
          if (a != b) {
            assembly_abs[s] += std::abs(lambda);
            assembly_count[s] += 2;
          }
        }
      }
    }
    ++extended_factorizations_;
    const auto start = std::chrono::steady_clock::now();
    const bool factorized = extended_->Factorize(values, deadline_);
    timed_out_ = extended_->timed_out();
    if (!timed_out_) {
      last_extended_seconds_ = std::chrono::duration<double>(
                                   std::chrono::steady_clock::now() - start)
                                   .count();
    }
    if (!factorized) return false;
    std::vector<double> rho;
    extended_->RowBackwardErrorBounds(&rho);
    double head = 0, tail = 0;
    for (int i = 0; i < size; ++i) {
      // Each entry: at most `count` terms, each with two roundings, summed:
      // within gamma_{count + 3} of the exact value.
      const double assembly = DoubleDoubleGamma(assembly_count[i] + 3) *
                              assembly_abs[i] * (1 + 1e-6);
      const double bound = rho[position_[i]] + assembly;
      double& side = i < t0 ? head : tail;
      side = std::max(side, bound);
    }
    if (SettleShift(head, &extended_shift_)) {
      backward_error_ = tail;
      proven_shift_ = c + tail;
      extended_shift_ =
          std::max(1.5 * head, std::numeric_limits<double>::min());
      VLOG(1) << "K_c proven (double-double): c " << c << " backward error "
              << tail << " (translation rows " << head << ", shift " << mu
              << ")";
      return true;
    }
  }
  LOG(WARNING) << "certificate matrix: the translation block's round-off "
                  "bound did not settle (double-double)";
  return false;
}

void CertificateMatrix::SolveShifted(const Eigen::MatrixXd& Y,
                                     Eigen::MatrixXd* X) const {
  CHECK(double_factorized_) << "SolveShifted() without a factor";
  if (!solver_)
    solver_ = std::make_unique<SparseCholeskyFactor>(ExtractFactor());
  Eigen::MatrixXd solution;
  solver_->SolveRowsTail(Y.transpose(), translation_size_, &solution,
                         problem_.num_threads());
  *X = solution.transpose();
}

void CertificateMatrix::SolveShifted(const Eigen::VectorXd& y,
                                     Eigen::VectorXd* x) const {
  Eigen::MatrixXd solution;
  SolveShifted(Eigen::MatrixXd(y), &solution);
  *x = solution.col(0);
}

}  // namespace ceres_sesync::internal
