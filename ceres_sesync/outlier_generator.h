// Wrong loop closures for outlier experiments (robust_solver.h): a copy of a
// pose graph with outlier measurements appended.
//
// The outliers are a fraction F of the output's loop closures (measurements
// other than odometry, i.e. |i - j| != 1 in dense order: IsOdometry() of
// robust_solver.h): for L loop closures in the input, k = round(F L / (1 -
// F)) are added, so F = 0.5 doubles the loop closures and F = 0.9 adds nine
// wrong ones per true one. They are appended after the input's
// measurements (the first m measurements of the output are the input's,
// unchanged), never between consecutive poses, and carry the median kappa
// and the median tau of the input's loop closures.
//
//  - kRandom: each outlier joins a uniformly random pair of poses (i, j),
//    |i - j| >= 2, with a uniformly random (Haar) relative rotation and a
//    relative translation uniform in the ball of radius rho, the largest
//    translation of the input's loop closures (else of any measurement;
//    at least 1e-3): the scale of a true closure, not an obviously absurd
//    one.
//  - kClustered ("perceptual aliasing"): groups of cluster_size mutually
//    consistent wrong closures. A group picks poses a, b (|a - b| >= 2) and
//    a wrong relative pose T of b seen from a (random as above), and joins
//    (a + s, b + s), s = 0..cluster_size-1, with the measurement that
//    placing the segment around b rigidly at X_a T would produce:
//    X_{a+s}^-1 X_a T X_b^-1 X_{b+s}, X the reference trajectory (the
//    graph's initial poses, else dead reckoning along its odometry), with
//    a and b drawn so that both segments fit. The last group may be
//    shorter.
//
// Deterministic for a seed on every platform (raw std::mt19937_64 words,
// langevin.h's samplers).

#ifndef CERES_SESYNC_OUTLIER_GENERATOR_H_
#define CERES_SESYNC_OUTLIER_GENERATOR_H_

#include <cstdint>
#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct OutlierOptions {
  enum class Mode { kRandom, kClustered };
  Mode mode = Mode::kRandom;
  // Fraction F of the output's loop closures that are outliers, in [0, 1).
  double fraction = 0.1;
  // kClustered: wrong closures per group (>= 1).
  int cluster_size = 10;
  uint64_t seed = 0;
};

// Writes the corrupted graph (a copy of `graph` plus the outliers: same
// poses, vertex ids, initial poses and FIX) to `corrupted` and the indices
// of the added measurements (ascending) to `outlier_indices` (if not null).
// Returns false with a message for invalid options, a graph that fails
// ValidatePoseGraph, has no loop closures or fewer than 3 poses (kRandom)
// or cluster_size + 2 poses (kClustered), or (kClustered) has no initial
// poses and no complete odometry chain.
bool AddOutliers(const PoseGraph& graph, const OutlierOptions& options,
                 PoseGraph* corrupted, std::vector<int>* outlier_indices,
                 std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_OUTLIER_GENERATOR_H_
