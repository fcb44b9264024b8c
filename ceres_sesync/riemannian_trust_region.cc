#include "ceres_sesync/riemannian_trust_region.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>

namespace ceres_sesync {
namespace {

double Inner(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.cwiseProduct(b).sum();
}

struct TcgResult {
  Eigen::MatrixXd eta;    // The step.
  Eigen::MatrixXd h_eta;  // Hessian times the step.
  int iterations = 0;
  bool hit_boundary = false;
};

// Preconditioned Steihaug-Toint truncated CG for min <g, eta> + 1/2 <H eta,
// eta> subject to <eta, P^{-1} eta> <= radius^2.
// The superlinear stopping term is made scale-free by measuring ||r0|| against
// reference_norm (the gradient norm at the start of the solve).
TcgResult TruncatedCg(const RiemannianTrustRegionOptions& options,
                      RiemannianCostFunction* cost, const Eigen::MatrixXd& g,
                      double radius, double reference_norm,
                      const std::function<bool()>& out_of_time) {
  TcgResult out;
  out.eta.setZero(g.rows(), g.cols());
  out.h_eta.setZero(g.rows(), g.cols());
  Eigen::MatrixXd r = g, z, delta, h_delta;
  cost->Precondition(r, &z);
  double z_r = Inner(z, r);
  delta = -z;
  double e_pe = 0, e_pd = 0, d_pd = z_r;
  const double r0 = std::sqrt(Inner(r, r));
  const double target =
      r0 * std::min(std::pow(r0 / reference_norm, options.tcg_theta),
                    options.tcg_kappa);
  const double radius2 = radius * radius;
  // sqrt(<r, P r>) <= the fraction of the outer tolerance, squared.
  const double floor = options.tcg_tolerance_fraction *
                       options.preconditioned_gradient_tolerance;
  const double floor2 = floor > 0 ? floor * floor : -1;
  for (int j = 0; j < options.max_inner_iterations; ++j) {
    cost->HessianVector(delta, &h_delta);
    ++out.iterations;
    const double d_hd = Inner(delta, h_delta);
    const double alpha = z_r / d_hd;
    const double e_pe_new = e_pe + 2 * alpha * e_pd + alpha * alpha * d_pd;
    if (d_hd <= 0 || e_pe_new >= radius2 || !std::isfinite(alpha)) {
      // Move to the boundary along delta.
      const double tau =
          (-e_pd +
           std::sqrt(std::max(0.0, e_pd * e_pd + d_pd * (radius2 - e_pe)))) /
          d_pd;
      out.eta += tau * delta;
      out.h_eta += tau * h_delta;
      out.hit_boundary = true;
      return out;
    }
    out.eta += alpha * delta;
    out.h_eta += alpha * h_delta;
    e_pe = e_pe_new;
    r += alpha * h_delta;
    cost->ProjectToTangent(r, &r);
    if (std::sqrt(Inner(r, r)) <= target) return out;
    // At the time limit the step so far (a descent step of the model: every
    // CG iterate decreases it) is taken as it is.
    if (out_of_time()) return out;
    cost->Precondition(r, &z);
    const double z_r_old = z_r;
    z_r = Inner(z, r);
    if (z_r <= floor2) return out;
    const double beta = z_r / z_r_old;
    delta = beta * delta - z;
    e_pd = beta * (e_pd + alpha * d_pd);
    d_pd = z_r + beta * beta * d_pd;
  }
  return out;
}

}  // namespace

std::string RiemannianTrustRegionSummary::TerminationString() const {
  switch (termination) {
    case Termination::kGradientTolerance:
      return "gradient tolerance";
    case Termination::kPreconditionedGradientTolerance:
      return "preconditioned gradient tolerance";
    case Termination::kRelativeDecrease:
      return "relative decrease tolerance";
    case Termination::kStepTolerance:
      return "step tolerance";
    case Termination::kMaxIterations:
      return "maximum iterations";
    case Termination::kMaxTime:
      return "time limit";
    case Termination::kUserCallback:
      return "stopped by callback";
    case Termination::kNonFinite:
      return "non-finite cost";
  }
  return "unknown";
}

void MinimizeRiemannianTrustRegion(const RiemannianTrustRegionOptions& options,
                                   RiemannianCostFunction* cost,
                                   Eigen::MatrixXd* x,
                                   RiemannianTrustRegionSummary* summary) {
  using Clock = std::chrono::steady_clock;
  using Termination = RiemannianTrustRegionSummary::Termination;
  const auto start = Clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  *summary = RiemannianTrustRegionSummary();
  double f = cost->Evaluate(*x);
  summary->initial_cost = f;
  Eigen::MatrixXd g, pg, x_new;
  double radius = options.initial_trust_radius;
  double reference_norm = 1, initial_radius = 1;
  // summary->hessian_vector_products at the last callback.
  int products_at_callback = 0;
  bool switched = false;  // The preconditioner changed (UpdatePreconditioner).
  auto finish = [&](Termination t) {
    summary->termination = t;
    summary->final_cost = f;
    summary->time_s = elapsed();
  };
  for (int k = 0;; ++k) {
    cost->Gradient(&g);
    cost->Precondition(g, &pg);
    const double g_norm = std::sqrt(Inner(g, g));
    double pg_norm = std::sqrt(std::max(0.0, Inner(g, pg)));
    // An adaptive preconditioner may change when the test is met: the test
    // that stops the solve is the final preconditioner's.
    while (pg_norm <= options.preconditioned_gradient_tolerance &&
           cost->UpdatePreconditioner(0, /*converged=*/true)) {
      cost->Precondition(g, &pg);
      pg_norm = std::sqrt(std::max(0.0, Inner(g, pg)));
      switched = true;
    }
    summary->final_gradient_norm = g_norm;
    summary->final_preconditioned_gradient_norm = pg_norm;
    if (!std::isfinite(f) || !std::isfinite(g_norm)) {
      return finish(Termination::kNonFinite);
    }
    if (g_norm <= options.gradient_tolerance) {
      return finish(Termination::kGradientTolerance);
    }
    if (pg_norm <= options.preconditioned_gradient_tolerance) {
      return finish(Termination::kPreconditionedGradientTolerance);
    }
    if (k >= options.max_iterations) return finish(Termination::kMaxIterations);
    if (options.max_time_s > 0 && elapsed() >= options.max_time_s) {
      return finish(Termination::kMaxTime);
    }
    if (k == 0) reference_norm = g_norm;
    if (radius <= 0 || switched) {
      // Initial radius: the length (in the P^{-1} norm) of the preconditioned
      // steepest-descent step -P g, a scale-free choice; again after the
      // preconditioner changed (the radius is in its norm).
      radius = pg_norm;
      if (switched) initial_radius = radius;
      switched = false;
    }
    if (k == 0) initial_radius = radius;
    // Inner solve, then shrink the radius until a step is accepted.
    for (;;) {
      const TcgResult step =
          TruncatedCg(options, cost, g, radius, reference_norm, [&] {
            return options.max_time_s > 0 && elapsed() >= options.max_time_s;
          });
      summary->hessian_vector_products += step.iterations;
      switched |=
          cost->UpdatePreconditioner(step.iterations, /*converged=*/false);
      const double model_decrease =
          -(Inner(g, step.eta) + 0.5 * Inner(step.eta, step.h_eta));
      cost->Retract(*x, step.eta, &x_new);
      const double f_new = cost->Evaluate(x_new);
      double actual_decrease = f - f_new;
      // Decreases must stand above the round-off in f (or in the cost's own
      // difference, when it has one).
      double noise = 4 * std::numeric_limits<double>::epsilon() * std::abs(f);
      // rho with a small safeguard against round-off when both are tiny.
      double eps = 1e-14 * std::max(1.0, std::abs(f));
      double difference, round_off;
      if (std::isfinite(f_new) &&
          cost->EvaluationDifference(&difference, &round_off)) {
        actual_decrease = -difference;
        noise = eps = round_off;
      }
      const double rho =
          (actual_decrease + eps) / (std::max(model_decrease, 0.0) + eps);
      const double step_norm = std::sqrt(Inner(step.eta, step.eta));
      const bool accepted =
          rho > 0.1 && std::isfinite(f_new) && actual_decrease > noise;
      if (!accepted || !(rho >= 0.25)) {
        radius *= 0.25;  // Every rejection shrinks the region (also NaN rho).
      } else if (rho > 0.75 && step.hit_boundary) {
        radius *= 2;
      }
      if (accepted) {
        *x = x_new;
        f = f_new;
        summary->iterations = k + 1;
        const int products =
            summary->hessian_vector_products - products_at_callback;
        products_at_callback = summary->hessian_vector_products;
        if (options.callback &&
            !options.callback(k + 1, f, g_norm, radius, products)) {
          cost->Gradient(&g);
          summary->final_gradient_norm = std::sqrt(Inner(g, g));
          return finish(Termination::kUserCallback);
        }
        const bool small_decrease =
            actual_decrease <=
            options.relative_decrease_tolerance * std::abs(f);
        // A convergence test met under a preconditioner that then changes
        // goes on in the new one (see UpdatePreconditioner).
        if ((small_decrease || step_norm <= options.step_tolerance) &&
            !(switched = cost->UpdatePreconditioner(0, /*converged=*/true))) {
          cost->Gradient(&g);
          cost->Precondition(g, &pg);
          summary->final_gradient_norm = std::sqrt(Inner(g, g));
          summary->final_preconditioned_gradient_norm =
              std::sqrt(std::max(0.0, Inner(g, pg)));
          return finish(small_decrease ? Termination::kRelativeDecrease
                                       : Termination::kStepTolerance);
        }
        break;
      }
      // Rejected: restore the current point in the cost function.
      cost->Evaluate(*x);
      if ((step_norm <= options.step_tolerance ||
           radius <= 1e-12 * initial_radius) &&
          !cost->UpdatePreconditioner(0, /*converged=*/true)) {
        summary->iterations = k + 1;
        return finish(Termination::kStepTolerance);
      }
      if (options.max_time_s > 0 && elapsed() >= options.max_time_s) {
        return finish(Termination::kMaxTime);
      }
      if (switched) {  // The radius restarts in the new norm.
        cost->Precondition(g, &pg);
        radius = initial_radius = std::sqrt(std::max(0.0, Inner(g, pg)));
        switched = false;
      }
    }
  }
}

}  // namespace ceres_sesync
