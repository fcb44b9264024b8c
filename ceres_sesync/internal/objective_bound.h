// A rigorous upper bound on the objective (pose_graph.h: eq. 12 plus the
// landmark and prior terms) at a given solution, for the suboptimality bounds
// of certificates: EvaluateObjective computes F in double, and a certificate
// must not rest on an F that round-off made look smaller than it is.

#ifndef CERES_SESYNC_INTERNAL_OBJECTIVE_BOUND_H_
#define CERES_SESYNC_INTERNAL_OBJECTIVE_BOUND_H_

#include "ceres_sesync/internal/measurement_weights.h"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::internal {

// F(poses, landmarks) + a bound on |computed F - exact F| for
// EvaluateObjective's arithmetic (standard model, u = 2^-53). Per residual
// entry r = x_0 - sum_k a_k b_k (d <= 3 products), |fl(r) - r| <= e =
// gamma_{d+1} (|x_0| + sum |a_k b_k|) + the inputs' own terms; its square
// errs by at most 2|fl(r)| e + e^2 (+ the rounding of the square); the
// weighted sums of m nonnegative terms err by at most gamma_{m+4} of their
// value. Typically 1e-12 of F or less (more on large maps: the residuals
// of translations far from the origin cancel more digits). Landmark
// measurements are bounded like the translation residuals of edges, priors
// like an edge from the identity pose. `landmarks` must hold one position
// per landmark. With `weights`, the same for the weighted problem
// (measurement_weights.h: its precisions are doubles, so the analysis is
// unchanged; weights apply to every term).
double ObjectiveUpperBound(const PoseGraph& graph, const Poses& poses,
                           const LandmarkPositions& landmarks = {},
                           const MeasurementWeights& weights = {});
inline double ObjectiveUpperBound(const PoseGraph& graph,
                                  const Solution& solution,
                                  const MeasurementWeights& weights = {}) {
  return ObjectiveUpperBound(graph, solution.poses, solution.landmarks,
                             weights);
}

// The sum of every precision of the graph (kappa and tau of the edges, nu of
// the landmark measurements, kappa and tau of the priors): the scale below
// which an objective value is zero up to round-off. With `weights`, of the
// weighted problem.
double TotalPrecision(const PoseGraph& graph,
                      const MeasurementWeights& weights = {});

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_OBJECTIVE_BOUND_H_
