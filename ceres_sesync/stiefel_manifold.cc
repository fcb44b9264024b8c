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
#include "ceres_sesync/internal/parallel.h"

namespace ceres_sesync {
namespace {

constexpr double kInvSqrt2 = 0.70710678118654752440;

// ---------------------------------------------------------------------------
// Blockwise kernels. D is the compile-time block width (2, 3) or
// Eigen::Dynamic; d is the runtime width (== D when D is fixed). Every
// workspace is created once per call, so for fixed D there is no heap
// allocation per block (measured: at most one per call). The Dynamic
// fallback's eigensolver allocates two small buffers per block.
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

// out_i = V_i - Y_i sym(Y_i^T V_i). out may alias v: each block is read
// completely before it is written. R is the compile-time number of rows (r)
// or Eigen::Dynamic.
template <int D, int R = Eigen::Dynamic>
void TangentProjectionKernel(const double* y, const double* v, int r, int d,
                             int n, double* out) {
  using Block = Eigen::Matrix<double, R, D>;
  Small<D> product(d, d);
  Small<D> sym(d, d);
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = 0; i < n; ++i) {
    Eigen::Map<const Block> y_i(y + i * stride, r, d);
    Eigen::Map<const Block> v_i(v + i * stride, r, d);
    product.noalias() = y_i.transpose().lazyProduct(v_i);
    sym = 0.5 * (product + product.transpose());
    Eigen::Map<Block> out_i(out + i * stride, r, d);
    out_i = v_i - y_i.lazyProduct(sym);
  }
}

// TangentProjectionKernel<D> with the common staircase ranks r = d .. d + 3
// unrolled at compile time (the inner solver's most frequent call; r = d is
// the first level's nonzero rows).
template <int D>
void TangentProjectionDispatch(const double* y, const double* v, int r, int d,
                               int n, double* out) {
  if constexpr (D != Eigen::Dynamic) {
    if (r == D) return TangentProjectionKernel<D, D>(y, v, r, d, n, out);
    if (r == D + 1)
      return TangentProjectionKernel<D, D + 1>(y, v, r, d, n, out);
    if (r == D + 2)
      return TangentProjectionKernel<D, D + 2>(y, v, r, d, n, out);
    if (r == D + 3)
      return TangentProjectionKernel<D, D + 3>(y, v, r, d, n, out);
  }
  TangentProjectionKernel<D>(y, v, r, d, n, out);
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

// Inverse square root M ~ G^(-1/2) of a symmetric positive-definite d x d
// matrix G, as a polynomial in G (so M commutes with G exactly, up to
// rounding). Returns false unless G is comfortably well conditioned
// (lambda_min > kMinEigenvalueRatio * lambda_max), in which case the caller
// falls back to an SVD.
//
// Why a polynomial in G suffices: for x with x^T x = G and any symmetric
// positive-definite M commuting with G, polar(x M) = polar(x). So small
// errors in M only make x M slightly non-orthonormal, and the Newton-Schulz
// polishing in PolarKernel (which converges to polar(x M)) removes
// them without changing the retraction.
constexpr double kMinEigenvalueRatio = 1e-4;  // cond(x) < 100.

// Newton-Schulz polishing stops once max |Q^T Q - I| is below this: a few
// ulps above the rounding floor of evaluating Q^T Q itself, and well below
// the 1e-14 orthonormality the solver relies on.
constexpr double kPolishThreshold = 4e-15;

template <int D>
class InverseSqrt {
 public:
  explicit InverseSqrt(int d) : eig_(d), scale_(d) {}
  // Dynamic fallback: symmetric eigendecomposition.
  bool Compute(const Small<D>& g, Small<D>* m) {
    eig_.compute(g);
    if (eig_.info() != Eigen::Success) return false;
    const auto& lambda = eig_.eigenvalues();  // Ascending.
    const int d = static_cast<int>(g.rows());
    if (!std::isfinite(lambda(d - 1)) ||
        !(lambda(0) > kMinEigenvalueRatio * lambda(d - 1))) {
      return false;
    }
    scale_ = lambda.cwiseSqrt().cwiseInverse();
    m->noalias() = eig_.eigenvectors() * scale_.asDiagonal() *
                   eig_.eigenvectors().transpose();
    return true;
  }

 private:
  Eigen::SelfAdjointEigenSolver<Small<D>> eig_;
  SmallVector<D> scale_;
};

// d = 2: sqrt(G) = (G + s I) / t with s = sqrt(det G), t = sqrt(tr G + 2 s),
// hence G^(-1/2) = t (G + s I)^(-1) = ((tr G + s) I - G) / (s t).
template <>
class InverseSqrt<2> {
 public:
  explicit InverseSqrt(int /*d*/) {}
  bool Compute(const Eigen::Matrix2d& g, Eigen::Matrix2d* m) {
    const double a = g(0, 0), b = g(0, 1), c = g(1, 1);
    const double trace = a + c;
    const double half_gap = std::hypot(0.5 * (a - c), b);
    const double lambda_max = 0.5 * trace + half_gap;
    const double det = a * c - b * b;
    if (!std::isfinite(lambda_max) ||
        !(det > kMinEigenvalueRatio * lambda_max * lambda_max)) {
      return false;
    }
    const double s = std::sqrt(det);
    const double st = s * std::sqrt(trace + 2.0 * s);
    (*m)(0, 0) = (trace + s - a) / st;
    (*m)(1, 1) = (trace + s - c) / st;
    (*m)(0, 1) = (*m)(1, 0) = -b / st;
    return true;
  }
};

// d = 3: eigenvalues in closed form (trigonometric solution of the shifted,
// scaled characteristic polynomial), then the square root U = sqrt(G) from the
// invariants of its eigenvalues mu_i = sqrt(lambda_i) (Cayley-Hamilton; e.g.
// Franca, Comput. Math. Appl. 1989):
//   U = (-G^2 + (I1^2 - I2) G + I1 I3 Id) / (I1 I2 - I3),
//   U^(-1) = (G - I1 U + I2 Id) / I3,
// with I1 = sum mu_i, I2 = sum_{i<j} mu_i mu_j, I3 = prod mu_i.
template <>
class InverseSqrt<3> {
 public:
  explicit InverseSqrt(int /*d*/) {}
  bool Compute(const Eigen::Matrix3d& g, Eigen::Matrix3d* m) {
    const double q = g.trace() / 3.0;
    const double b00 = g(0, 0) - q, b11 = g(1, 1) - q, b22 = g(2, 2) - q;
    const double b01 = g(0, 1), b02 = g(0, 2), b12 = g(1, 2);
    const double p2 = (b00 * b00 + b11 * b11 + b22 * b22 +
                       2.0 * (b01 * b01 + b02 * b02 + b12 * b12)) /
                      6.0;
    double lambda1 = q, lambda2 = q, lambda3 = q;  // Descending.
    if (p2 > 0.0) {
      const double p = std::sqrt(p2);
      const double inv_p = 1.0 / p;
      const double c00 = b00 * inv_p, c11 = b11 * inv_p, c22 = b22 * inv_p;
      const double c01 = b01 * inv_p, c02 = b02 * inv_p, c12 = b12 * inv_p;
      const double det_c = c00 * (c11 * c22 - c12 * c12) -
                           c01 * (c01 * c22 - c12 * c02) +
                           c02 * (c01 * c12 - c11 * c02);
      const double half_det = std::clamp(0.5 * det_c, -1.0, 1.0);
      const double phi = std::acos(half_det) / 3.0;
      constexpr double kTwoPiOverThree = 2.0943951023931954923;
      lambda1 = q + 2.0 * p * std::cos(phi);
      lambda3 = q + 2.0 * p * std::cos(phi + kTwoPiOverThree);
      lambda2 = 3.0 * q - lambda1 - lambda3;
    }
    if (!std::isfinite(lambda1) || !(lambda3 > kMinEigenvalueRatio * lambda1) ||
        !(lambda2 > 0.0)) {
      return false;
    }
    const double mu1 = std::sqrt(lambda1), mu2 = std::sqrt(lambda2),
                 mu3 = std::sqrt(lambda3);
    const double i1 = mu1 + mu2 + mu3;
    const double i2 = mu1 * mu2 + mu2 * mu3 + mu3 * mu1;
    const double i3 = mu1 * mu2 * mu3;
    const Eigen::Matrix3d g2 = g * g;
    Eigen::Matrix3d u = (i1 * i1 - i2) * g - g2;
    u.diagonal().array() += i1 * i3;
    u /= (i1 * i2 - i3);
    *m = g - i1 * u;
    m->diagonal().array() += i2;
    *m /= i3;
    return true;
  }
};

// out_i = polar factor of (Y_i + V_i) (v may be null, meaning zero): the
// polar retraction, or (with v null) the projection onto St(d, r)^n. Both y
// and v may alias out.
//
// Fixed d (2, 3): hand-written row loops (each output row depends only on the
// same row of the input, which is what makes aliasing safe), then Newton-
// Schulz polishing Q <- Q (3 I - Q^T Q) / 2, which converges quadratically to
// polar(Q) = polar(x) and leaves Q orthonormal to rounding level (typically
// one step). For a tangent V, x^T x = I + V^T V, so the fast path is taken
// whenever ||V||_2 < 99; an SVD handles everything else (ill conditioning,
// rank deficiency, non-finite input).
template <int D>
void PolarKernel(const double* y, const double* v, int r, int d, int n,
                 double* out) {
  static_assert(D != Eigen::Dynamic, "see the specialization below");
  (void)d;
  InverseSqrt<D> inverse_sqrt(D);
  Small<D> gram;
  Small<D> m;
  std::unique_ptr<SvdPolar<D>> svd;  // Only for ill-conditioned blocks.
  // Workspace for x = Y_i + V_i (one allocation per call).
  Tall<D> x(r, D);
  double* xp = x.data();
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * D;
  // Gram matrix of the r x D column-major block a.
  auto gram_of = [r](const double* a, Small<D>* g) {
    double acc[D][D] = {};
    for (int j = 0; j < r; ++j) {
      for (int k = 0; k < D; ++k) {
        for (int l = k; l < D; ++l) acc[k][l] += a[j + k * r] * a[j + l * r];
      }
    }
    for (int k = 0; k < D; ++k) {
      for (int l = k; l < D; ++l) (*g)(k, l) = (*g)(l, k) = acc[k][l];
    }
  };
  // o = a * c, row by row (o may alias a).
  auto multiply = [r](const double* a, const Small<D>& c, double* o) {
    for (int j = 0; j < r; ++j) {
      double row[D];
      for (int k = 0; k < D; ++k) row[k] = a[j + k * r];
      for (int k = 0; k < D; ++k) {
        double sum = 0.0;
        for (int l = 0; l < D; ++l) sum += row[l] * c(l, k);
        o[j + k * r] = sum;
      }
    }
  };
  for (int i = 0; i < n; ++i) {
    const double* y_i = y + i * stride;
    if (v != nullptr) {
      const double* v_i = v + i * stride;
      for (std::ptrdiff_t k = 0; k < stride; ++k) xp[k] = y_i[k] + v_i[k];
    } else {
      std::copy(y_i, y_i + stride, xp);
    }
    double* out_i = out + i * stride;
    gram_of(xp, &gram);
    if (!inverse_sqrt.Compute(gram, &m)) {
      if (!svd) svd = std::make_unique<SvdPolar<D>>(r, D);
      MutableBlock<D> out_map(out_i, r, D);
      svd->Compute(x, &out_map);
      continue;
    }
    multiply(xp, m, out_i);
    for (int step = 0; step < 3; ++step) {
      gram_of(out_i, &gram);
      gram.diagonal().array() -= 1.0;
      if (!(gram.cwiseAbs().maxCoeff() > kPolishThreshold)) break;
      m = -0.5 * gram;
      m.diagonal().array() += 1.0;
      multiply(out_i, m, out_i);
    }
  }
}

// Dynamic d: the same algorithm with Eigen expressions and a symmetric
// eigendecomposition for the inverse square root.
template <>
void PolarKernel<Eigen::Dynamic>(const double* y, const double* v, int r, int d,
                                 int n, double* out) {
  using MatrixX = Eigen::MatrixXd;
  MatrixX x(r, d);
  MatrixX gram(d, d);
  MatrixX m(d, d);
  InverseSqrt<Eigen::Dynamic> inverse_sqrt(d);
  std::unique_ptr<SvdPolar<Eigen::Dynamic>> svd;
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  for (int i = 0; i < n; ++i) {
    ConstBlock<Eigen::Dynamic> y_i(y + i * stride, r, d);
    if (v != nullptr) {
      x = y_i + ConstBlock<Eigen::Dynamic>(v + i * stride, r, d);
    } else {
      x = y_i;
    }
    MutableBlock<Eigen::Dynamic> out_i(out + i * stride, r, d);
    gram.noalias() = x.transpose().lazyProduct(x);
    if (!inverse_sqrt.Compute(gram, &m)) {
      if (!svd) svd = std::make_unique<SvdPolar<Eigen::Dynamic>>(r, d);
      svd->Compute(x, &out_i);
      continue;
    }
    out_i.noalias() = x.lazyProduct(m);
    for (int step = 0; step < 3; ++step) {
      gram.noalias() = out_i.transpose().lazyProduct(out_i);
      gram.diagonal().array() -= 1.0;
      if (!(gram.cwiseAbs().maxCoeff() > kPolishThreshold)) break;
      m = -0.5 * gram;
      m.diagonal().array() += 1.0;
      x = out_i;
      out_i.noalias() = x.lazyProduct(m);
    }
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
                                    Eigen::MatrixXd* out, int num_threads) {
  if (out == nullptr) return;
  if (!SameProductShape(Y, V, d) || Y.rows() < d || out == &Y) {
    out->resize(0, 0);
    return;
  }
  const int n = static_cast<int>(Y.cols() / d);
  const int r = static_cast<int>(Y.rows());
  out->resize(Y.rows(), Y.cols());  // No-op (keeps data) when out == &V.
  const std::ptrdiff_t stride = static_cast<std::ptrdiff_t>(r) * d;
  internal::ParallelParts(
      internal::ThreadsForPass(num_threads, static_cast<double>(Y.size())),
      [&](int part, int parts) {
        const int begin = internal::PartBegin(n, part, parts);
        const int end = internal::PartBegin(n, part + 1, parts);
        CERES_SESYNC_DISPATCH_ON_D(d, TangentProjectionDispatch,
                                   Y.data() + begin * stride,
                                   V.data() + begin * stride, r, d, end - begin,
                                   out->data() + begin * stride);
      });
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
  CERES_SESYNC_DISPATCH_ON_D(d, PolarKernel, Y.data(), V.data(),
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
  CERES_SESYNC_DISPATCH_ON_D(d, PolarKernel, X.data(), nullptr,
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
  CERES_SESYNC_DISPATCH_ON_D(d_, PolarKernel, x, v.data(), r_, d_, 1,
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
  CERES_SESYNC_DISPATCH_ON_D(d(), PolarKernel, x, v.data(), r(), d(), n_,
                             x_plus_delta);
  return AllFinite(x_plus_delta, AmbientSize());
}

namespace {

// The block-diagonal orthonormal tangent basis of St(d, r)^n at x, written
// row-major as the PlusJacobian (ambient x tangent) or, transposed, as the
// MinusJacobian (tangent x ambient).
bool WriteProductBasis(int d, int r, int n, const double* x, bool transposed,
                       double* jacobian) {
  BlockOps ops(d, r);
  const int ambient = r * d;
  const int tangent = StiefelTangentDimension(d, r);
  const std::ptrdiff_t total_ambient = static_cast<std::ptrdiff_t>(n) * ambient;
  const std::ptrdiff_t total_tangent = static_cast<std::ptrdiff_t>(n) * tangent;
  std::fill_n(jacobian, total_ambient * total_tangent, 0.0);
  for (int i = 0; i < n; ++i) {
    if (!ops.SetPoint(x + static_cast<std::ptrdiff_t>(i) * ambient)) {
      return false;
    }
    const std::ptrdiff_t row0 = static_cast<std::ptrdiff_t>(i) * ambient;
    const std::ptrdiff_t col0 = static_cast<std::ptrdiff_t>(i) * tangent;
    ops.Basis([&](int row, int col, double value) {
      if (transposed) {
        jacobian[(col0 + col) * total_ambient + row0 + row] = value;
      } else {
        jacobian[(row0 + row) * total_tangent + col0 + col] = value;
      }
    });
  }
  return true;
}

}  // namespace

bool StiefelProductManifold::PlusJacobian(const double* x,
                                          double* jacobian) const {
  return IsValid() && WriteProductBasis(d(), r(), n_, x, false, jacobian);
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
  return IsValid() && WriteProductBasis(d(), r(), n_, x, true, jacobian);
}

}  // namespace ceres_sesync
