// Sparse test of the SE-Sync optimality certificate.
//
// For multipliers Lambda (block diagonal, n symmetric d x d blocks) the
// certificate matrix is S = Q - Lambda (Rosen et al. 2019, Section 5.3). Q is
// dense, but S + cI is the Schur complement of the positive definite block
// Lbar in the sparse matrix
//
//   K_c = [ Lbar     -Vbar            ]     ((n-1) + dn square),
//         [ -Vbar^T   D - Lambda + cI ]
//
// so S + cI is positive definite if and only if K_c is, and a sparse Cholesky
// factorization of K_c proves lambda_min(S) > -c, up to round-off, which
// Prove() accounts for completely (see there). The same factorization (in
// double) applies (S + cI)^{-1}, which the shift-and-invert eigensolver uses.
//
// Both arithmetics run the supernodal factorization of extended_cholesky.h
// (threaded, in the problem's vertex ordering, symbolic analyses kept):
// double for solves and fast proofs, double-double for proofs that double
// cannot resolve. (CHOLMOD did the double ones before: at 10^5 poses its
// serial factorization took 3.3x the time of this one on one thread, 5.9x
// on two.)

#ifndef CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_
#define CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_

#include <algorithm>
#include <chrono>
#include <memory>
#include <utility>
#include <vector>

#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {

class DoubleDoubleCholesky;

// The arithmetic of a proof's factorization.
enum class ProofPrecision {
  kDouble,        // Fast; resolves ~1e-16 of K's scale.
  kDoubleDouble,  // ~1e-31 of K's scale, 1.8-4.6x slower (measured).
};
const char* ProofPrecisionName(ProofPrecision precision);

class CertificateMatrix {
 public:
  // `problem` must outlive this object. K's base values (without Lambda and
  // c) and the data's rounding bounds are copied from it here.
  explicit CertificateMatrix(const SESyncProblem& problem);
  ~CertificateMatrix();

  // After problem.UpdateWeights(): copies the new base values and rounding
  // bounds. The pattern is the same, so the symbolic analyses (of the
  // double and the double-double factorization) are kept; the next
  // factorization is numeric only. The double-double proofs assemble from
  // ForEachDataTerm with the problem's weights, so they are of the weighted
  // problem too.
  void Refresh();

  // Factorizes K_c in double for solves (the preconditioner, the
  // eigensolver): no proof. Returns true iff the factorization completed.
  bool Factorize(const Eigen::MatrixXd& Lambda, double c);

  // Tries to prove S + eta I positive semidefinite for eta = c + delta with a
  // small delta, accounting for all round-off. Returns true iff it did;
  // proven_shift() is then eta.
  //
  // The matrix factorized is K' = K_c - diag(M, 0), K_c assembled from the
  // measurements' exact values and M = diag(mu_j) > 0 a shift of the
  // translation block. A completed factorization L L^T = K'~ + E of the
  // assembled K'~ bounds, row by row, the factorization's backward error E
  // (DoubleDoubleCholesky::RowBackwardErrorBounds, gamma_{k+1} |L||L^T| in
  // either arithmetic) and the assembly's rounding A = K'~ - K':
  // K' + diag(rho) >= 0 with rho_i >= sum_j |E_ij| + |A_ij|. If rho_j <= mu_j
  // on every translation row j, then K_c + diag(0, delta I) >= 0 with delta
  // the largest rho_i on the rotation rows, and its Schur complement gives
  // S + (c + delta) I >= 0: a complete proof, with no first-order step.
  // The shifts are adapted until they cover their rows' bounds: in double
  // row by row (a row's bound varies 10-1000x across rows, smallest where
  // elimination is short), in double-double one mu for all rows. M costs
  // about sum_j mu_j (t_j - t_0)^2 / n in lambda_min (DoubleShiftCost: the
  // global rotations' translations, where S is near singular), which is
  // why the largest maps need double-double: its mu is ~1e15 times smaller.
  // Row by row, double's cost is 20-1500x below that of one mu for all rows
  // (the largest bound) on the benchmark maps. A double proof leaves its
  // factor for SolveShifted() (of S_M + cI, S_M = S - Vbar^T Lbar^-1 M
  // Lbar^-1 Vbar to first order).
  bool Prove(const Eigen::MatrixXd& Lambda, double c, ProofPrecision precision);

  // Frees the double factor (after ExtractFactor(), its copy is all that a
  // caller needs) and keeps the symbolic analysis. SolveShifted() needs a
  // new Factorize() or double Prove() after this.
  void ReleaseFactor();

  // After a successful Factorize() or double Prove(): x = (S_M + cI)^{-1} y,
  // y and x in R^{dn}, with M = diag(translation_shifts()) (none after
  // Factorize()).
  void SolveShifted(const Eigen::VectorXd& y, Eigen::VectorXd* x) const;
  // The same for the columns of Y (dn x k).
  void SolveShifted(const Eigen::MatrixXd& Y, Eigen::MatrixXd* X) const;
  // After a successful Factorize() (or double Prove()): a copy of the factor
  // for fast repeated solves X = V (S + cI)^{-1} with V of size r x dn
  // (SolveRowsTail with offset translation_size()).
  SparseCholeskyFactor ExtractFactor() const;
  int translation_size() const { return translation_size_; }

  // After a successful Prove(): eta = c + delta, delta and mu.
  double proven_shift() const { return proven_shift_; }
  double backward_error() const { return backward_error_; }
  // mu_j of the current double factor, by translation row j (empty after
  // Factorize()).
  const std::vector<double>& translation_shifts() const {
    return factorized_shift_;
  }
  // mu_j the next double proof starts with, by translation row j: 64 times
  // Lbar's row bound plus twice the data's rounding before the first proof,
  // 1.5 times the bounds the last one met after it.
  const std::vector<double>& next_double_shifts() const {
    return double_shift_;
  }
  // Replaces them (one per translation row; for tests: the proofs adapt
  // shifts that are too small, up to three attempts).
  void set_next_double_shifts(std::vector<double> shifts) {
    CHECK_EQ(static_cast<int>(shifts.size()), translation_size_);
    double_shift_ = std::move(shifts);
  }
  // What those shifts cost in lambda_min(S), to first order: the largest
  // eigenvalue of sum_j mu_j o_j o_j^T / n, o_j = offsets.col(j), offsets
  // (d x translation_size()) the candidate's translations from the gauge's
  // (TranslationOffsets(); none: 0). Double proofs at shifts below it fail.
  // (One mu for all rows and the largest coordinate's sum, as before, cost
  // 3-100x more on the benchmark maps.)
  double DoubleShiftCost(const Eigen::MatrixXd& offsets) const;
  // The same for the shifts of the current double factor
  // (translation_shifts(); 0 after Factorize()): how far below
  // lambda_min(S) a Lanczos estimate from that factor (of S_M) can be.
  double FactorShiftCost(const Eigen::MatrixXd& offsets) const;
  // t_k - t_gauge for the translation nodes k of T (d x
  // problem.num_translations(), RecoverTranslations()'s layout), by K's
  // translation row.
  Eigen::MatrixXd TranslationOffsets(const Eigen::MatrixXd& T) const;

  // A time limit for the factorizations (none by default): a double-double
  // factorization stops when it passes (Prove() then returns false and
  // timed_out() is true); double ones run to the end (a stopped one would
  // read as "not positive definite" to callers of Factorize()), so callers
  // ask PredictedSeconds() first.
  void set_deadline(std::chrono::steady_clock::time_point deadline) {
    deadline_ = deadline;
  }
  bool timed_out() const { return timed_out_; }
  // Seconds the next factorization in `precision` is expected to take (the
  // last one's time, same pattern; double-double before its first run:
  // 4.6x the double time, the measured upper end: 1.8x on ais2klinik, 2.7-4.0x
  // on the 3D datasets and city10000, 4.6x on a 10^5-pose city); 0 if unknown.
  double PredictedSeconds(ProofPrecision precision) const;
  // Whether a double factorization has completed (succeeded) on this matrix.
  bool double_completed() const { return double_completed_; }

  // Factorizations so far, by arithmetic, and the seconds spent in the
  // double-double ones (including their assembly).
  int double_factorizations() const { return double_factorizations_; }
  int extended_factorizations() const { return extended_factorizations_; }
  double extended_time_s() const { return extended_time_s_; }

  // A factorization's cost in units of the two triangular solves with r
  // right-hand sides that one preconditioned Hessian-vector product applies
  // with a factor of K's pattern: flops / (4 r nnz(L)) with two flops per
  // multiply-add, from the symbolic analysis (deterministic, unlike a
  // measured time).
  double FactorizationCostInSolves(int r) const;
  // Multiply-adds of one factorization (sum over columns of count^2 / 2).
  double factorization_flops() const;
  // Nonzeros of the factor L (diagonal included).
  double factor_nonzeros() const;

  // Dimension dn of S.
  int dimension() const { return rotation_size_; }
  // Factorizations cost much more than products with Q (3D graphs): flops /
  // nnz(L) >= kSupernodalSwitch, the rule by which CHOLMOD would choose its
  // supernodal layout here.
  bool supernodal() const;

 private:
  // K's pattern with the problem's current base values.
  SparseMatrix BaseMatrix() const;
  // base_values_, data_rounding_ and the initial shifts from `base`.
  void SetData(const SparseMatrix& base);
  // K_ = K_c with Lambda, c and the translation block Lbar - diag(mu) (mu
  // empty: Lbar); returns per-row bounds on the rounding of this assembly.
  void Assemble(const Eigen::MatrixXd& Lambda, double c,
                const std::vector<double>& mu, std::vector<double>* rounding);
  bool ProveDouble(const Eigen::MatrixXd& Lambda, double c);
  // DoubleShiftCost() for the translation rows' `shifts` (empty: 0).
  double ShiftCost(const std::vector<double>& shifts,
                   const Eigen::MatrixXd& offsets) const;
  // The double factorization of K_, counted and timed; true iff it completed.
  bool FactorizeDouble();
  bool ProveDoubleDouble(const Eigen::MatrixXd& Lambda, double c);
  // K_'s upper triangle permuted by ordering_ in compressed columns,
  // completed to whole vertex blocks (block_start: where each vertex's
  // unknowns begin in ordering_; the factorizations' pattern, analyzed by
  // blocks, with explicit zeros: 0.1-3% more flops than K_'s own pattern on
  // the datasets), the map of its values (permuted_index_) and position_.
  void InitializePermutedPattern(const std::vector<int>& block_start,
                                 std::vector<int>* permuted_start,
                                 std::vector<int>* permuted_row);
  // The double-double factor, sharing the double one's symbolic analysis.
  void InitializeDoubleDouble();
  // mu settled when the bound `head` it must cover met it or not; if not, it
  // becomes 2 head.
  bool SettleShift(double head, double* mu) const;

  const SESyncProblem& problem_;
  int d_ = 0, n_ = 0, translation_size_ = 0, rotation_size_ = 0;
  SparseMatrix K_;                         // Lower triangle, pattern fixed.
  std::vector<double> base_values_;        // K_0 without Lambda.
  std::vector<int> block_entry_;           // Value index of each (i, a >= b).
  std::vector<int> translation_diagonal_;  // Value index of each Lbar_jj.
  std::vector<int> ordering_;  // Fill-reducing: ordering_[k] = k-th pivot.
  std::vector<int> position_;  // Its inverse.
  // Where each value of K_ goes in the factorizations' permuted upper
  // triangle.
  std::vector<int> permuted_index_;
  int pattern_entries_ = 0;  // Entries of that pattern (K_'s and zeros).
  // Rounding of the stored data matrices, per row of K.
  std::vector<double> data_rounding_;
  // The double factorizations (same scheme as the double-double proofs,
  // extended_cholesky.h) and, built on the first SolveShifted() after one,
  // the solver of its factor.
  std::unique_ptr<DoubleDoubleCholesky> double_;
  bool double_factorized_ = false;
  mutable std::unique_ptr<SparseCholeskyFactor> solver_;
  // mu_j of the current double factor (empty: none).
  std::vector<double> factorized_shift_;
  // The shifts the next proofs start with: the translation block of a proof's
  // matrix is Lbar - diag(mu_j) in double, Lbar - mu I in double-double.
  std::vector<double> double_shift_;
  double extended_shift_ = 0;
  double proven_shift_ = 0;
  double backward_error_ = 0;
  int double_factorizations_ = 0, extended_factorizations_ = 0;
  double extended_time_s_ = 0;
  double last_double_seconds_ = 0, last_extended_seconds_ = 0;
  bool double_completed_ = false;
  std::chrono::steady_clock::time_point deadline_ =
      std::chrono::steady_clock::time_point::max();
  bool timed_out_ = false;
  // Double-double: the factorization.
  std::unique_ptr<DoubleDoubleCholesky> extended_;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CERTIFICATE_MATRIX_H_
