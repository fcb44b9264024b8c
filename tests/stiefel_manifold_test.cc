// Tests of ceres_sesync/stiefel_manifold.h: the free functions on St(d, r)^n
// and the ceres::Manifold implementations StiefelManifold and
// StiefelProductManifold.

#include "ceres_sesync/stiefel_manifold.h"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "Eigen/Dense"
#include "ceres/ceres.h"
#include "ceres/manifold_test_utils.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

using ceres::HasCorrectMinusJacobianAt;
using ceres::HasCorrectPlusJacobianAt;
using ceres::HasCorrectRightMultiplyByPlusJacobianAt;
using ceres::MinusPlusIsIdentityAt;
using ceres::MinusPlusJacobianIsIdentityAt;
using ceres::PlusMinusIsIdentityAt;
using ceres::Vector;
using ceres::XMinusXIsZeroAt;
using ceres::XPlusZeroIsXAt;
using Eigen::MatrixXd;

// Tolerance for the Ceres manifold invariants. The Plus/Minus round trips are
// exact up to rounding (~1e-15), but the Jacobian checks compare against a
// Ridders numerical derivative, which is accurate to roughly 1e-10 relative
// for these smooth maps; 1e-9 leaves a margin while still catching any wrong
// entry (an error in a basis vector is O(1)).
constexpr double kManifoldTolerance = 1e-9;

MatrixXd Gaussian(int rows, int cols, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  MatrixXd m(rows, cols);
  for (Eigen::Index k = 0; k < m.size(); ++k) m.data()[k] = normal(*rng);
  return m;
}

Vector AsVector(const MatrixXd& m) {
  return Eigen::Map<const Vector>(m.data(), m.size());
}

// Polar factor U V^T of a matrix, computed independently of the library
// (Eigen's BDCSVD on the whole block).
MatrixXd ReferencePolar(const MatrixXd& x) {
  Eigen::BDCSVD<MatrixXd> svd(x, Eigen::ComputeThinU | Eigen::ComputeThinV);
  return svd.matrixU() * svd.matrixV().transpose();
}

MatrixXd ReferenceProjectToProduct(const MatrixXd& x, int d) {
  MatrixXd out(x.rows(), x.cols());
  for (Eigen::Index i = 0; i < x.cols() / d; ++i) {
    out.middleCols(d * i, d) = ReferencePolar(x.middleCols(d * i, d));
  }
  return out;
}

// max_i ||Y_i^T V_i + V_i^T Y_i||_max: zero iff V is tangent at Y.
double TangencyError(const MatrixXd& y, const MatrixXd& v, int d) {
  double worst = 0.0;
  for (Eigen::Index i = 0; i < y.cols() / d; ++i) {
    const MatrixXd p =
        y.middleCols(d * i, d).transpose() * v.middleCols(d * i, d);
    worst = std::max(worst, (p + p.transpose()).cwiseAbs().maxCoeff());
  }
  return worst;
}

struct Sizes {
  int d;
  int r;
  int n;
};

// ---------------------------------------------------------------------------
// Sizes and validation.
// ---------------------------------------------------------------------------

TEST(StiefelTangentDimension, MatchesFormulaAndRejectsBadSizes) {
  EXPECT_EQ(StiefelTangentDimension(1, 1), 0);  // St(1,1) = {+-1}.
  EXPECT_EQ(StiefelTangentDimension(1, 4), 3);  // The 3-sphere.
  EXPECT_EQ(StiefelTangentDimension(2, 2), 1);  // O(2).
  EXPECT_EQ(StiefelTangentDimension(3, 3), 3);  // O(3).
  EXPECT_EQ(StiefelTangentDimension(3, 5), 9);
  EXPECT_EQ(StiefelTangentDimension(0, 3), -1);
  EXPECT_EQ(StiefelTangentDimension(3, 2), -1);
}

TEST(StiefelManifold, InvalidSizesGiveAnInertObjectInsteadOfACrash) {
  StiefelManifold bad(3, 2);
  EXPECT_FALSE(bad.IsValid());
  EXPECT_EQ(bad.AmbientSize(), 0);
  EXPECT_EQ(bad.TangentSize(), 0);
  double x[6] = {1, 0, 0, 1, 0, 0};
  double out[6];
  EXPECT_FALSE(bad.Plus(x, x, out));
  EXPECT_FALSE(bad.Minus(x, x, out));
  EXPECT_FALSE(bad.PlusJacobian(x, out));
  EXPECT_FALSE(bad.MinusJacobian(x, out));
  StiefelProductManifold bad_product(2, 3, 0);
  EXPECT_FALSE(bad_product.IsValid());
  EXPECT_EQ(bad_product.AmbientSize(), 0);
  EXPECT_FALSE(bad_product.Plus(x, x, out));
}

TEST(StiefelManifold, NonFiniteInputIsRejected) {
  StiefelManifold manifold(2, 3);
  std::mt19937_64 rng(3);
  MatrixXd x = RandomStiefelProductPoint(2, 3, 1, &rng);
  Vector delta = Vector::Zero(manifold.TangentSize());
  delta(0) = std::nan("");
  Vector out(manifold.AmbientSize());
  EXPECT_FALSE(manifold.Plus(x.data(), delta.data(), out.data()));
  MatrixXd y = x;
  y(0, 0) = std::numeric_limits<double>::infinity();
  Vector coords(manifold.TangentSize());
  EXPECT_FALSE(manifold.Minus(y.data(), x.data(), coords.data()));
}

TEST(StiefelProductShape, FreeFunctionsRejectBadShapesWithoutCrashing) {
  std::string error;
  EXPECT_TRUE(IsStiefelProductShape(MatrixXd::Zero(3, 6), 2, &error));
  EXPECT_FALSE(IsStiefelProductShape(MatrixXd::Zero(3, 7), 2, &error));
  EXPECT_THAT(error, testing::HasSubstr("multiple of d"));
  EXPECT_FALSE(IsStiefelProductShape(MatrixXd::Zero(1, 6), 2, &error));
  EXPECT_FALSE(IsStiefelProductShape(MatrixXd::Zero(3, 6), 0, &error));

  const MatrixXd a = MatrixXd::Ones(3, 6);
  const MatrixXd b = MatrixXd::Ones(3, 7);
  EXPECT_EQ(SymBlockDiagProduct(a, b, 2).size(), 0);
  EXPECT_EQ(SymBlockDiagProduct(a, a, 0).size(), 0);
  MatrixXd out = MatrixXd::Ones(2, 2);
  ProjectToStiefelProductTangent(a, b, 2, &out);
  EXPECT_EQ(out.size(), 0);
  out = MatrixXd::Ones(2, 2);
  RetractStiefelProduct(a, b, 2, &out);
  EXPECT_EQ(out.size(), 0);
  out = MatrixXd::Ones(2, 2);
  ProjectToStiefelProduct(b, 2, &out);
  EXPECT_EQ(out.size(), 0);
  std::mt19937_64 rng(1);
  EXPECT_EQ(RandomStiefelProductPoint(3, 2, 4, &rng).size(), 0);
  EXPECT_EQ(RandomStiefelProductPoint(2, 3, 4, nullptr).size(), 0);
}

// ---------------------------------------------------------------------------
// Free functions.
// ---------------------------------------------------------------------------

TEST(SymBlockDiagProduct, MatchesNaiveDenseComputation) {
  std::mt19937_64 rng(11);
  for (const Sizes& s :
       {Sizes{2, 3, 5}, Sizes{3, 5, 4}, Sizes{4, 6, 3}, Sizes{1, 2, 7}}) {
    const MatrixXd a = Gaussian(s.r, s.d * s.n, &rng);
    const MatrixXd b = Gaussian(s.r, s.d * s.n, &rng);
    const MatrixXd dense = a.transpose() * b;  // (dn) x (dn)
    const MatrixXd result = SymBlockDiagProduct(a, b, s.d);
    ASSERT_EQ(result.rows(), s.d);
    ASSERT_EQ(result.cols(), s.d * s.n);
    for (int i = 0; i < s.n; ++i) {
      const MatrixXd block = dense.block(s.d * i, s.d * i, s.d, s.d);
      const MatrixXd expected = 0.5 * (block + block.transpose());
      // Same sums in a possibly different order: rounding-level agreement.
      EXPECT_LT((result.middleCols(s.d * i, s.d) - expected).norm(),
                1e-13 * (1.0 + expected.norm()))
          << "d=" << s.d << " block " << i;
    }
  }
}

class StiefelProductFreeFunctions : public testing::TestWithParam<Sizes> {};

TEST_P(StiefelProductFreeFunctions,
       TangentProjectionIsTangentIdempotentOrthogonal) {
  const Sizes s = GetParam();
  std::mt19937_64 rng(100 + s.d * 10 + s.r);
  const MatrixXd y = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
  const MatrixXd v = Gaussian(s.r, s.d * s.n, &rng);
  MatrixXd p;
  ProjectToStiefelProductTangent(y, v, s.d, &p);
  ASSERT_EQ(p.rows(), v.rows());
  ASSERT_EQ(p.cols(), v.cols());
  // Tangent: Y_i^T P_i skew to rounding (entries of size ~1).
  EXPECT_LT(TangencyError(y, p, s.d), 1e-12);
  // Idempotent.
  MatrixXd pp;
  ProjectToStiefelProductTangent(y, p, s.d, &pp);
  EXPECT_LT((pp - p).norm(), 1e-12 * p.norm());
  // Orthogonal projection: the residual V - P is orthogonal to every tangent
  // vector, in particular to P itself and to another projected vector.
  MatrixXd q;
  ProjectToStiefelProductTangent(y, Gaussian(s.r, s.d * s.n, &rng), s.d, &q);
  EXPECT_NEAR(((v - p).array() * p.array()).sum(), 0.0,
              1e-12 * v.squaredNorm());
  EXPECT_NEAR(((v - p).array() * q.array()).sum(), 0.0,
              1e-12 * v.squaredNorm());
  // Equals the textbook formula V - Y SymBlockDiag(Y^T V).
  const MatrixXd sym = SymBlockDiagProduct(y, v, s.d);
  for (int i = 0; i < s.n; ++i) {
    const MatrixXd expected =
        v.middleCols(s.d * i, s.d) -
        y.middleCols(s.d * i, s.d) * sym.middleCols(s.d * i, s.d);
    EXPECT_LT((p.middleCols(s.d * i, s.d) - expected).norm(), 1e-13 * v.norm());
  }
  // In-place use (out aliases V) gives the same result.
  MatrixXd in_place = v;
  ProjectToStiefelProductTangent(y, in_place, s.d, &in_place);
  EXPECT_LT((in_place - p).norm(), 1e-14 * p.norm());
}

TEST_P(StiefelProductFreeFunctions, RetractionStaysOnManifoldAndIsPolarFactor) {
  const Sizes s = GetParam();
  std::mt19937_64 rng(200 + s.d * 10 + s.r);
  const MatrixXd y = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
  MatrixXd out;
  // R_Y(0) = Y.
  RetractStiefelProduct(y, MatrixXd::Zero(y.rows(), y.cols()), s.d, &out);
  EXPECT_LT((out - y).cwiseAbs().maxCoeff(), 1e-15 * 10);
  for (double step : {1e-8, 1e-3, 0.1, 1.0, 10.0, 50.0, 1000.0}) {
    MatrixXd v;
    ProjectToStiefelProductTangent(y, Gaussian(s.r, s.d * s.n, &rng), s.d, &v);
    v *= step / std::sqrt(static_cast<double>(s.n));
    RetractStiefelProduct(y, v, s.d, &out);
    // Orthonormal to 1e-14 for any step size (the largest steps exercise the
    // SVD fallback for blocks with cond(Y_i + V_i) > 100).
    EXPECT_LT(StiefelProductOrthonormalityError(out, s.d), 1e-14) << step;
    // The polar retraction is the nearest point of St(d,r)^n to Y + V.
    const MatrixXd expected = ReferenceProjectToProduct(y + v, s.d);
    EXPECT_LT((out - expected).cwiseAbs().maxCoeff(), 1e-12) << step;
    // In place (out aliases Y, and out aliases V).
    MatrixXd y_copy = y;
    RetractStiefelProduct(y_copy, v, s.d, &y_copy);
    EXPECT_LT((y_copy - out).cwiseAbs().maxCoeff(), 1e-15) << step;
    MatrixXd v_copy = v;
    RetractStiefelProduct(y, v_copy, s.d, &v_copy);
    EXPECT_LT((v_copy - out).cwiseAbs().maxCoeff(), 1e-15) << step;
  }
}

TEST_P(StiefelProductFreeFunctions, RetractionAgreesWithYPlusVToFirstOrder) {
  const Sizes s = GetParam();
  std::mt19937_64 rng(300 + s.d * 10 + s.r);
  const MatrixXd y = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
  MatrixXd v;
  ProjectToStiefelProductTangent(y, Gaussian(s.r, s.d * s.n, &rng), s.d, &v);
  v /= v.norm();
  // e(t) = ||R_Y(tV) - (Y + tV)|| = (t^2/2) ||Y V^T V|| + O(t^4) for the polar
  // retraction, so halving t divides e by 4 (and the ratio e/t^2 converges).
  MatrixXd out;
  double previous = 0.0;
  for (int k = 0; k < 6; ++k) {
    const double t = 0.1 / std::pow(2.0, k);
    RetractStiefelProduct(y, t * v, s.d, &out);
    const double error = (out - (y + t * v)).norm();
    if (k > 0) {
      EXPECT_NEAR(previous / error, 4.0, 0.1) << "t = " << t;
    }
    previous = error;
  }
}

TEST_P(StiefelProductFreeFunctions, ProjectionToManifoldIsPolarFactor) {
  const Sizes s = GetParam();
  std::mt19937_64 rng(400 + s.d * 10 + s.r);
  // A point on the manifold is its own projection.
  const MatrixXd y = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
  MatrixXd out;
  ProjectToStiefelProduct(y, s.d, &out);
  EXPECT_LT((out - y).cwiseAbs().maxCoeff(), 1e-14);
  // A generic matrix projects to the SVD polar factor of each block, which is
  // no farther from X than any other point of the manifold.
  const MatrixXd x = Gaussian(s.r, s.d * s.n, &rng);
  ProjectToStiefelProduct(x, s.d, &out);
  EXPECT_LT((out - ReferenceProjectToProduct(x, s.d)).cwiseAbs().maxCoeff(),
            1e-12);
  EXPECT_LT(StiefelProductOrthonormalityError(out, s.d), 1e-14);
  for (int trial = 0; trial < 20; ++trial) {
    const MatrixXd other = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
    EXPECT_LE((x - out).norm(), (x - other).norm());
  }
  // In place.
  MatrixXd x_copy = x;
  ProjectToStiefelProduct(x_copy, s.d, &x_copy);
  EXPECT_LT((x_copy - out).cwiseAbs().maxCoeff(), 1e-15);
  // Ill-conditioned blocks: condition 50 (closed-form path) and 1e5 (SVD
  // fallback) both match the reference polar factor. The polar factor's
  // sensitivity is ~1/sigma_min, so allow 1e-12 * cond.
  for (double cond : {50.0, 1e5}) {
    const MatrixXd u = ReferencePolar(Gaussian(s.r, s.d, &rng));
    const MatrixXd w = ReferencePolar(Gaussian(s.d, s.d, &rng));
    const Eigen::VectorXd sigma =
        Eigen::VectorXd::LinSpaced(s.d, 1.0, 1.0 / cond);
    const MatrixXd block = u * sigma.asDiagonal() * w.transpose();
    ProjectToStiefelProduct(block, s.d, &out);
    EXPECT_LT((out - ReferencePolar(block)).cwiseAbs().maxCoeff(), 1e-12 * cond)
        << cond;
    EXPECT_LT(StiefelProductOrthonormalityError(out, s.d), 1e-14) << cond;
  }
  // A rank-deficient block (zero and rank one) still gives an orthonormal
  // block.
  MatrixXd deficient = x;
  deficient.leftCols(s.d).setZero();
  if (s.n > 1) {
    deficient.middleCols(s.d, s.d) =
        Gaussian(s.r, 1, &rng) * Gaussian(1, s.d, &rng);
  }
  ProjectToStiefelProduct(deficient, s.d, &out);
  EXPECT_LT(StiefelProductOrthonormalityError(out, s.d), 1e-14);
}

TEST_P(StiefelProductFreeFunctions,
       RandomPointsAreOrthonormalAndDeterministic) {
  const Sizes s = GetParam();
  std::mt19937_64 rng1(77);
  std::mt19937_64 rng2(77);
  std::mt19937_64 rng3(78);
  const MatrixXd a = RandomStiefelProductPoint(s.d, s.r, s.n, &rng1);
  const MatrixXd b = RandomStiefelProductPoint(s.d, s.r, s.n, &rng2);
  const MatrixXd c = RandomStiefelProductPoint(s.d, s.r, s.n, &rng3);
  ASSERT_EQ(a.rows(), s.r);
  ASSERT_EQ(a.cols(), s.d * s.n);
  EXPECT_LT(StiefelProductOrthonormalityError(a, s.d), 1e-14);
  EXPECT_EQ(a, b);  // Bitwise identical for the same seed.
  EXPECT_GT((a - c).norm(), 0.1);
  // The next draw from the same engine differs from the first.
  EXPECT_GT((RandomStiefelProductPoint(s.d, s.r, s.n, &rng1) - a).norm(), 0.1);
}

INSTANTIATE_TEST_SUITE_P(Sizes, StiefelProductFreeFunctions,
                         testing::Values(Sizes{2, 2, 3}, Sizes{2, 3, 4},
                                         Sizes{3, 3, 3}, Sizes{3, 5, 6},
                                         Sizes{1, 4, 3}, Sizes{4, 6, 2}),
                         [](const testing::TestParamInfo<Sizes>& info) {
                           return "d" + std::to_string(info.param.d) + "r" +
                                  std::to_string(info.param.r) + "n" +
                                  std::to_string(info.param.n);
                         });

TEST(RandomStiefelProductPoint, IsHaarDistributedInFirstAndSecondMoments) {
  // For Haar-distributed Y in St(d, r): E[Y] = 0 and E[Y_jk^2] = 1/r. (A QR
  // without the sign fix would bias the diagonal entries to be positive.)
  const int d = 2, r = 4, samples = 20000;
  std::mt19937_64 rng(5);
  const MatrixXd y = RandomStiefelProductPoint(d, r, samples, &rng);
  MatrixXd mean = MatrixXd::Zero(r, d);
  MatrixXd second = MatrixXd::Zero(r, d);
  for (int i = 0; i < samples; ++i) {
    mean += y.middleCols(d * i, d);
    second += y.middleCols(d * i, d).cwiseAbs2();
  }
  mean /= samples;
  second /= samples;
  // Standard errors: sqrt(1/(r N)) = 0.0035 for the mean and about 0.0025
  // for the second moment; 0.02 is > 5 sigma.
  EXPECT_LT(mean.cwiseAbs().maxCoeff(), 0.02);
  EXPECT_LT((second.array() - 1.0 / r).abs().maxCoeff(), 0.02);
}

// ---------------------------------------------------------------------------
// Ceres manifold invariants.
// ---------------------------------------------------------------------------

class StiefelManifoldInvariants
    : public testing::TestWithParam<std::pair<int, int>> {};

TEST_P(StiefelManifoldInvariants, HoldAtRandomPoints) {
  const int d = GetParam().first;
  const int r = GetParam().second;
  StiefelManifold manifold(d, r);
  ASSERT_TRUE(manifold.IsValid());
  EXPECT_EQ(manifold.AmbientSize(), r * d);
  EXPECT_EQ(manifold.TangentSize(), StiefelTangentDimension(d, r));
  std::mt19937_64 rng(1000 + 10 * d + r);
  for (int trial = 0; trial < 5; ++trial) {
    const Vector x = AsVector(RandomStiefelProductPoint(d, r, 1, &rng));
    // Tangent steps of norm ~0.5 (ordinary optimizer steps)...
    const Vector delta = 0.5 / std::sqrt(manifold.TangentSize()) *
                         AsVector(Gaussian(manifold.TangentSize(), 1, &rng));
    // ... and a different nearby point, not produced by Plus.
    MatrixXd y_matrix;
    ProjectToStiefelProduct(
        Eigen::Map<const MatrixXd>(x.data(), r, d) + 0.3 * Gaussian(r, d, &rng),
        d, &y_matrix);
    const Vector y = AsVector(y_matrix);
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y,
                                         kManifoldTolerance);
  }
}

TEST_P(StiefelManifoldInvariants, MinusInvertsPlusForLargeSteps) {
  const int d = GetParam().first;
  const int r = GetParam().second;
  StiefelManifold manifold(d, r);
  std::mt19937_64 rng(2000 + 10 * d + r);
  const Vector x = AsVector(RandomStiefelProductPoint(d, r, 1, &rng));
  for (double size : {2.0, 10.0}) {
    const Vector delta = size / std::sqrt(manifold.TangentSize()) *
                         AsVector(Gaussian(manifold.TangentSize(), 1, &rng));
    Vector x_plus(manifold.AmbientSize());
    ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), x_plus.data()));
    Vector back(manifold.TangentSize());
    ASSERT_TRUE(manifold.Minus(x_plus.data(), x.data(), back.data()));
    // Conditioning of the Lyapunov solve grows with the step; 1e-9 relative.
    EXPECT_LT((back - delta).norm(), 1e-9 * delta.norm()) << size;
  }
}

TEST_P(StiefelManifoldInvariants, PlusJacobianIsOrthonormalTangentBasis) {
  const int d = GetParam().first;
  const int r = GetParam().second;
  StiefelManifold manifold(d, r);
  std::mt19937_64 rng(3000 + 10 * d + r);
  const MatrixXd x = RandomStiefelProductPoint(d, r, 1, &rng);
  const int a = manifold.AmbientSize(), t = manifold.TangentSize();
  ceres::Matrix jacobian(a, t);  // Row-major, as Ceres passes it.
  ASSERT_TRUE(manifold.PlusJacobian(x.data(), jacobian.data()));
  EXPECT_LT((jacobian.transpose() * jacobian - MatrixXd::Identity(t, t)).norm(),
            1e-14 * t);
  for (int k = 0; k < t; ++k) {
    const MatrixXd v =
        Eigen::Map<const MatrixXd>(Vector(jacobian.col(k)).data(), r, d);
    EXPECT_LT(TangencyError(x, v, d), 1e-14) << "column " << k;
    // CoordinatesToTangent agrees with the Jacobian columns.
    Vector e = Vector::Zero(t);
    e(k) = 1.0;
    MatrixXd v2(r, d);
    ASSERT_TRUE(manifold.CoordinatesToTangent(x.data(), e.data(), v2.data()));
    EXPECT_LT((v2 - v).norm(), 1e-14);
  }
  // TangentToCoordinates is the adjoint: coordinates of the projection.
  const MatrixXd g = Gaussian(r, d, &rng);
  Vector coords(t);
  ASSERT_TRUE(manifold.TangentToCoordinates(x.data(), g.data(), coords.data()));
  EXPECT_LT((coords - jacobian.transpose() * AsVector(g)).norm(), 1e-14 * t);
}

TEST(StiefelManifold, MinusFailsWhenTargetIsNotReachable) {
  // On St(1, 2) (the circle) the polar retraction reaches only the open half
  // circle around x; the antipode is not in its image.
  StiefelManifold manifold(1, 2);
  const double x[2] = {1.0, 0.0};
  const double antipode[2] = {-1.0, 0.0};
  double delta[1];
  EXPECT_FALSE(manifold.Minus(antipode, x, delta));
  // A point at 60 degrees is reachable and is recovered exactly: on the circle
  // the polar retraction of a step t is at angle atan(t).
  const double y[2] = {0.5, std::sqrt(3.0) / 2.0};
  ASSERT_TRUE(manifold.Minus(y, x, delta));
  EXPECT_NEAR(std::abs(delta[0]), std::tan(M_PI / 3.0), 1e-14);
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, StiefelManifoldInvariants,
    testing::Values(std::make_pair(2, 2), std::make_pair(2, 3),
                    std::make_pair(3, 3), std::make_pair(3, 5),
                    std::make_pair(1, 4)),
    [](const testing::TestParamInfo<std::pair<int, int>>& info) {
      return "d" + std::to_string(info.param.first) + "r" +
             std::to_string(info.param.second);
    });

class StiefelProductManifoldInvariants : public testing::TestWithParam<Sizes> {
};

TEST_P(StiefelProductManifoldInvariants, HoldAtRandomPoints) {
  const Sizes s = GetParam();
  StiefelProductManifold manifold(s.d, s.r, s.n);
  ASSERT_TRUE(manifold.IsValid());
  EXPECT_EQ(manifold.AmbientSize(), s.r * s.d * s.n);
  EXPECT_EQ(manifold.TangentSize(), s.n * StiefelTangentDimension(s.d, s.r));
  std::mt19937_64 rng(4000 + 10 * s.d + s.r);
  for (int trial = 0; trial < 3; ++trial) {
    const MatrixXd x_matrix = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
    const Vector x = AsVector(x_matrix);
    const Vector delta = 0.5 / std::sqrt(manifold.TangentSize() / s.n) *
                         AsVector(Gaussian(manifold.TangentSize(), 1, &rng));
    MatrixXd y_matrix;
    ProjectToStiefelProduct(x_matrix + 0.3 * Gaussian(s.r, s.d * s.n, &rng),
                            s.d, &y_matrix);
    const Vector y = AsVector(y_matrix);
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y,
                                         kManifoldTolerance);
  }
}

TEST_P(StiefelProductManifoldInvariants,
       PlusEqualsFreeRetractionOfBasisTangent) {
  const Sizes s = GetParam();
  StiefelProductManifold manifold(s.d, s.r, s.n);
  StiefelManifold block(s.d, s.r);
  std::mt19937_64 rng(5000 + 10 * s.d + s.r);
  const MatrixXd y = RandomStiefelProductPoint(s.d, s.r, s.n, &rng);
  const Vector delta = AsVector(Gaussian(manifold.TangentSize(), 1, &rng));
  // The tangent matrix of the coordinates, via the Jacobian (the basis).
  ceres::Matrix jacobian(manifold.AmbientSize(), manifold.TangentSize());
  ASSERT_TRUE(manifold.PlusJacobian(y.data(), jacobian.data()));
  const Vector v_vec = jacobian * delta;
  const MatrixXd v = Eigen::Map<const MatrixXd>(v_vec.data(), s.r, s.d * s.n);
  EXPECT_LT(TangencyError(y, v, s.d), 1e-13);
  MatrixXd expected;
  RetractStiefelProduct(y, v, s.d, &expected);
  MatrixXd actual(s.r, s.d * s.n);
  ASSERT_TRUE(manifold.Plus(y.data(), delta.data(), actual.data()));
  EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 1e-13);
  // The product is exactly the blockwise StiefelManifold.
  const int t = block.TangentSize();
  for (int i = 0; i < s.n; ++i) {
    MatrixXd block_plus(s.r, s.d);
    ASSERT_TRUE(block.Plus(y.middleCols(s.d * i, s.d).eval().data(),
                           delta.data() + t * i, block_plus.data()));
    EXPECT_LT(
        (block_plus - actual.middleCols(s.d * i, s.d)).cwiseAbs().maxCoeff(),
        1e-15);
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, StiefelProductManifoldInvariants,
                         testing::Values(Sizes{2, 3, 4}, Sizes{3, 4, 3}),
                         [](const testing::TestParamInfo<Sizes>& info) {
                           return "d" + std::to_string(info.param.d) + "r" +
                                  std::to_string(info.param.r) + "n" +
                                  std::to_string(info.param.n);
                         });

// ---------------------------------------------------------------------------
// End to end inside ceres::Solve.
// ---------------------------------------------------------------------------

// r(Y) = Y - A for one St(3,3)^2 parameter block (18 numbers), so the cost is
// (1/2) sum_i ||Y_i - A_i||_F^2.
class DistanceToTarget : public ceres::SizedCostFunction<18, 18> {
 public:
  explicit DistanceToTarget(const MatrixXd& target) : target_(target) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    for (int k = 0; k < 18; ++k)
      residuals[k] = parameters[0][k] - target_.data()[k];
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, 18, 18, Eigen::RowMajor>>(jacobians[0])
          .setIdentity();
    }
    return true;
  }

 private:
  MatrixXd target_;
};

TEST(StiefelProductManifold, CeresSolveFindsNearestOrthogonalMatrices) {
  std::mt19937_64 rng(42);
  // Targets A_i: noisy orthogonal matrices (noise 0.1 per entry), a typical
  // rotation-estimation situation. (For arbitrary A_i Gauss-Newton converges
  // only linearly, because the residual at the optimum is large.)
  const MatrixXd targets =
      RandomStiefelProductPoint(3, 3, 2, &rng) + 0.1 * Gaussian(3, 6, &rng);
  // Closed form: argmin_{Y in O(3)} ||Y - A||_F is the polar factor of A.
  const MatrixXd expected = ReferenceProjectToProduct(targets, 3);
  // St(3,3) = O(3) has two components and a retraction never leaves the
  // starting one, so start in the component of the answer (flip a column
  // of a random start if its determinant has the wrong sign).
  MatrixXd y = RandomStiefelProductPoint(3, 3, 2, &rng);
  for (int i = 0; i < 2; ++i) {
    if (y.middleCols(3 * i, 3).determinant() *
            expected.middleCols(3 * i, 3).determinant() <
        0) {
      y.col(3 * i) *= -1.0;
    }
  }
  ceres::Problem problem;
  problem.AddResidualBlock(new DistanceToTarget(targets), nullptr, y.data());
  problem.SetManifold(y.data(), new StiefelProductManifold(3, 3, 2));
  ceres::Solver::Options options;
  // Stop on the gradient (max-norm of the projected gradient step), not on
  // the cost change, which stalls at rounding level ~1e-8 away from optimum.
  options.function_tolerance = 0.0;
  options.parameter_tolerance = 0.0;
  options.gradient_tolerance = 1e-13;
  options.max_num_iterations = 200;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_LT(StiefelProductOrthonormalityError(y, 3), 1e-14);
  // Ceres accepts a step only if the computed cost decreases, so the
  // reachable accuracy is about sqrt(eps * cost / curvature) ~ 1e-10 here
  // (measured: 3e-11); 1e-8 per entry, as the brief asks, leaves a margin.
  EXPECT_LT((y - expected).cwiseAbs().maxCoeff(), 1e-8) << summary.FullReport();
}

// Products large enough to be split over threads (> 2^19 entries): bitwise
// the same with one and two threads, also in place (out aliasing V), and
// each block the serial formula's.
TEST(StiefelProduct, BlockwisePassesDoNotDependOnThreadCount) {
  std::mt19937_64 rng(17);
  for (int d : {2, 3}) {
    const int r = d + 2, n = (1 << 19) / (r * d) + 1000;
    const MatrixXd Y = RandomStiefelProductPoint(d, r, n, &rng);
    const MatrixXd V = MatrixXd::Random(r, d * n);
    const MatrixXd Lambda = MatrixXd::Random(d, d * n);
    MatrixXd one, two, in_place = V;
    ProjectToStiefelProductTangent(Y, V, d, &one, 1);
    ProjectToStiefelProductTangent(Y, V, d, &two, 2);
    ProjectToStiefelProductTangent(Y, in_place, d, &in_place, 2);
    EXPECT_TRUE((one.array() == two.array()).all()) << "d = " << d;
    EXPECT_TRUE((one.array() == in_place.array()).all()) << "d = " << d;
    for (int i : {0, n / 2, n - 1}) {
      const MatrixXd Yi = Y.middleCols(d * i, d), Vi = V.middleCols(d * i, d);
      const MatrixXd YtV = Yi.transpose() * Vi;
      const MatrixXd expected = Vi - Yi * (0.5 * (YtV + YtV.transpose()));
      EXPECT_LT((one.middleCols(d * i, d) - expected).norm(), 1e-13);
    }
    internal::BlockDiagonalMultiply(V, Lambda, d, &one, 1);
    internal::BlockDiagonalMultiply(V, Lambda, d, &two, 2);
    EXPECT_TRUE((one.array() == two.array()).all()) << "d = " << d;
    for (int i : {0, n / 2, n - 1}) {
      const MatrixXd expected =
          V.middleCols(d * i, d) * Lambda.middleCols(d * i, d);
      EXPECT_LT((one.middleCols(d * i, d) - expected).norm(), 1e-13);
    }
  }
}

}  // namespace
}  // namespace ceres_sesync
