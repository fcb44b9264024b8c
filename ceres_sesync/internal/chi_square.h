// The chi-square distribution with k degrees of freedom (small integer k):
// the TLS threshold of robust_solver.h is one of its quantiles.

#ifndef CERES_SESYNC_INTERNAL_CHI_SQUARE_H_
#define CERES_SESYNC_INTERNAL_CHI_SQUARE_H_

namespace ceres_sesync::internal {

// P(X <= x) for X ~ chi^2(k), k >= 1, by the closed forms of the
// regularized lower incomplete gamma function P(k/2, x/2) at integer and
// half-integer arguments (Abramowitz & Stegun 26.4.4-26.4.5): even k,
//   1 - exp(-x/2) sum_{i < k/2} (x/2)^i / i!;
// odd k, erf(sqrt(x/2)) - exp(-x/2) sum over the half-integer terms.
// Accurate to ~1e-15 absolute for k <= 50.
double ChiSquareCdf(double x, int k);

// The p-quantile of chi^2(k): the x with ChiSquareCdf(x, k) = p, for p in
// (0, 1), by bisection to full double precision. NaN for p outside (0, 1)
// or k < 1.
double ChiSquareQuantile(double p, int k);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CHI_SQUARE_H_
