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

// Wrong data associations and false position fixes, for graphs with
// landmarks or position priors: a copy of the graph with outlier landmark
// measurements and priors appended (the input's come first, unchanged; the
// relative pose measurements are the input's).
//  - Wrong associations, k_L = round(F_L M / (1 - F_L)) for M landmark
//    measurements: a uniformly random landmark measurement (i, l, z, nu)
//    of the input attributed to a uniformly random other landmark l' != l,
//    i.e. (i, l', z, nu): a front end matching an observation to the wrong
//    landmark. No pair (l, l') is used twice (two such observations, from
//    different poses, would agree with each other on where l' is: a
//    consistent wrong cluster, not random outliers). One can fit by chance
//    when l' lies within the noise of l.
//  - False fixes, k_P = round(F_P P / (1 - F_P)) for P position priors
//    (priors with a position term): a position prior on a uniformly random
//    pose i at t_ref(i) (the initial poses, else dead reckoning along
//    odometry moved rigidly onto the position priors by least squares) plus a
//    jump in a uniform direction of 10 to 40 (uniformly) standard deviations
//    tau^(-1/2) per axis, tau the median of the input's position priors, which
//    it gets: a multipath jump.
struct LandmarkOutlierOptions {
  // F_L, in [0, 1): fraction of the output's landmark measurements that are
  // wrong associations.
  double landmark_fraction = 0.1;
  // F_P, in [0, 1): fraction of the output's position priors that are
  // false fixes.
  double prior_fraction = 0;
  uint64_t seed = 0;
};

// Writes the corrupted graph to `corrupted` and the indices of the added
// landmark measurements and priors (into corrupted->landmark_measurements
// and ->priors, ascending) to the index vectors (if not null). Returns false
// with a message for invalid options, a graph that fails ValidatePoseGraph,
// F_L > 0 without two landmarks, or F_P > 0 without a position prior or a
// reference trajectory.
bool AddLandmarkOutliers(const PoseGraph& graph,
                         const LandmarkOutlierOptions& options,
                         PoseGraph* corrupted,
                         std::vector<int>* landmark_outliers,
                         std::vector<int>* prior_outliers, std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_OUTLIER_GENERATOR_H_
