#include "ceres_sesync/stiefel_manifold.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "Eigen/Cholesky"
#include "Eigen/Eigenvalues"
#include "Eigen/LU"
#include "Eigen/QR"
#include "Eigen/SVD"

namespace ceres_sesync {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

// ---------------------------------------------------------------------------
// Blockwise kernels. D is the compile-time block width (2, 3) or
// Eigen::Dynamic; d is the runtime width (== D when D is fixed). Every
// workspace is created once per call, so there is no heap allocation per
// block (for fixed D there is at most one small allocation per call).
// ---------------------------------------------------------------------------

template <int D>
using Small = Eigen::Matrix<double, D, D>;
template <int D>
using SmallVector = Eigen::Matrix<double, D, 1>;
template <int D>
using Tall = Eigen::Matrix<double, Eigen::Dynamic, D>;
template <int D>
using ConstBlock = Eigen::Map<const Tall<D>>;
template <int D>
using MutableBlock = Eigen::Map<Tall<D>>;

// out (d x dn) block i = sym(A_i^T B_i), A and B p x dn.
template <int D>
void SymBlockDiagKernel(const double* a, const double* b, int p, int d, int n,
                        double* out) {
  Small<D> product(d, d);
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(p) * d;
  for (int i = 0; i < n; ++i) {
    ConstBlock<D> a_i(a + i * stride, p, d);
    ConstBlock<D> b_i(b + i * stride, p, d);
    product.noalias() = a_i.transpose().lazyProduct(b_i);
    Eigen::Map<Small<D>> out_i(out + static_cast<std::ptrdiff_t>(i) * d * d, d,
                               d);
    out_i = 0.5 * (product + product.transpose());
  }
}

// out_i = V_i - Y_i sym(Y_i^T V_i). out may alias v: each output coefficient
// (j, k) reads only V_i(j, k) of V_i.
template <int D>
void TangentProjectionKernel(const double* y, const double* v, int r, int d,
                             int n, double* out) {
  Small<D> product(d, d);
  Small<D> sym(d, d);
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = 0; i < n; ++i) {
    ConstBlock<D> y_i(y + i * stride, r, d);
    ConstBlock<D> v_i(v + i * stride, r, d);
    product.noalias() = y_i.transpose().lazyProduct(v_i);
    sym = 0.5 * (product + product.transpose());
    MutableBlock<D> out_i(out + i * stride, r, d);
    out_i = v_i - y_i.lazyProduct(sym);
  }
}

// Orthogonal polar factor of the r x d matrix x via a thin SVD; robust to rank
// deficiency (the result is then one of the nearest orthonormal matrices).
template <int D>
class SvdPolar {
 public:
  SvdPolar(int r, int d)
      : svd_(r, d, Eigen::ComputeThinU | Eigen::ComputeThinV) {}
  template <typename In, typename Out>
  void Compute(const In& x, Out* out) {
    svd_.compute(x);
    out->noalias() = svd_.matrixU() * svd_.matrixV().transpose();
  }

 private:
  Eigen::JacobiSVD<Tall<D>> svd_;
};

// out_i = polar factor of (Y_i + V_i) (V may be null, meaning zero). Both y
// and v may alias out: each block is first copied into a workspace.
template <int D>
void PolarRetractionKernel(const double* y, const double* v, int r, int d,
                           int n, double* out) {
  Tall<D> x(r, d);
  Small<D> gram(d, d);
  Small<D> inv_sqrt(d, d);
  SmallVector<D> scale(d);
  Eigen::SelfAdjointEigenSolver<Small<D>> eig(d);
  std::unique_ptr<SvdPolar<D>> svd;  // Only for rank-deficient blocks.
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = 0; i < n; ++i) {
    ConstBlock<D> y_i(y + i * stride, r, d);
    if (v != nullptr) {
      x = y_i + ConstBlock<D>(v + i * stride, r, d);
    } else {
      x = y_i;
    }
    MutableBlock<D> out_i(out + i * stride, r, d);
    gram.noalias() = x.transpose().lazyProduct(x);
    eig.compute(gram);
    const SmallVector<D>& lambda = eig.eigenvalues();  // Ascending.
    // The eigenvalue route loses accuracy like eps * cond(x)^2; use it only
    // when cond(x) < 100 (always true for a tangent V with ||V||_2 < 99,
    // since then gram = I + V^T V). Otherwise fall back to an SVD.
    const bool well_conditioned =
        eig.info() == Eigen::Success && std::isfinite(lambda(d - 1)) &&
        lambda(0) > 1e-4 * lambda(d - 1) && lambda(0) > 0.0;
    if (!well_conditioned) {
      if (!svd) svd = std::make_unique<SvdPolar<D>>(r, d);
      svd->Compute(x, &out_i);
      continue;
    }
    scale = lambda.cwiseSqrt().cwiseInverse();
    const Small<D>& u = eig.eigenvectors();
    inv_sqrt.noalias() = u * scale.asDiagonal() * u.transpose();
    out_i.noalias() = x.lazyProduct(inv_sqrt);
    // One Newton-Schulz step Q <- Q (3 I - Q^T Q) / 2 polishes the
    // orthonormality to rounding level; it converges to the same polar
    // factor, so it does not change the retraction.
    gram.noalias() = out_i.transpose().lazyProduct(out_i);
    gram.diagonal().array() -= 1.0;
    if (gram.cwiseAbs().maxCoeff() >
        2.0 * std::numeric_limits<double>::epsilon()) {
      inv_sqrt = -0.5 * gram;
      inv_sqrt.diagonal().array() += 1.0;
      x = out_i;
      out_i.noalias() = x.lazyProduct(inv_sqrt);
    }
  }
}

template <int D>
void SvdProjectionKernel(const double* x, int r, int d, int n, double* out) {
  SvdPolar<D> svd(r, d);
  Tall<D> copy(r, d);
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = 0; i < n; ++i) {
    copy = ConstBlock<D>(x + i * stride, r, d);
    MutableBlock<D> out_i(out + i * stride, r, d);
    svd.Compute(copy, &out_i);
  }
}

// Calls Kernel<2>, Kernel<3> or Kernel<Dynamic> according to d.
#define CERES_SESYNC_DISPATCH_ON_D(d, Kernel, ...) \
  do {                                             \
    if ((d) == 2) {                                \
      Kernel<2>(__VA_ARGS__);                      \
    } else if ((d) == 3) {                         \
      Kernel<3>(__VA_ARGS__);                      \
    } else {                                       \
      Kernel<Eigen::Dynamic>(__VA_ARGS__);         \
    }                                              \
  } while (false)

bool SameProductShape(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b,
                      int d) {
  return d >= 1 && a.rows() == b.rows() && a.cols() == b.cols() &&
         a.cols() % d == 0;
}

// A standard normal deviate pair from raw 64-bit engine output (Box-Muller),
// independent of the standard library's distribution implementations.
void GaussianPair(std::mt19937_64* rng, double* z0, double* z1) {
  constexpr double kTwoPow53Inv = 1.0 / 9007199254740992.0;
  const double u1 = static_cast<double>(((*rng)() >> 11) + 1) * kTwoPow53Inv;
  const double u2 = static_cast<double>((*rng)() >> 11) * kTwoPow53Inv;
  const double radius = std::sqrt(-2.0 * std::log(u1));
  constexpr double kTwoPi = 6.283185307179586476925;
  *z0 = radius * std::cos(kTwoPi * u2);
  *z1 = radius * std::sin(kTwoPi * u2);
}

// ---------------------------------------------------------------------------
// Single-block machinery shared by StiefelManifold and
// StiefelProductManifold. Not the solver's hot path, so it uses dynamic
// matrices; one Workspace is allocated per call and reused across blocks.
// ---------------------------------------------------------------------------

using ConstMatrixMap = Eigen::Map<const Eigen::MatrixXd>;
using MatrixMap = Eigen::Map<Eigen::MatrixXd>;
using RowMajorMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

class BlockOps {
 public:
  BlockOps(int d, int r)
      : d_(d),
        r_(r),
        num_skew_(d * (d - 1) / 2),
        tangent_size_(StiefelTangentDimension(d, r)),
        qr_(r, d),
        padded_(r, d),
        small_(d, d),
        tangent_(r, d),
        q_full_(r, r) {}

  int tangent_size() const { return tangent_size_; }
  int ambient_size() const { return r_ * d_; }

  // Sets the base point Y (r x d, column-major) and factors it; Y_perp is the
  // last r - d columns of the full Householder Q factor.
  bool SetPoint(const double* y) {
    y_ = y;
    ConstMatrixMap y_map(y, r_, d_);
    if (!y_map.allFinite()) return false;
    qr_.compute(y_map);
    return true;
  }

  // tangent = Y Omega(delta) + Y_perp K(delta).
  void CoordinatesToTangent(const double* delta, double* tangent) {
    ConstMatrixMap y(y_, r_, d_);
    MatrixMap v(tangent, r_, d_);
    SkewFromCoordinates(delta, &small_);
    if (r_ > d_) {
      padded_.topRows(d_).setZero();
      padded_.bottomRows(r_ - d_) =
          ConstMatrixMap(delta + num_skew_, r_ - d_, d_);
      v.noalias() = qr_.householderQ() * padded_;
    } else {
      v.setZero();
    }
    v.noalias() += y * small_;
  }

  // delta = B^T vec(G): coordinates of the tangent projection of G (r x d).
  void AmbientToCoordinates(const double* g, double* delta) {
    ConstMatrixMap y(y_, r_, d_);
    ConstMatrixMap g_map(g, r_, d_);
    small_.noalias() = y.transpose() * g_map;
    int k = 0;
    for (int a = 0; a < d_; ++a) {
      for (int b = a + 1; b < d_; ++b) {
        delta[k++] = kInvSqrt2 * (small_(a, b) - small_(b, a));
      }
    }
    if (r_ > d_) {
      padded_.noalias() = qr_.householderQ().transpose() * g_map;
      MatrixMap(delta + num_skew_, r_ - d_, d_) = padded_.bottomRows(r_ - d_);
    }
  }

  // Column-major ambient x tangent basis matrix B (written through `set`,
  // called as set(row, col, value) for every entry).
  template <typename Setter>
  void Basis(Setter set) {
    ConstMatrixMap y(y_, r_, d_);
    const int ambient = ambient_size();
    for (int row = 0; row < ambient; ++row) {
      for (int col = 0; col < tangent_size_; ++col) set(row, col, 0.0);
    }
    int k = 0;
    for (int a = 0; a < d_; ++a) {
      for (int b = a + 1; b < d_; ++b, ++k) {
        // Y E_k: column b gets  Y.col(a) / sqrt2, column a gets
        // -Y.col(b)/sqrt2.
        for (int j = 0; j < r_; ++j) {
          set(j + b * r_, k, kInvSqrt2 * y(j, a));
          set(j + a * r_, k, -kInvSqrt2 * y(j, b));
        }
      }
    }
    if (r_ > d_) {
      q_full_.setIdentity();
      q_full_.applyOnTheLeft(qr_.householderQ());
      for (int q = 0; q < d_; ++q) {
        for (int p = 0; p < r_ - d_; ++p, ++k) {
          // Y_perp e_p e_q^T: column q is Y_perp.col(p).
          for (int j = 0; j < r_; ++j) set(j + q * r_, k, q_full_(j, d_ + p));
        }
      }
    }
  }

  // Finds the tangent V at Y with polar-retraction R_Y(V) = y and writes its
  // coordinates. Returns false if there is none.
  bool InverseRetraction(const double* y_target, double* delta) {
    ConstMatrixMap y(y_, r_, d_);
    ConstMatrixMap target(y_target, r_, d_);
    if (!target.allFinite()) return false;
    // A S + S A^T = 2 I with A = Y^T y, vectorized:
    // (I kron A + A kron I) vec(S) = 2 vec(I).
    const Eigen::MatrixXd a = y.transpose() * target;
    const int dd = d_ * d_;
    Eigen::MatrixXd system = Eigen::MatrixXd::Zero(dd, dd);
    for (int p = 0; p < d_; ++p) {
      for (int q = 0; q < d_; ++q) {
        // Unknown S(p, q) is vec index p + q d. Equation (i, j) is row i + j d.
        for (int i = 0; i < d_; ++i) {
          // (A S)(i, q) += A(i, p) S(p, q).
          system(i + q * d_, p + q * d_) += a(i, p);
          // (S A^T)(p, j) += S(p, q) A(j, q).
          system(p + i * d_, p + q * d_) += a(i, q);
        }
      }
    }
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(dd);
    for (int i = 0; i < d_; ++i) rhs(i + i * d_) = 2.0;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(system);
    if (!lu.isInvertible()) return false;
    const Eigen::VectorXd s_vec = lu.solve(rhs);
    small_ = Eigen::Map<const Eigen::MatrixXd>(s_vec.data(), d_, d_);
    small_ = (0.5 * (small_ + small_.transpose())).eval();
    if (!small_.allFinite()) return false;
    Eigen::LLT<Eigen::MatrixXd> llt(small_);
    if (llt.info() != Eigen::Success) return false;  // Not in R_Y's image.
    tangent_.noalias() = target * small_;
    tangent_ -= y;
    AmbientToCoordinates(tangent_.data(), delta);
    return true;
  }

 private:
  void SkewFromCoordinates(const double* delta, Eigen::MatrixXd* omega) const {
    omega->setZero();
    int k = 0;
    for (int a = 0; a < d_; ++a) {
      for (int b = a + 1; b < d_; ++b) {
        (*omega)(a, b) = kInvSqrt2 * delta[k];
        (*omega)(b, a) = -kInvSqrt2 * delta[k];
        ++k;
      }
    }
  }

  const int d_;
  const int r_;
  const int num_skew_;
  const int tangent_size_;
  const double* y_ = nullptr;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
  Eigen::MatrixXd padded_;
  Eigen::MatrixXd small_;
  Eigen::MatrixXd tangent_;
  Eigen::MatrixXd q_full_;
};

bool AllFinite(const double* p, int size) {
  return ConstMatrixMap(p, size, 1).allFinite();
}

}  // namespace

// ---------------------------------------------------------------------------
// Free functions.
// ---------------------------------------------------------------------------

int StiefelTangentDimension(int d, int r) {
  if (d < 1 || r < d) return -1;
  return r * d - d * (d + 1) / 2;
}

bool IsStiefelProductShape(const Eigen::MatrixXd& Y, int d,
                           std::string* error) {
  std::string message;
  if (d < 1) {
    message = "block size d = " + std::to_string(d) + " must be >= 1";
  } else if (Y.rows() < d) {
    message = "matrix has " + std::to_string(Y.rows()) +
              " rows; St(d, r) needs r >= d = " + std::to_string(d);
  } else if (Y.cols() == 0 || Y.cols() % d != 0) {
    message =
        "matrix has " + std::to_string(Y.cols()) +
        " columns; expected a positive multiple of d = " + std::to_string(d);
  }
  if (message.empty()) return true;
  if (error != nullptr) *error = message;
  return false;
}

double StiefelProductOrthonormalityError(const Eigen::MatrixXd& Y, int d) {
  if (!IsStiefelProductShape(Y, d, nullptr)) {
    return std::numeric_limits<double>::infinity();
  }
  double worst = 0.0;
  for (Eigen::Index i = 0; i < Y.cols() / d; ++i) {
    const auto block = Y.middleCols(d * i, d);
    Eigen::MatrixXd e = block.transpose() * block;
    e.diagonal().array() -= 1.0;
    const double err = e.cwiseAbs().maxCoeff();
    if (!(err <= worst)) worst = err;  // Propagates NaN as a large error.
    if (std::isnan(worst)) return std::numeric_limits<double>::infinity();
  }
  return worst;
}

Eigen::MatrixXd SymBlockDiagProduct(const Eigen::MatrixXd& A,
                                    const Eigen::MatrixXd& B, int d) {
  if (!SameProductShape(A, B, d)) return Eigen::MatrixXd();
  const int n = static_cast<int>(A.cols() / d);
  Eigen::MatrixXd out(d, A.cols());
  CERES_SESYNC_DISPATCH_ON_D(d, SymBlockDiagKernel, A.data(), B.data(),
                             static_cast<int>(A.rows()), d, n, out.data());
  return out;
}

void ProjectToStiefelProductTangent(const Eigen::MatrixXd& Y,
                                    const Eigen::MatrixXd& V, int d,
                                    Eigen::MatrixXd* out) {
  if (out == nullptr) return;
  if (!SameProductShape(Y, V, d) || Y.rows() < d || out == &Y) {
    out->resize(0, 0);
    return;
  }
  const int n = static_cast<int>(Y.cols() / d);
  out->resize(Y.rows(), Y.cols());  // No-op (keeps data) when out == &V.
  CERES_SESYNC_DISPATCH_ON_D(d, TangentProjectionKernel, Y.data(), V.data(),
                             static_cast<int>(Y.rows()), d, n, out->data());
}

void RetractStiefelProduct(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& V,
                           int d, Eigen::MatrixXd* out) {
  if (out == nullptr) return;
  if (!SameProductShape(Y, V, d) || Y.rows() < d) {
    out->resize(0, 0);
    return;
  }
  const int n = static_cast<int>(Y.cols() / d);
  out->resize(Y.rows(), Y.cols());  // No-op when out aliases Y or V.
  CERES_SESYNC_DISPATCH_ON_D(d, PolarRetractionKernel, Y.data(), V.data(),
                             static_cast<int>(Y.rows()), d, n, out->data());
}

void ProjectToStiefelProduct(const Eigen::MatrixXd& X, int d,
                             Eigen::MatrixXd* out) {
  if (out == nullptr) return;
  if (d < 1 || X.rows() < d || X.cols() % d != 0) {
    out->resize(0, 0);
    return;
  }
  const int n = static_cast<int>(X.cols() / d);
  out->resize(X.rows(), X.cols());
  CERES_SESYNC_DISPATCH_ON_D(d, SvdProjectionKernel, X.data(),
                             static_cast<int>(X.rows()), d, n, out->data());
}

Eigen::MatrixXd RandomStiefelProductPoint(int d, int r, int n,
                                          std::mt19937_64* rng) {
  if (d < 1 || r < d || n < 0 || rng == nullptr) return Eigen::MatrixXd();
  Eigen::MatrixXd y(r, static_cast<Eigen::Index>(d) * n);
  Eigen::MatrixXd gaussian(r, d);
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(r, d);
  Eigen::MatrixXd q(r, d);
  for (int i = 0; i < n; ++i) {
    double* g = gaussian.data();
    const int size = r * d;
    for (int k = 0; k < size; k += 2) {
      double z0, z1;
      GaussianPair(rng, &z0, &z1);
      g[k] = z0;
      if (k + 1 < size) g[k + 1] = z1;
    }
    qr.compute(gaussian);
    q.setIdentity();
    q.applyOnTheLeft(qr.householderQ());
    for (int j = 0; j < d; ++j) {
      if (qr.matrixQR()(j, j) < 0.0) q.col(j) = -q.col(j);
    }
    y.middleCols(static_cast<Eigen::Index>(d) * i, d) = q;
  }
  return y;
}

// ---------------------------------------------------------------------------
// StiefelManifold.
// ---------------------------------------------------------------------------

StiefelManifold::StiefelManifold(int d, int r)
    : d_(d), r_(r), valid_(d >= 1 && r >= d) {
  if (!valid_) d_ = r_ = 0;
}

int StiefelManifold::AmbientSize() const { return valid_ ? r_ * d_ : 0; }

int StiefelManifold::TangentSize() const {
  return valid_ ? StiefelTangentDimension(d_, r_) : 0;
}

bool StiefelManifold::CoordinatesToTangent(const double* x, const double* delta,
                                           double* tangent) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x) || !AllFinite(delta, TangentSize())) return false;
  ops.CoordinatesToTangent(delta, tangent);
  return true;
}

bool StiefelManifold::TangentToCoordinates(const double* x,
                                           const double* ambient,
                                           double* delta) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x)) return false;
  ops.AmbientToCoordinates(ambient, delta);
  return true;
}

bool StiefelManifold::Plus(const double* x, const double* delta,
                           double* x_plus_delta) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x) || !AllFinite(delta, TangentSize())) return false;
  std::vector<double> v(static_cast<size_t>(AmbientSize()));
  ops.CoordinatesToTangent(delta, v.data());
  CERES_SESYNC_DISPATCH_ON_D(d_, PolarRetractionKernel, x, v.data(), r_, d_, 1,
                             x_plus_delta);
  return AllFinite(x_plus_delta, AmbientSize());
}

bool StiefelManifold::PlusJacobian(const double* x, double* jacobian) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x)) return false;
  const int tangent = TangentSize();
  ops.Basis([&](int row, int col, double value) {
    jacobian[row * tangent + col] = value;
  });
  return true;
}

bool StiefelManifold::RightMultiplyByPlusJacobian(
    const double* x, const int num_rows, const double* ambient_matrix,
    double* tangent_matrix) const {
  if (!valid_ || num_rows < 0) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x)) return false;
  for (int row = 0; row < num_rows; ++row) {
    ops.AmbientToCoordinates(
        ambient_matrix + static_cast<std::ptrdiff_t>(row) * AmbientSize(),
        tangent_matrix + static_cast<std::ptrdiff_t>(row) * TangentSize());
  }
  return true;
}

bool StiefelManifold::Minus(const double* y, const double* x,
                            double* y_minus_x) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x)) return false;
  return ops.InverseRetraction(y, y_minus_x);
}

bool StiefelManifold::MinusJacobian(const double* x, double* jacobian) const {
  if (!valid_) return false;
  BlockOps ops(d_, r_);
  if (!ops.SetPoint(x)) return false;
  const int ambient = AmbientSize();
  ops.Basis([&](int row, int col, double value) {
    jacobian[col * ambient + row] = value;
  });
  return true;
}

// ---------------------------------------------------------------------------
// StiefelProductManifold.
// ---------------------------------------------------------------------------

StiefelProductManifold::StiefelProductManifold(int d, int r, int n)
    : block_(d, r), n_(block_.IsValid() && n >= 1 ? n : 0) {}

int StiefelProductManifold::AmbientSize() const {
  return IsValid() ? n_ * block_.AmbientSize() : 0;
}

int StiefelProductManifold::TangentSize() const {
  return IsValid() ? n_ * block_.TangentSize() : 0;
}

bool StiefelProductManifold::Plus(const double* x, const double* delta,
                                  double* x_plus_delta) const {
  if (!IsValid()) return false;
  const int ambient = block_.AmbientSize();
  const int tangent = block_.TangentSize();
  if (!AllFinite(delta, TangentSize())) return false;
  BlockOps ops(d(), r());
  std::vector<double> v(static_cast<size_t>(AmbientSize()));
  for (int i = 0; i < n_; ++i) {
    if (!ops.SetPoint(x + static_cast<std::ptrdiff_t>(i) * ambient)) {
      return false;
    }
    ops.CoordinatesToTangent(
        delta + static_cast<std::ptrdiff_t>(i) * tangent,
        v.data() + static_cast<std::ptrdiff_t>(i) * ambient);
  }
  CERES_SESYNC_DISPATCH_ON_D(d(), PolarRetractionKernel, x, v.data(), r(), d(),
                             n_, x_plus_delta);
  return AllFinite(x_plus_delta, AmbientSize());
}

bool StiefelProductManifold::PlusJacobian(const double* x,
                                          double* jacobian) const {
  if (!IsValid()) return false;
  const int ambient = block_.AmbientSize();
  const int tangent = block_.TangentSize();
  const std::ptrdiff_t total_tangent = TangentSize();
  std::fill_n(jacobian,
              static_cast<std::ptrdiff_t>(AmbientSize()) * total_tangent, 0.0);
  BlockOps ops(d(), r());
  for (int i = 0; i < n_; ++i) {
    if (!ops.SetPoint(x + static_cast<std::ptrdiff_t>(i) * ambient)) {
      return false;
    }
    const std::ptrdiff_t row0 = static_cast<std::ptrdiff_t>(i) * ambient;
    const std::ptrdiff_t col0 = static_cast<std::ptrdiff_t>(i) * tangent;
    ops.Basis([&](int row, int col, double value) {
      jacobian[(row0 + row) * total_tangent + col0 + col] = value;
    });
  }
  return true;
}

bool StiefelProductManifold::RightMultiplyByPlusJacobian(
    const double* x, const int num_rows, const double* ambient_matrix,
    double* tangent_matrix) const {
  if (!IsValid() || num_rows < 0) return false;
  const int ambient = block_.AmbientSize();
  const int tangent = block_.TangentSize();
  const std::ptrdiff_t total_ambient = AmbientSize();
  const std::ptrdiff_t total_tangent = TangentSize();
  BlockOps ops(d(), r());
  for (int i = 0; i < n_; ++i) {
    if (!ops.SetPoint(x + static_cast<std::ptrdiff_t>(i) * ambient)) {
      return false;
    }
    for (int row = 0; row < num_rows; ++row) {
      ops.AmbientToCoordinates(ambient_matrix + row * total_ambient +
                                   static_cast<std::ptrdiff_t>(i) * ambient,
                               tangent_matrix + row * total_tangent +
                                   static_cast<std::ptrdiff_t>(i) * tangent);
    }
  }
  return true;
}

bool StiefelProductManifold::Minus(const double* y, const double* x,
                                   double* y_minus_x) const {
  if (!IsValid()) return false;
  const int ambient = block_.AmbientSize();
  const int tangent = block_.TangentSize();
  BlockOps ops(d(), r());
  for (int i = 0; i < n_; ++i) {
    const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(i) * ambient;
    if (!ops.SetPoint(x + offset) ||
        !ops.InverseRetraction(
            y + offset, y_minus_x + static_cast<std::ptrdiff_t>(i) * tangent)) {
      return false;
    }
  }
  return true;
}

bool StiefelProductManifold::MinusJacobian(const double* x,
                                           double* jacobian) const {
  if (!IsValid()) return false;
  const int ambient = block_.AmbientSize();
  const int tangent = block_.TangentSize();
  const std::ptrdiff_t total_ambient = AmbientSize();
  std::fill_n(jacobian,
              static_cast<std::ptrdiff_t>(TangentSize()) * total_ambient, 0.0);
  BlockOps ops(d(), r());
  for (int i = 0; i < n_; ++i) {
    if (!ops.SetPoint(x + static_cast<std::ptrdiff_t>(i) * ambient)) {
      return false;
    }
    const std::ptrdiff_t row0 = static_cast<std::ptrdiff_t>(i) * ambient;
    const std::ptrdiff_t col0 = static_cast<std::ptrdiff_t>(i) * tangent;
    ops.Basis([&](int row, int col, double value) {
      jacobian[(col0 + col) * total_ambient + row0 + row] = value;
    });
  }
  return true;
}

}  // namespace ceres_sesync
