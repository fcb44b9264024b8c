// Samplers for the noise model of SE-Sync's synthetic experiments (Rosen et
// al., IJRR 2019, eq. 10 and Appendix A):
//
//   t~_ij = t_ij + N(0, tau^-1 I_d),   R~_ij = R_ij * Langevin(I_d, kappa).
//
// Every sampler here draws only raw 64-bit words from a std::mt19937_64 and
// turns them into variates with its own arithmetic (no
// std::*_distribution, whose algorithms differ between standard libraries),
// so a seed yields the same stream on every platform.

#ifndef CERES_SESYNC_LANGEVIN_H_
#define CERES_SESYNC_LANGEVIN_H_

#include <random>

#include "Eigen/Core"

namespace ceres_sesync {

// Returns a uniform variate in [0, 1) with 53 random bits.
double SampleUniform01(std::mt19937_64* rng);

// Returns a standard normal variate N(0, 1) (Marsaglia's polar method).
double SampleStandardNormal(std::mt19937_64* rng);

// Returns a sample of the von Mises distribution vM(mu, concentration) on the
// circle, density exp(concentration * cos(theta - mu)) / (2 pi I0(conc.))
// (paper eq. 59), wrapped to [-pi, pi]. Uses the rejection sampler of Best
// and Fisher (1979, Appl. Statist. 28(2)), with the intermediate quantities
// rearranged so that it stays accurate for very large concentrations (angles
// of order 1/sqrt(concentration) are resolved to full relative precision).
// concentration == 0 gives the uniform distribution; +infinity gives mu.
// Returns NaN if concentration is negative or NaN, or mu is not finite.
double SampleVonMises(double mu, double concentration, std::mt19937_64* rng);

// Returns a sample X ~ Langevin(I_d, kappa), the isotropic Langevin
// distribution on SO(d) with mode I and concentration kappa, by the paper's
// Algorithm 4: a rotation through an angle theta ~ vM(0, 2 kappa) about an
// axis uniform on S^2 (d = 3), or R(theta) (d = 2). Multiply a mode M on the
// left (M * X) for Langevin(M, kappa).
//
// Note: for d = 2 this is exactly the density of eq. (52). For d = 3 it is
// the paper's generative description, which is what its experiments use; it
// draws the angle from vM(0, 2 kappa) itself and so omits the Haar-measure
// factor (1 - cos theta) of the exact SO(3) density (52). The RMS angle is
// therefore exactly eq. (63) for both d.
//
// Returns an empty matrix if d is not 2 or 3 or kappa is negative or NaN.
Eigen::MatrixXd SampleIsotropicLangevin(int d, double kappa,
                                        std::mt19937_64* rng);

// Expected value of cos(theta) for theta ~ vM(0, concentration): the Bessel
// ratio I1(c) / I0(c), evaluated without overflow for any c >= 0 (series for
// small c, continued fraction otherwise). For X ~ Langevin(I, kappa) drawn by
// SampleIsotropicLangevin, E||X - I||_F^2 = 4 (1 - VonMisesMeanCosine(2
// kappa)) for both d = 2 and d = 3.
double VonMisesMeanCosine(double concentration);

// The paper's eq. (63): the standard deviation (= RMS) of the rotation angle
// of Langevin(M, kappa), sqrt(int_{-pi}^{pi} theta^2 exp(2 kappa cos theta)
// / (2 pi I0(2 kappa)) dtheta), in radians, by composite Simpson quadrature
// (scaled to avoid overflow; accurate to ~1e-10 relative for any kappa >= 0).
double LangevinAngularStandardDeviation(double kappa);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_LANGEVIN_H_
