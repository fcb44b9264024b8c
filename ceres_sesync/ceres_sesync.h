// Umbrella header: everything a user of ceres_sesync needs, in one include.
//
//   #include "ceres_sesync/ceres_sesync.h"
//
// The public API (each header documents its part):
//
//   pose_graph.h              The data model: PoseGraph,
//                             RelativePoseMeasurement, LandmarkMeasurement,
//                             PosePrior, Pose/Poses, Solution,
//                             EvaluateObjective (eq. 12 + landmark and prior
//                             terms), ValidatePoseGraph.
//   g2o_io.h                  Reading/writing g2o files, writing TUM
//                             trajectories.
//   sesync_solver.h           Solve(): SE-Sync, certifiably correct pose-graph
//                             optimization (SolverOptions, SolverSummary).
//   robust_solver.h           SolveRobust(): outlier-robust GNC with truncated
//                             least squares around SE-Sync, per-edge
//                             verdicts, the accepted edges' problem
//                             certified.
//   certification.h           Certify(): a global-optimality certificate or a
//                             suboptimality bound for ANY solution, e.g. one
//                             computed by Ceres.
//   component_solver.h        SolveByComponent(): a disconnected graph solved
//                             per connected component, each in its own gauge.
//   pose_conversions.h        Conversions to/from Eigen isometries,
//                             quaternions, (x, y, yaw), and the pose maps and
//                             constraint vectors of Ceres's examples/slam.
//   ceres_baseline.h          The same objective minimized by Ceres
//                             (SolveWithCeres, BuildCeresProblem), and the
//                             odometry initialization.
//   chordal_initialization.h  The chordal rotation initialization.
//   cube_generator.h          The synthetic cube benchmark of the paper.
//   city_generator.h          Large synthetic maps: a Manhattan-style walk
//                             with loop closures on revisits.
//   landmark_generator.h      A synthetic landmark-SLAM benchmark (Manhattan
//                             walk, random landmarks, GPS / start priors).
//   outlier_generator.h       Wrong loop closures (random or clustered) for
//                             outlier experiments.
//   langevin.h                The isotropic Langevin / von Mises noise
//                             samplers used by the generators.
//   stiefel_manifold.h        St(d, r) and St(d, r)^n: free functions and
//                             ceres::Manifold classes.
//   riemannian_trust_region.h The Riemannian trust-region solver used by
//                             SE-Sync (usable for any matrix-manifold cost).
//
// Implementation details live in ceres_sesync/internal/ and are not part of
// the API (not included here).

#ifndef CERES_SESYNC_CERES_SESYNC_H_
#define CERES_SESYNC_CERES_SESYNC_H_

#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/component_solver.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/outlier_generator.h"
#include "ceres_sesync/pose_conversions.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/process_memory.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/robust_solver.h"
#include "ceres_sesync/sesync_solver.h"
#include "ceres_sesync/stiefel_manifold.h"

#endif  // CERES_SESYNC_CERES_SESYNC_H_
