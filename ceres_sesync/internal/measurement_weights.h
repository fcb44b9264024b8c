// Per-measurement weights: the one place where they enter the objective.
//
// A weighted problem (graduated non-convexity, robust_solver.h) scales
// measurement k's precisions by a weight w_k >= 0. Its precisions are the
// doubles
//
//   kappa_k^w = fl(w_k kappa_k),   tau_k^w = fl(w_k tau_k),
//
// rounded once, and the weighted problem is DEFINED by them: every consumer
// (the data matrices of sesync_problem.h and their rounding bounds, the
// double-double certificate of certificate_matrix.cc, the objective and its
// rigorous upper bound in objective_bound.h) takes its precisions from
// WeightedPrecisions(), so every proof is a proof about exactly this problem.
// With weights in {0, 1} the products are exact: the weighted problem IS the
// problem of the weight-1 measurements (the zero-weight terms are exact zeros
// in every sum), so its certificate certifies that inlier-only problem.
//
// An empty weight vector means every weight is 1 (the graph's own problem).

#ifndef CERES_SESYNC_INTERNAL_MEASUREMENT_WEIGHTS_H_
#define CERES_SESYNC_INTERNAL_MEASUREMENT_WEIGHTS_H_

#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync::internal {

// Empty, or one finite weight >= 0 per measurement of the graph.
using MeasurementWeights = std::vector<double>;

struct Precisions {
  double kappa = 0;
  double tau = 0;
};

// The precisions of measurement k of the weighted problem (see above).
inline Precisions WeightedPrecisions(const RelativePoseMeasurement& e,
                                     const MeasurementWeights& weights,
                                     size_t k) {
  if (weights.empty()) return {e.kappa, e.tau};
  return {weights[k] * e.kappa, weights[k] * e.tau};
}

// Checks that `weights` is empty or has one finite weight >= 0 per
// measurement, and that the measurements of positive weight connect all the
// poses (else the translational Laplacian of the weighted problem is
// singular and the relative placement of the components undetermined).
// Returns false with a message saying which (for disconnection: the number
// of components and one pose of the smaller side) otherwise.
bool CheckMeasurementWeights(const PoseGraph& graph,
                             const MeasurementWeights& weights,
                             std::string* error);

// F of the weighted problem at `poses`: eq. (12) with the weighted
// precisions (EvaluateObjective for empty weights, bitwise).
double WeightedObjective(const PoseGraph& graph,
                         const MeasurementWeights& weights, const Poses& poses);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_MEASUREMENT_WEIGHTS_H_
