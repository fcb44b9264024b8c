#include "ceres_sesync/internal/sesync_problem.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "glog/logging.h"

namespace ceres_sesync::internal {

using Triplet = Eigen::Triplet<double>;

double CholmodFactor::BackwardErrorBound() {
  cholmod_common* common = &cholmod();
  cholmod_factor* L = cholmod_copy_factor(m_cholmodFactor, common);
  CHECK(L != nullptr) << "out of memory copying the Cholesky factor";
  // Simplicial, LL^T, packed: plain compressed columns.
  cholmod_change_factor(CHOLMOD_REAL, /*to_ll=*/1, /*to_super=*/0,
                        /*to_packed=*/1, /*to_monotonic=*/1, L, common);
  const int n = static_cast<int>(L->n);
  const int* p = static_cast<const int*>(L->p);
  const int* row = static_cast<const int*>(L->i);
  const double* x = static_cast<const double*>(L->x);
  std::vector<double> column_sum(n, 0.0), v(n, 0.0);
  std::vector<int> row_count(n, 0);
  for (int j = 0; j < n; ++j) {
    for (int k = p[j]; k < p[j + 1]; ++k) {
      column_sum[j] += std::abs(x[k]);
      ++row_count[row[k]];
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int k = p[j]; k < p[j + 1]; ++k) {
      v[row[k]] += std::abs(x[k]) * column_sum[j];
    }
  }
  cholmod_free_factor(&L, common);
  // Entry (i, j) of L L^T sums at most min(k_i, k_j) products (k_i = nonzeros
  // in row i), so row i of the error is bounded by gamma_{k_i + 1} v_i.
  const double unit_roundoff = std::numeric_limits<double>::epsilon() / 2;
  double bound = 0;
  for (int i = 0; i < n; ++i) {
    const double m = 4.0 * (row_count[i] + 1);
    bound = std::max(bound, m * unit_roundoff / (1 - m * unit_roundoff) * v[i]);
  }
  return bound;
}

void ConfigureCholmod(bool supernodal, CholmodFactor* factor) {
  factor->setMode(supernodal ? Eigen::CholmodSupernodalLLt
                             : Eigen::CholmodSimplicialLLt);
  factor->cholmod().print = 0;
}

SESyncProblem::SESyncProblem(const PoseGraph& graph)
    : d_(graph.dimension), n_(graph.num_poses) {
  const int d = d_, n = n_;
  std::vector<Triplet> lrho, sigma, v, lw;
  const size_t m = graph.measurements.size();
  lrho.reserve(m * (2 * d + 2 * d * d));
  sigma.reserve(m * d * d);
  v.reserve(2 * m * d);
  lw.reserve(4 * m);
  for (const RelativePoseMeasurement& e : graph.measurements) {
    const int i = e.i, j = e.j;
    for (int a = 0; a < d; ++a) {
      lrho.emplace_back(d * i + a, d * i + a, e.kappa);
      lrho.emplace_back(d * j + a, d * j + a, e.kappa);
      for (int b = 0; b < d; ++b) {
        lrho.emplace_back(d * i + a, d * j + b, -e.kappa * e.R(a, b));
        lrho.emplace_back(d * j + b, d * i + a, -e.kappa * e.R(a, b));
        sigma.emplace_back(d * i + a, d * i + b, e.tau * e.t(a) * e.t(b));
      }
      // V = A Omega B^T: +tau t~^T at (j, block i), -tau t~^T at (i, block i).
      v.emplace_back(j, d * i + a, e.tau * e.t(a));
      v.emplace_back(i, d * i + a, -e.tau * e.t(a));
    }
    lw.emplace_back(i, i, e.tau);
    lw.emplace_back(j, j, e.tau);
    lw.emplace_back(std::max(i, j), std::min(i, j), -e.tau);
  }
  Lrho_.resize(d * n, d * n);
  Lrho_.setFromTriplets(lrho.begin(), lrho.end());
  SparseMatrix sigma_matrix(d * n, d * n);
  sigma_matrix.setFromTriplets(sigma.begin(), sigma.end());
  D_ = Lrho_ + sigma_matrix;

  // Drop vertex 0 (the gauge t_0 = 0) from the translational blocks.
  std::vector<Triplet> vbar, lbar;
  for (const Triplet& t : v) {
    if (t.row() > 0) vbar.emplace_back(t.row() - 1, t.col(), t.value());
  }
  for (const Triplet& t : lw) {
    if (t.row() > 0 && t.col() > 0) {
      lbar.emplace_back(t.row() - 1, t.col() - 1, t.value());
    }
  }
  Vbar_.resize(n - 1, d * n);
  Vbar_.setFromTriplets(vbar.begin(), vbar.end());
  VbarT_ = Vbar_.transpose();
  Lbar_.resize(n - 1, n - 1);
  Lbar_.setFromTriplets(lbar.begin(), lbar.end());
  if (n == 1) {
    ok_ = true;
    return;
  }
  lbar_factor_ = std::make_unique<CholmodFactor>();
  ConfigureCholmod(/*supernodal=*/false, lbar_factor_.get());
  lbar_factor_->compute(Lbar_);
  ok_ = lbar_factor_->info() == Eigen::Success;
  LOG_IF(ERROR, !ok_) << "Cholesky factorization of the reduced translational "
                         "Laplacian failed";
}

void SESyncProblem::MultiplyQ(const Eigen::MatrixXd& Y,
                              Eigen::MatrixXd* YQ) const {
  *YQ = Y * D_;
  if (n_ == 1) return;
  const Eigen::MatrixXd P = (Y * VbarT_).transpose();  // (n-1) x r
  const Eigen::MatrixXd Z = lbar_factor_->solve(P);    // Lbar^{-1} Vbar Y^T
  YQ->noalias() -= Z.transpose() * Vbar_;
}

Eigen::MatrixXd SESyncProblem::RecoverTranslations(
    const Eigen::MatrixXd& R) const {
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(d_, n_);
  if (n_ == 1) return T;
  const Eigen::MatrixXd rhs = Vbar_ * R.transpose();  // (n-1) x d
  T.rightCols(n_ - 1) = lbar_factor_->solve(rhs).transpose();
  return T;
}

void BlockDiagonalMultiply(const Eigen::MatrixXd& V,
                           const Eigen::MatrixXd& Lambda, int d,
                           Eigen::MatrixXd* out) {
  const int n = static_cast<int>(V.cols() / d);
  out->resize(V.rows(), V.cols());
  for (int i = 0; i < n; ++i) {
    out->middleCols(d * i, d).noalias() =
        V.middleCols(d * i, d) * Lambda.middleCols(d * i, d);
  }
}

}  // namespace ceres_sesync::internal
