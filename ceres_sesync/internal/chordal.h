// Chordal rotation estimate from a rotational connection Laplacian.

#ifndef CERES_SESYNC_INTERNAL_CHORDAL_H_
#define CERES_SESYNC_INTERNAL_CHORDAL_H_

#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

// Minimizes tr(R L R^T) over R (d x dn) with R_0 = I fixed, then projects the
// blocks to SO(d). L is L(G^rho) (both triangles stored). Returns false if the
// reduced Laplacian cannot be factorized.
bool ChordalRotationsFromLaplacian(const SparseMatrix& L, int d,
                                   Eigen::MatrixXd* R);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CHORDAL_H_
