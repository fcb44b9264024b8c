// Chordal initialization (Martinec and Pajdla 2007; Carlone et al. 2015; used
// by Rosen et al. 2019, Section 6): the rotations minimizing
// sum kappa_ij ||R_j - R_i R~_ij||_F^2 without the orthogonality constraints
// (one sparse linear least-squares solve, gauge R_0 = I), each block then
// projected to SO(d); translations are the optimal ones for those rotations
// (eq. 21).

#ifndef CERES_SESYNC_CHORDAL_INITIALIZATION_H_
#define CERES_SESYNC_CHORDAL_INITIALIZATION_H_

#include <string>

#include "Eigen/Core"
#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

// Chordal rotations R = [R_1 ... R_n] (d x dn). `graph` must pass
// ValidatePoseGraph. Returns false (with a message) if the sparse solve fails.
// Gauge: R_0 = I; with priors, the world frame (the chordal estimate includes
// the world rotation R_w, and R is expressed relative to it). Parts of the
// graph whose rotations are tied together only through translations (the
// world with position priors only; poses linked only by landmarks) are
// estimated separately and then rotated into place against the full
// objective (internal/chordal.h).
bool ChordalRotations(const PoseGraph& graph, Eigen::MatrixXd* R,
                      std::string* error);

// Chordal rotations plus the optimal translations for them, as poses with
// pose 0 at the origin (with priors: in the world frame, t_w = 0 when a
// prior has a position term).
bool ChordalInitialization(const PoseGraph& graph, Poses* poses,
                           std::string* error);

// The same with the optimal landmark positions (one per landmark).
bool ChordalInitialization(const PoseGraph& graph, Solution* solution,
                           std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CHORDAL_INITIALIZATION_H_
