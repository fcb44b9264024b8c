// Per-term weights: the one place where they enter the objective.
//
// A weighted problem (graduated non-convexity, robust_solver.h) scales the
// precisions of term k by a weight w_k >= 0. The terms are those of
// pose_graph.h's F, in one order: the relative pose measurements (k = 0..m-1),
// then the landmark measurements (k = m + q), then the priors (k = m + M + q),
// NumWeightedTerms(graph) in all. Its precisions are the doubles
//
//   kappa_k^w = fl(w_k kappa_k),  tau_k^w = fl(w_k tau_k),
//   nu_k^w = fl(w_k nu_k),
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

// Empty, or one finite weight >= 0 per term of the graph (see above).
using MeasurementWeights = std::vector<double>;

// m + M + P: the relative pose measurements, landmark measurements and
// priors, the order of the weights.
inline size_t NumWeightedTerms(const PoseGraph& graph) {
  return graph.measurements.size() + graph.landmark_measurements.size() +
         graph.priors.size();
}
// Term indices of landmark measurement q and prior q.
inline size_t LandmarkTerm(const PoseGraph& graph, size_t q) {
  return graph.measurements.size() + q;
}
inline size_t PriorTerm(const PoseGraph& graph, size_t q) {
  return graph.measurements.size() + graph.landmark_measurements.size() + q;
}

struct Precisions {
  double kappa = 0;
  double tau = 0;
};

// The precisions of term k of the weighted problem (see above): a relative
// pose measurement, a landmark measurement (its nu) or a prior.
inline Precisions WeightedPrecisions(const RelativePoseMeasurement& e,
                                     const MeasurementWeights& weights,
                                     size_t k) {
  if (weights.empty()) return {e.kappa, e.tau};
  return {weights[k] * e.kappa, weights[k] * e.tau};
}
inline double WeightedPrecision(const LandmarkMeasurement& o,
                                const MeasurementWeights& weights, size_t k) {
  return weights.empty() ? o.nu : weights[k] * o.nu;
}
inline Precisions WeightedPrecisions(const PosePrior& p,
                                     const MeasurementWeights& weights,
                                     size_t k) {
  if (weights.empty()) return {p.kappa, p.tau};
  return {weights[k] * p.kappa, weights[k] * p.tau};
}

// Checks that `weights` is empty or has one finite weight >= 0 per term,
// and that the terms of positive weight connect the problem: every pose,
// landmark and (with priors) the world frame, and its translational terms
// all translation nodes (else a Laplacian of the weighted problem is
// singular and the relative placement of the components undetermined; the
// same conditions as ValidatePoseGraph's for the graph itself). A prior
// term of positive weight ties its pose to the world frame, whose
// translation node exists when some prior of the graph has a position
// term. Returns false with a message saying which (for disconnection: the
// number of components and one vertex of the smaller side) otherwise.
bool CheckMeasurementWeights(const PoseGraph& graph,
                             const MeasurementWeights& weights,
                             std::string* error);

// F of the weighted problem at `poses` and `landmarks` (sizes as for
// EvaluateObjective, unchecked): pose_graph.h's F with the weighted
// precisions. EvaluateObjective is this with empty weights.
double WeightedObjective(const PoseGraph& graph,
                         const MeasurementWeights& weights, const Poses& poses,
                         const LandmarkPositions& landmarks = {});

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_MEASUREMENT_WEIGHTS_H_
