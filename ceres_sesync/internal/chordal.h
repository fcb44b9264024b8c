// Chordal rotation estimate from a rotational connection Laplacian.

#ifndef CERES_SESYNC_INTERNAL_CHORDAL_H_
#define CERES_SESYNC_INTERNAL_CHORDAL_H_

#include <vector>

#include "ceres_sesync/internal/sesync_problem.h"

namespace ceres_sesync::internal {

// Minimizes tr(R L R^T) over R (d x dn) with the first block of every
// connected component of L's block graph fixed at I (R_0 = I for a connected
// graph), then projects the blocks to SO(d). L is L(G^rho) (both triangles
// stored). `component` (if not null) gets the component of every block,
// numbered in order of their first blocks (block 0 is in component 0).
// `block_ordering` (if not null and not empty): a fill-reducing elimination
// order of the blocks (SESyncProblem::vertex_ordering() mapped to rotation
// blocks; used only if it holds every free block), expanded to the free
// blocks' entries, instead of CHOLMOD's own analysis (on a 10^5-pose city that
// analysis, AMD then METIS on the dn scalar unknowns, took 2.0 s of the chordal
// stage's 3.7 s). The factorization and solves use up to `num_threads`
// threads (the same results for every count). Returns false if the reduced
// Laplacian cannot be factorized.
bool ChordalRotationsFromLaplacian(
    const SparseMatrix& L, int d, Eigen::MatrixXd* R,
    std::vector<int>* component = nullptr,
    const std::vector<int>* block_ordering = nullptr, int num_threads = 1);

// The chordal rotations of the problem (d x dn, n = num_rotations()). The
// rotation graph may be disconnected where the whole problem is not: the
// world block R_w with position priors only, poses tied to each other only
// through landmarks. Each component is then estimated on its own and the
// components are rotated into place by minimizing F over one rotation per
// component (components c = 1..k-1, component 0 fixed): F(G) =
// tr(G A G^T) with A = C Q C^T (dk x dk; C stacks the components' chordal
// rotations as row blocks: one product with Q), in which the terms G_c A_cc
// G_c^T are constant, so block-coordinate descent over the G_c is a
// sequence of Procrustes problems (exact in one step for k = 2, the world
// block against the poses). With more than 64 components they are left as
// estimated. Returns false if a factorization failed.
bool ChordalRotations(const SESyncProblem& problem, Eigen::MatrixXd* R);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_CHORDAL_H_
