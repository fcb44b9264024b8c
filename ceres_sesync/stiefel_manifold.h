// The Stiefel manifold St(d, r) = {Y in R^(r x d) : Y^T Y = I_d} and the
// product St(d, r)^n used by the SE-Sync Burer-Monteiro relaxation
// (Rosen et al., IJRR 2019, Sec. 4.1 and Problem 9).
//
// Layout convention (fixed; the solver depends on it). A point of St(d, r)^n
// is an r x (d n) column-major Eigen::MatrixXd Y whose i-th block
// Y_i = Y.middleCols(d * i, d) is r x d with Y_i^T Y_i = I_d. Because of the
// column-major storage block i occupies r * d contiguous doubles, which is
// exactly the ambient layout of one StiefelManifold parameter block (an r x d
// column-major matrix), so an St(d, r)^n point can be handed to Ceres either
// as one StiefelProductManifold block or as n StiefelManifold blocks.
//
// Two interfaces are provided:
//
//  1. Free functions on whole r x (d n) matrices. They are the hot path of the
//     Riemannian solver: O(n r d^2) work. d = 2 and d = 3 use fixed-size
//     kernels with O(1) heap allocations per call (none per block); other d
//     use a dynamic fallback whose retraction/projection allocate small d x d
//     eigensolver buffers per block.
//
//  2. ceres::Manifold implementations (StiefelManifold, StiefelProductManifold)
//     so that St(d, r) and St(d, r)^n can be used as parameter-block manifolds
//     in a ceres::Problem or a ceres::GradientProblem.
//
// Retraction. Everything here uses the polar retraction
//
//   R_Y(V) = (Y + V) (I_d + V^T V)^(-1/2)      (blockwise),
//
// i.e. the polar factor of Y + V, which for a tangent V is also the nearest
// point of St(d, r) to Y + V (a second-order retraction). Per block it costs
// one d x d Gram matrix G = (Y_i + V_i)^T (Y_i + V_i), a closed-form G^(-1/2)
// (d = 2, 3; an eigendecomposition otherwise), one r x d x d product and
// usually one Newton-Schulz polishing step, so the result is orthonormal to
// < 5e-15 even for large steps. Blocks with cond(Y_i + V_i) > 100 (never for
// a tangent V with ||V_i||_2 < 99) fall back to an SVD.

#ifndef CERES_SESYNC_STIEFEL_MANIFOLD_H_
#define CERES_SESYNC_STIEFEL_MANIFOLD_H_

#include <random>
#include <string>

#include "Eigen/Core"
#include "ceres/manifold.h"

namespace ceres_sesync {

// ---------------------------------------------------------------------------
// Free functions on St(d, r)^n (hot path).
//
// Shape contract shared by all of them: d >= 1, the matrices have the same
// number of rows and a number of columns that is a multiple of d. On a shape
// violation the functions never crash: the output is resized to 0 x 0 (or an
// empty matrix is returned). Use IsStiefelProductShape() to validate input
// once, outside of loops. Unless stated otherwise `out` may alias an input.
// ---------------------------------------------------------------------------

// Dimension of St(d, r): r d - d (d + 1) / 2. Returns -1 unless 1 <= d <= r.
int StiefelTangentDimension(int d, int r);

// Returns true if Y is r x (d n) with 1 <= d <= r and n >= 1 (it does not check
// orthonormality). Otherwise returns false and, if `error` is not null,
// describes the problem.
bool IsStiefelProductShape(const Eigen::MatrixXd& Y, int d, std::string* error);

// Largest blockwise deviation from orthonormality, max_i ||Y_i^T Y_i - I||_max
// (or +infinity for an invalid shape). Useful in tests and assertions.
double StiefelProductOrthonormalityError(const Eigen::MatrixXd& Y, int d);

// SymBlockDiag_d(A^T B): the n symmetric d x d blocks
// sym(A_i^T B_i) = (A_i^T B_i + B_i^T A_i) / 2, stored side by side as a
// d x (d n) matrix. A and B are p x (d n) for any p >= 0 (e.g. p = r).
Eigen::MatrixXd SymBlockDiagProduct(const Eigen::MatrixXd& A,
                                    const Eigen::MatrixXd& B, int d);

// Orthogonal projection onto the tangent space of St(d, r)^n at Y, eq. (42)
// of Rosen et al. 2019:
//   out = V - Y SymBlockDiag_d(Y^T V)   (blockwise),
// so that Y_i^T out_i + out_i^T Y_i = 0. `out` may alias V (not Y). Large
// products are split over up to `num_threads` threads by blocks (the same
// results for any thread count).
void ProjectToStiefelProductTangent(const Eigen::MatrixXd& Y,
                                    const Eigen::MatrixXd& V, int d,
                                    Eigen::MatrixXd* out, int num_threads = 1);

// Polar retraction, blockwise:
//   out_i = (Y_i + V_i) (I + V_i^T V_i)^(-1/2) = polar factor of (Y_i + V_i).
// (For a tangent V, (Y_i + V_i)^T (Y_i + V_i) = I + V_i^T V_i; the
// implementation uses the left-hand form (Y_i + V_i) ((Y_i + V_i)^T
// (Y_i + V_i))^(-1/2), which is the polar factor for any V with Y_i + V_i of
// full column rank.) The output is orthonormal to < 5e-15.
// `out` may alias Y or V.
void RetractStiefelProduct(const Eigen::MatrixXd& Y, const Eigen::MatrixXd& V,
                           int d, Eigen::MatrixXd* out);

// Nearest point of St(d, r)^n to X in the Frobenius norm: the orthogonal
// polar factor U_i W_i^T of each block (X_i = U_i S_i W_i^T a thin SVD).
// Computed like the retraction (closed-form inverse square root of X_i^T X_i
// plus polishing), with an SVD for blocks of condition number > 100. For a
// rank-deficient block the result is still orthonormal (one of the nearest
// points). `out` may alias X.
void ProjectToStiefelProduct(const Eigen::MatrixXd& X, int d,
                             Eigen::MatrixXd* out);

// A Haar-uniformly distributed random point of St(d, r)^n: for each block the
// Q factor of the thin QR of an r x d standard Gaussian matrix, with the sign
// of each column chosen so that diag(R) > 0 (Mezzadri 2007). The Gaussians
// are generated from the raw 64-bit output of `rng` (Box-Muller), so the
// result is deterministic for a given rng state and does not depend on the
// standard library's distribution implementations. Returns an
// empty matrix if the sizes are invalid (d < 1, r < d, n < 0) or rng is null.
Eigen::MatrixXd RandomStiefelProductPoint(int d, int r, int n,
                                          std::mt19937_64* rng);

// ---------------------------------------------------------------------------
// ceres::Manifold implementations.
//
// Tangent coordinates of St(d, r) at a point Y (TangentSize() = r d -
// d (d + 1) / 2 numbers, in this order):
//   * d (d - 1) / 2 coordinates w_k of a skew-symmetric d x d matrix
//       Omega = sum_k w_k E_k,  E_k = (e_a e_b^T - e_b e_a^T) / sqrt(2),
//     for the pairs (a, b), a < b, in the order (0,1), (0,2), ..., (1,2), ...;
//   * (r - d) d coordinates of an (r - d) x d matrix K, column-major.
// The tangent vector is V = Y Omega + Y_perp K, where Y_perp is the r x (r-d)
// orthonormal complement of Y formed by the last r - d columns of the full Q
// factor of a Householder QR of Y (a deterministic function of Y). The basis
// {Y E_k} u {Y_perp e_p e_q^T} is orthonormal in the Frobenius metric, so
// MinusJacobian = PlusJacobian^T.
//
// Plus(x, delta) = R_x(V(delta)) with the polar retraction above.
// Minus(y, x) is its exact inverse: it finds the tangent V with R_x(V) = y,
// V = y S - Y, where S is the symmetric positive-definite solution of the
// d x d Lyapunov equation (Y^T y) S + S (y^T Y) = 2 I, and returns the
// coordinates of V. It returns false if y is not in the image of R_x (S does
// not exist or is not positive definite), which can only happen when y is far
// from x (e.g. the principal angles between their column spans reach 90 deg).
// ---------------------------------------------------------------------------

// St(d, r) as a Ceres manifold. The ambient vector is an r x d column-major
// matrix. Sizes must satisfy 1 <= d <= r; otherwise the object is invalid:
// IsValid() is false, AmbientSize() = TangentSize() = 0 and every operation
// returns false.
class StiefelManifold : public ceres::Manifold {
 public:
  StiefelManifold(int d, int r);
  ~StiefelManifold() override = default;

  bool IsValid() const { return valid_; }
  int d() const { return d_; }
  int r() const { return r_; }

  int AmbientSize() const override;
  int TangentSize() const override;

  bool Plus(const double* x, const double* delta,
            double* x_plus_delta) const override;
  // Row-major AmbientSize() x TangentSize(): the orthonormal tangent basis
  // [vec(Y E_k), vec(Y_perp F_l)] described above.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // tangent_matrix = ambient_matrix * PlusJacobian(x), computed directly
  // (O(num_rows r d^2), without forming the Jacobian).
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows,
                                   const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  bool Minus(const double* y, const double* x,
             double* y_minus_x) const override;
  // Row-major TangentSize() x AmbientSize(): the transpose of PlusJacobian.
  bool MinusJacobian(const double* x, double* jacobian) const override;

  // Tangent vector V = Y Omega + Y_perp K (r x d, column-major, written to
  // `tangent`) of the coordinates `delta` at the point `x`.
  bool CoordinatesToTangent(const double* x, const double* delta,
                            double* tangent) const;
  // Coordinates of the orthogonal projection of an arbitrary r x d matrix G
  // onto the tangent space at x (i.e. PlusJacobian(x)^T vec(G)).
  bool TangentToCoordinates(const double* x, const double* ambient,
                            double* delta) const;

 private:
  int d_ = 0;
  int r_ = 0;
  bool valid_ = false;
};

// St(d, r)^n as a single Ceres manifold. The ambient vector is the r x (d n)
// column-major matrix Y of the layout convention (r d n doubles); the tangent
// vector is the concatenation of the n blocks' StiefelManifold coordinates
// (n (r d - d (d + 1) / 2) doubles). Every operation is applied blockwise with
// one shared StiefelManifold. Requires 1 <= d <= r and n >= 1; otherwise the
// object is invalid (see StiefelManifold).
class StiefelProductManifold : public ceres::Manifold {
 public:
  StiefelProductManifold(int d, int r, int n);
  ~StiefelProductManifold() override = default;

  bool IsValid() const { return block_.IsValid() && n_ >= 1; }
  int d() const { return block_.d(); }
  int r() const { return block_.r(); }
  int n() const { return n_; }
  // The manifold of one block.
  const StiefelManifold& block_manifold() const { return block_; }

  int AmbientSize() const override;
  int TangentSize() const override;

  bool Plus(const double* x, const double* delta,
            double* x_plus_delta) const override;
  // Row-major, block diagonal with the blocks' PlusJacobians. Note that this
  // is a dense (r d n) x (n t) matrix; for large n prefer
  // RightMultiplyByPlusJacobian, which Ceres' GradientProblemSolver uses.
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows,
                                   const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  bool Minus(const double* y, const double* x,
             double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  StiefelManifold block_;
  int n_ = 0;
};

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_STIEFEL_MANIFOLD_H_
