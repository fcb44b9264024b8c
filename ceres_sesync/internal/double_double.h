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
// SubtractProducts(s, x, y, K) (the inner loop of the supernodal
// factorization) computes s - sum_{j=1..K} x_j y_j for K <= kMaxProducts
// with ONE renormalization: the high parts T_j accumulate exactly by TwoSum,
// the low parts t_j (errors and low products) in double, and TwoSum(T_K,
// t_K) at the end. It satisfies the Cray-style model with the products
// fused:
//
//   fl(s - sum_j x_j y_j) = s (1 + alpha) - sum_j x_j y_j (1 + beta_j),
//   |alpha| <= (K^2 + 2K) u^2 (1 + 40u),
//   |beta_j| <= (n_j^2 + 6 n_j + 6) u^2 (1 + 40u),  n_j = K - j + 1
//
// (n_j: the steps from product j to the end; K = 1: 3.01 u^2 and 13.01 u^2).
// Since K^2 + 2K <= 32 K and n^2 + 6n + 6 <= 32 n for 1 <= n <= 25, this is
// at most what K steps of the Cray model with kDoubleDoubleUnitRoundoff give
// the accumulator (K factors) and product j (n_j factors), so in the
// recursion of Lemma 8.4 (with Higham's Lemma 3.3, (1 + theta_a)(1 +
// theta_b) = 1 + theta_{a+b}) every term of an entry still carries at most
// theta_m for m the products from it to the end: the Cholesky bound
// gamma_{k+1} |L||L^T| holds unchanged, whatever the blocking.
//
// Derivation (normalized operands, |z_lo| <= u |z_hi|, P_j = |x_j,hi
// y_j,hi|, m_j = |s_hi| + sum_{i<=j} P_i). Step j: p_j = RN(x_hi y_hi);
// p_e = x_hi y_hi - p_j exactly by an FMA, |p_e| <= u P_j; a = RN(x_hi y_lo +
// p_e) (FMA, error <= 2u^2 P_j, |a| <= 2u (1 + u) P_j); q_j = RN(x_lo y_hi +
// a) (FMA, error <= (3u^2 + 2u^3) P_j, |q_j| <= (3u + 6u^2) P_j), so q_j is
// within (5u^2 + 2u^3) P_j of Q_j = p_e + x_hi y_lo + x_lo y_hi, and x_lo y_lo
// (<= u^2 P_j) is dropped. (T_j, e_j) = TwoSum(T_{j-1}, -p_j) is exact with
// |e_j| <= u |T_j| <= u (1 + 10u) m_j (T_0 = s_hi; |T_j| <= (1 + u)^{j+1}
// m_j). w_j = RN(t_{j-1} - q_j) and t_j = RN(e_j + w_j) (t_0 = s_lo) err by
// at most u (2 + u)(|t_{j-1}| + |q_j|) + u |e_j| together. Unrolling,
// r = T_K + t_K = s - sum_j (p_j + q_j) + sum_j (roundings of w_j, t_j), so
//   |r - (s - sum_j x_j y_j)| <= sum_j (6u^2 + 2u^3) P_j
//                                + sum_j (roundings of w_j and t_j),
// and |t_{j-1}| <= (1 + 28u) tau_{j-1} with tau_{j-1} = u (|s_hi| +
// sum_{i<j} (3 P_i + m_i)) = u (j |s_hi| + sum_{i<j} (3 + j - i) P_i). Step
// j's roundings are therefore at most u^2 (1 + 32u) ((2j + 1) |s_hi| +
// sum_{i<=j} (7 + 2 (j - i)) P_i); summed over j = 1..K, |s_hi| collects
// K^2 + 2K and P_i collects sum_{j=i..K} (7 + 2 (j - i)) = n_i^2 + 6 n_i.
// With |s_hi| <= |s| / (1 - u) and P_j <= |x_j y_j| / (1 - u)^2 the bounds
// above follow (the (1 + 40u) covers every second-order factor for
// K <= 8). A zero product (x or y zero) is an exact no-op on (T, t) (p =
// p_e = a = q = 0, e = 0), so explicit zeros change no result.
//
// Underflow (operands or products below 2^-969, where the low parts lose
// bits): every rounding above obeys fl(z) = z (1 + delta) + eta with
// |eta| <= 2^-1075, and eta != 0 only for the product and the three FMAs of
// a step (sums with a subnormal result are exact, so TwoSum stays exact);
// carried through the derivation, each step errs by at most 4 (1 + u)^2K
// 2^-1075 < 2^-1070 absolutely beyond the model, the per-operation margin
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

// The correctly rounded double operations, for the *Parts functions below.
// FmaAdd and FmaSub are a + b and a - b as well (rounded once: RN(a 1 + b) =
// RN(a + b)), which SIMD code may compute with FMA instructions to use both
// kinds of floating-point units.
struct DoubleOps {
  static double Add(double a, double b) { return a + b; }
  static double Sub(double a, double b) { return a - b; }
  static double FmaAdd(double a, double b) { return a + b; }
  static double FmaSub(double a, double b) { return a - b; }
  static double Fma(double a, double b, double c) { return std::fma(a, b, c); }
};

// The steps of SubtractProducts (bound in the file comment) on the parts of
// double-doubles. `Real` is double or a SIMD vector of doubles, with
// Ops::Add, Sub and Fma the correctly rounded a + b, a - b and a b + c (lane
// by lane: extended_cholesky.cc's kernels; FmaAdd and FmaSub likewise). Every
// type runs the same
// operations in the same order, so results do not depend on the vector
// width.
//
// One step: (T, t) <- (T, t) - x y, with (T, t) not renormalized.
template <class Ops, class Real>
[[gnu::always_inline]] inline void SubtractProductParts(Real x_hi, Real x_lo,
                                                        Real y_hi, Real y_lo,
                                                        Real* T, Real* t) {
  const Real p = x_hi * y_hi;
  const Real p_e = Ops::Fma(x_hi, y_hi, -p);  // Exact: x_hi y_hi = p + p_e.
  const Real a = Ops::Fma(x_hi, y_lo, p_e);
  const Real q = Ops::Fma(x_lo, y_hi, a);
  // (S, e) = TwoSum(T, -p).
  const Real S = Ops::Sub(*T, p);
  const Real b = Ops::Sub(S, *T);
  const Real e = Ops::Sub(Ops::FmaSub(*T, Ops::Sub(S, b)), Ops::FmaAdd(p, b));
  *t = Ops::Add(e, Ops::Sub(*t, q));
  *T = S;
}

// (T, t) <- TwoSum(T, t): the normalized double-double T + t.
template <class Ops, class Real>
[[gnu::always_inline]] inline void RenormalizeParts(Real* T, Real* t) {
  const Real r = Ops::Add(*T, *t);
  const Real c = Ops::Sub(r, *T);
  *t = Ops::Add(Ops::Sub(*T, Ops::Sub(r, c)), Ops::Sub(*t, c));
  *T = r;
}

// The largest number of products SubtractProducts' bound covers.
constexpr int kMaxProducts = 8;

// s - sum_{j<count} x[j] y[j] with one renormalization, count <=
// kMaxProducts (bound in the file comment).
inline DoubleDouble SubtractProducts(const DoubleDouble& s,
                                     const DoubleDouble* x,
                                     const DoubleDouble* y, int count) {
  double T = s.hi, t = s.lo;
  for (int j = 0; j < count; ++j) {
    SubtractProductParts<DoubleOps>(x[j].hi, x[j].lo, y[j].hi, y[j].lo, &T, &t);
  }
  RenormalizeParts<DoubleOps>(&T, &t);
  return {T, t};
}

// Joldes-Muller-Popescu Algorithm 12 (DWTimesDW3), on parts as above (the
// kernels scale columns with it).
template <class Ops, class Real>
[[gnu::always_inline]] inline void MultiplyParts(Real x_hi, Real x_lo,
                                                 Real y_hi, Real y_lo,
                                                 Real* r_hi, Real* r_lo) {
  const Real p = x_hi * y_hi;
  const Real e = Ops::Fma(x_hi, y_hi, -p);  // TwoProduct.
  const Real tl0 = x_lo * y_lo;
  const Real tl1 = Ops::Fma(x_hi, y_lo, tl0);
  const Real cl2 = Ops::Fma(x_lo, y_hi, tl1);
  const Real b = Ops::Add(e, cl2);
  // FastTwoSum(p, b).
  const Real s = Ops::Add(p, b);
  *r_lo = Ops::Sub(b, Ops::Sub(s, p));
  *r_hi = s;
}

inline DoubleDouble operator*(const DoubleDouble& x, const DoubleDouble& y) {
  DoubleDouble r;
  MultiplyParts<DoubleOps>(x.hi, x.lo, y.hi, y.lo, &r.hi, &r.lo);
  return r;
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

// Higham's gamma_k = k u / (1 - k u) for double, u = 2^-53.
inline double DoubleGamma(double k) {
  constexpr double u = 0x1p-53;
  return k * u / (1 - k * u);
}

// gamma_k = k w / (1 - k w) for w = kDoubleDoubleUnitRoundoff (Higham's
// gamma for this arithmetic).
inline double DoubleDoubleGamma(double k) {
  return k * kDoubleDoubleUnitRoundoff / (1 - k * kDoubleDoubleUnitRoundoff);
}

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_DOUBLE_DOUBLE_H_
