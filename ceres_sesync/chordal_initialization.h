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
bool ChordalRotations(const PoseGraph& graph, Eigen::MatrixXd* R,
                      std::string* error);

// Chordal rotations plus the optimal translations for them, as poses with
// pose 0 at the origin.
bool ChordalInitialization(const PoseGraph& graph, Poses* poses,
                           std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_CHORDAL_INITIALIZATION_H_
