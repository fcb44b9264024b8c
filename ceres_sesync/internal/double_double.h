// Double-word ("double-double") arithmetic with rigorous error bounds, for
// the high-precision proof of the optimality certificate
// (extended_cholesky.h).
//
// A DoubleDouble is the unevaluated sum hi + lo of two doubles with
// |lo| <= ulp(hi) / 2 (about 106 significant bits). With u = 2^-53 the unit
// roundoff of double, every operation below satisfies the standard model of
// floating-point arithmetic (Higham, "Accuracy and Stability of Numerical
// Algorithms", eq. 2.4)
//
//   fl(x op y) = (x op y)(1 + delta),  |delta| <= kDoubleDoubleUnitRoundoff,
//
// for op in {+, -, *, /} and sqrt, in the absence of underflow (no operand or
// intermediate result below 2^-900 in magnitude, or zero): the callers reject
// data that could underflow. kDoubleDoubleUnitRoundoff = 32 u^2 ~ 3.9e-31 is
// a uniform, deliberately generous cover of the per-operation bounds:
//  - addition: Algorithm 6 (AccurateDWPlusDW) of Joldes, Muller, Popescu,
//    "Tight and rigorous error bounds for basic building blocks of
//    double-word arithmetic", ACM TOMS 44(2), 2017: 3u^2 + 13u^3;
//  - multiplication: their Algorithm 12 (DWTimesDW3, with FMA): 5u^2;
//  - reciprocal 1/x: r0 = RN(1/x_hi), e = 1 - x r0 (1 - x_hi r0 is exact with
//    an FMA because r0 is correctly rounded), r = r0 + r0 e: truncation
//    r0 e^2 <= 4u^2 r0, roundings of e and r0 e <= 5u^2 r0, so <= 9.1u^2;
//    division x / y = x * (1 / y): <= 9.1u^2 + 5u^2 + O(u^4) < 15u^2;
//  - square root: s0 = RN(sqrt(x_hi)), r = x - s0^2 (x_hi - s0^2 exact with
//    an FMA), s = s0 + r / (2 s0): truncation <= 1.2u^2 s0, roundings
//    <= 3u^2 s0, so <= 4.2u^2.
// The FMA is std::fma (correctly rounded, in hardware or in software), so
// results are bitwise identical on every machine.
//
// AccumulateSubtract(x, y) (the inner loop of the factorization) is a cheaper
// subtraction that satisfies the weaker model of Cray-style arithmetic,
//
//   fl(x - y) = x (1 + alpha) - y (1 + beta),  |alpha|, |beta| <= 3.01 u^2:
//
// with (s, e) = TwoSum(x_hi, -y_hi) exact, t = fl(x_lo - y_lo), w = fl(e + t)
// and the exact TwoSum(s, w), the error is w - (e + x_lo - y_lo), at most
// u|e| + (2u + u^2)(|x_lo| + |y_lo|) <= (3u^2 + u^3)(|x_hi| + |y_hi|), since
// |e| <= u|s| <= u(|x_hi| + |y_hi|) and |x_lo| <= u|x_hi|. This model is all
// the backward-error analysis of inner products and Cholesky needs: the
// recursion s_k = s_{k-1}(1 + alpha_k) - p_k(1 + beta_k) gives every term the
// same product of at most k factors (1 + delta) as the standard model does
// in the proof of Higham's Lemma 8.4 (Higham's Ch. 2 notes the same of the
// model for arithmetic without a guard digit), so the Cholesky bound
// gamma_{k+1} |L||L^T| holds with kDoubleDoubleUnitRoundoff.
//
// MultiplySubtract(s, x, y) (the inner loop of the supernodal factorization)
// fuses the product into the subtraction, s - x y, in the same Cray-style
// model with the product counted once:
//
//   fl(s - x y) = s (1 + alpha) - x y (1 + beta),
//   |alpha| <= 3.01 u^2,  |beta| <= 13.01 u^2.
//
// With P = |x_hi y_hi| and normalized operands (|z_lo| <= u |z_hi|):
// p = RN(x_hi y_hi) and p_e = x_hi y_hi - p (exact by an FMA, |p_e| <=
// u |p|); a = RN(x_hi y_lo + p_e) and q = RN(x_lo y_hi + a) (two FMAs)
// approximate p_e + x_hi y_lo + x_lo y_hi: |x_hi y_lo + p_e| <= (2u + u^2) P,
// so q errs by <= u (2u + u^2) P + u (u + (1 + u)(2u + u^2)) P <= (5u^2 +
// 5u^3) P, and |q| <= (3u + 7u^2) P; x_lo y_lo (<= u^2 P) is dropped.
// (S, e) = TwoSum(s_hi, -p) is exact, |e| <= u |S| <= u (1 + u)(|s_hi| +
// (1 + u) P). w = RN(s_lo - q) errs by <= u (|s_lo| + |q|) <= u^2 |s_hi| +
// (3u^2 + 7u^3) P; t = RN(e + w) by <= u (|e| + |w|) <= (2u^2 + 2u^3) |s_hi|
// + (4u^2 + 13u^3) P, using |w| <= (1 + u)(|s_lo| + |q|); the final
// TwoSum(S, t) is exact (it renormalizes). S + t therefore differs from
// s - x y by at most (3u^2 + 2u^3) |s_hi| + (13u^2 + 25u^3) P, and
// |s_hi| <= |s| / (1 - u), P <= |x y| / (1 - u)^2 give the bounds above. In
// the recursion of Lemma 8.4 every product now carries ONE factor (1 + beta)
// where a multiplication and a subtraction carried two, so the Cholesky
// bound gamma_{k+1} |L||L^T| holds a fortiori. A zero product (x or y zero)
// leaves s unchanged exactly (up to the sign of zeros): p = p_e = a = q = 0,
// e = 0, t = s_lo and TwoSum(s_hi, s_lo) = s for normalized s.
//
// Underflow (operands or products below 2^-969, where the low parts lose
// bits): every rounding above obeys fl(z) = z (1 + delta) + eta with
// |eta| <= 2^-1075, and eta != 0 only for the product and the three FMAs
// (sums with a subnormal result are exact, so TwoSum stays exact); carried
// through the derivation, MultiplySubtract errs by at most 4 (1 + u)^3
// 2^-1075 < 2^-1070 absolutely beyond its model, the per-operation margin
// extended_cholesky.cc adds.

#ifndef CERES_SESYNC_INTERNAL_DOUBLE_DOUBLE_H_
#define CERES_SESYNC_INTERNAL_DOUBLE_DOUBLE_H_

#include <cmath>
#include <limits>

namespace ceres_sesync::internal {

constexpr double kUnitRoundoffDouble =
    std::numeric_limits<double>::epsilon() / 2;
constexpr double kDoubleDoubleUnitRoundoff =
    32 * kUnitRoundoffDouble * kUnitRoundoffDouble;

struct DoubleDouble {
  double hi = 0;
  double lo = 0;
  DoubleDouble() = default;
  constexpr DoubleDouble(double h) : hi(h), lo(0) {}  // NOLINT: exact
  constexpr DoubleDouble(double h, double l) : hi(h), lo(l) {}
  // The nearest double (the sum rounded once).
  double ToDouble() const { return hi + lo; }
  // An upper bound on |x| as a double: |hi| + |lo| rounded up by the
  // relative margin 2u (|hi| + |lo| <= |x| (1 + 2u) and one rounding).
  double AbsUpperBound() const {
    return (std::abs(hi) + std::abs(lo)) * (1 + 4 * kUnitRoundoffDouble);
  }
};

namespace dd {

// s + e = a + b exactly (Knuth's TwoSum).
inline DoubleDouble TwoSum(double a, double b) {
  const double s = a + b;
  const double bb = s - a;
  const double e = (a - (s - bb)) + (b - bb);
  return {s, e};
}

// s + e = a + b exactly, provided |a| >= |b| or a == 0 (Dekker's
// Fast2Sum).
inline DoubleDouble FastTwoSum(double a, double b) {
  const double s = a + b;
  const double e = b - (s - a);
  return {s, e};
}

// p + e = a * b exactly (no overflow or underflow).
inline DoubleDouble TwoProduct(double a, double b) {
  const double p = a * b;
  return {p, std::fma(a, b, -p)};
}

}  // namespace dd

inline DoubleDouble operator-(const DoubleDouble& x) { return {-x.hi, -x.lo}; }

// Joldes-Muller-Popescu Algorithm 6 (AccurateDWPlusDW).
inline DoubleDouble operator+(const DoubleDouble& x, const DoubleDouble& y) {
  const DoubleDouble s = dd::TwoSum(x.hi, y.hi);
  const DoubleDouble t = dd::TwoSum(x.lo, y.lo);
  const DoubleDouble v = dd::FastTwoSum(s.hi, s.lo + t.hi);
  return dd::FastTwoSum(v.hi, t.lo + v.lo);
}

inline DoubleDouble operator-(const DoubleDouble& x, const DoubleDouble& y) {
  return x + (-y);
}

// x - y in the Cray-style model above (about 1.6x faster than operator-).
inline DoubleDouble AccumulateSubtract(const DoubleDouble& x,
                                       const DoubleDouble& y) {
  const DoubleDouble s = dd::TwoSum(x.hi, -y.hi);
  return dd::TwoSum(s.hi, s.lo + (x.lo - y.lo));
}

// The correctly rounded double operations, for MultiplySubtractParts.
struct DoubleOps {
  static double Add(double a, double b) { return a + b; }
  static double Sub(double a, double b) { return a - b; }
  static double Fma(double a, double b, double c) { return std::fma(a, b, c); }
};

// s - x y in the Cray-style model above (bound in the file comment), on the
// parts of double-doubles. `Real` is double or a SIMD vector of doubles, with
// Ops::Add, Sub and Fma the correctly rounded a + b, a - b and a b + c (lane
// by lane; extended_cholesky.cc's kernels). Every type runs the same
// operations in the same order, so results do not depend on the vector
// width.
template <class Ops, class Real>
[[gnu::always_inline]] inline void MultiplySubtractParts(
    Real s_hi, Real s_lo, Real x_hi, Real x_lo, Real y_hi, Real y_lo,
    Real* r_hi, Real* r_lo) {
  const Real p = x_hi * y_hi;
  const Real p_e = Ops::Fma(x_hi, y_hi, -p);  // Exact: x_hi y_hi = p + p_e.
  const Real a = Ops::Fma(x_hi, y_lo, p_e);
  const Real q = Ops::Fma(x_lo, y_hi, a);
  // (S, e) = TwoSum(s_hi, -p).
  const Real S = Ops::Sub(s_hi, p);
  const Real b = Ops::Sub(S, s_hi);
  const Real e = Ops::Sub(Ops::Sub(s_hi, Ops::Sub(S, b)), Ops::Add(p, b));
  const Real t = Ops::Add(e, Ops::Sub(s_lo, q));
  // TwoSum(S, t).
  const Real r = Ops::Add(S, t);
  const Real c = Ops::Sub(r, S);
  *r_lo = Ops::Add(Ops::Sub(S, Ops::Sub(r, c)), Ops::Sub(t, c));
  *r_hi = r;
}

inline DoubleDouble MultiplySubtract(const DoubleDouble& s,
                                     const DoubleDouble& x,
                                     const DoubleDouble& y) {
  DoubleDouble r;
  MultiplySubtractParts<DoubleOps>(s.hi, s.lo, x.hi, x.lo, y.hi, y.lo, &r.hi,
                                   &r.lo);
  return r;
}

// Joldes-Muller-Popescu Algorithm 12 (DWTimesDW3).
inline DoubleDouble operator*(const DoubleDouble& x, const DoubleDouble& y) {
  const DoubleDouble c = dd::TwoProduct(x.hi, y.hi);
  const double tl0 = x.lo * y.lo;
  const double tl1 = std::fma(x.hi, y.lo, tl0);
  const double cl2 = std::fma(x.lo, y.hi, tl1);
  return dd::FastTwoSum(c.hi, c.lo + cl2);
}

// 1 / x by one Newton step from the correctly rounded double reciprocal
// (bound in the file comment).
inline DoubleDouble Reciprocal(const DoubleDouble& x) {
  const double r0 = 1 / x.hi;
  const double e = std::fma(-x.hi, r0, 1.0) - x.lo * r0;
  return dd::FastTwoSum(r0, r0 * e);
}

inline DoubleDouble operator/(const DoubleDouble& x, const DoubleDouble& y) {
  return x * Reciprocal(y);
}

// sqrt(x) for x > 0 by one Newton step from the correctly rounded double
// square root (bound in the file comment).
inline DoubleDouble Sqrt(const DoubleDouble& x) {
  const double s0 = std::sqrt(x.hi);
  const double r = std::fma(-s0, s0, x.hi) + x.lo;
  return dd::FastTwoSum(s0, r / (2 * s0));
}

inline DoubleDouble& operator+=(DoubleDouble& x, const DoubleDouble& y) {
  return x = x + y;
}
inline DoubleDouble& operator-=(DoubleDouble& x, const DoubleDouble& y) {
  return x = x - y;
}
inline DoubleDouble& operator*=(DoubleDouble& x, const DoubleDouble& y) {
  return x = x * y;
}

// Comparisons of normalized values: the order of hi, then of lo.
inline bool operator<(const DoubleDouble& x, const DoubleDouble& y) {
  return x.hi < y.hi || (x.hi == y.hi && x.lo < y.lo);
}
inline bool operator>(const DoubleDouble& x, const DoubleDouble& y) {
  return y < x;
}
inline bool operator<=(const DoubleDouble& x, const DoubleDouble& y) {
  return !(y < x);
}
inline bool operator==(const DoubleDouble& x, const DoubleDouble& y) {
  return x.hi == y.hi && x.lo == y.lo;
}

// gamma_k = k w / (1 - k w) for w = kDoubleDoubleUnitRoundoff (Higham's
// gamma for this arithmetic).
inline double DoubleDoubleGamma(double k) {
  return k * kDoubleDoubleUnitRoundoff / (1 - k * kDoubleDoubleUnitRoundoff);
}

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_DOUBLE_DOUBLE_H_
