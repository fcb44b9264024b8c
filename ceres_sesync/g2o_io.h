// Reading and writing pose graphs in the g2o text format (plus TUM
// trajectories for the results).
//
// Supported lines (one record per line; blank lines and lines starting with
// '#' are ignored, a blank line carries no edge):
//
//   VERTEX_SE2 id x y theta
//   VERTEX_SE3:QUAT id x y z qx qy qz qw
//   EDGE_SE2 i j dx dy dtheta I11 I12 I13 I22 I23 I33
//   EDGE_SE3:QUAT i j dx dy dz qx qy qz qw I11 I12 ... I16 I22 ... I66
//   VERTEX2 id x y theta                                   (legacy TORO)
//   EDGE2 i j dx dy dtheta I11 I12 I22 I33 I13 I23         (legacy TORO)
//   FIX id
// point landmarks and priors (g2o's types_slam2d / types_slam3d):
//   VERTEX_XY id x y                                       (2D landmark)
//   EDGE_SE2_XY pose landmark x y I11 I12 I22
//   EDGE_PRIOR_SE2 pose x y theta I11 I12 I13 I22 I23 I33  (pose prior)
//   EDGE_PRIOR_SE2_XY pose x y I11 I12 I22                 (position prior)
//   VERTEX_TRACKXYZ id x y z                               (3D landmark)
//   PARAMS_SE3OFFSET param x y z qx qy qz qw               (sensor offset)
//   EDGE_SE3_TRACKXYZ pose landmark param x y z I11 I12 I13 I22 I23 I33
//   EDGE_SE3_PRIOR pose param x y z qx qy qz qw I11 .. I16 I22 .. I66
//   EDGE_SE3_XYZ_PRIOR pose param x y z I11 I12 I13 I22 I23 I33
//
// The formats and error conventions are g2o's own (checked against
// RainerKuemmerle/g2o: the tags registered in g2o/types/slam2d/types_slam2d.cpp
// and g2o/types/slam3d/types_slam3d.cpp; the read() and computeError() of
// edge_se2_pointxy, edge_se2_prior, edge_se2_xyprior, edge_se3_pointxyz,
// edge_se3_prior, edge_se3_xyzprior and parameter_se3_offset; and
// OptimizableGraph::load in g2o/core/optimizable_graph.cpp, which reads an
// edge's vertex ids and then the edge, whose read() begins with its
// parameter ids, and a parameter line as "TAG id data"):
//  - EDGE_SE2_XY: error x_pose^-1 p - z, so z is the landmark in the pose's
//    frame, as in the model (pose_graph.h).
//  - EDGE_SE3_TRACKXYZ: error (x_pose * offset)^-1 p - z with the offset of
//    parameter `param`; the offset is applied: the model's measurement is
//    t_off + R_off z (exact: nu = 3 / tr(I^-1) does not change under R_off).
//  - EDGE_PRIOR_SE2 / EDGE_SE3_PRIOR: error Z^-1 x_pose (3D: Z^-1 (x_pose *
//    offset)), translation in Z's frame; the information splits like an
//    edge's into tau (position) and kappa (rotation), see below. A block
//    that is exactly zero means no prior on that part (g2o's own
//    initialEstimate reads it so), which gives position-only and
//    rotation-only priors; both blocks zero is an error. EDGE_SE3_PRIOR
//    offsets without translation are applied (R~ = R_Z R_off^T); offsets
//    with a translation are rejected (file:line): they would couple the
//    position and the rotation of the prior, which the model has no term
//    for.
//  - EDGE_PRIOR_SE2_XY / EDGE_SE3_XYZ_PRIOR: error t_pose - z (g2o's
//    EDGE_SE3_XYZ_PRIOR does not use its offset, and neither does this
//    reader); nu = d / tr(I^-1).
//  - Parameter ids are non-negative integers; as in g2o, the
//    PARAMS_SE3OFFSET line must come before the edges that use it. 2D g2o
//    landmark types do not use parameters.
// Not supported (an error naming the line, or skipped with the option
// below): landmark priors and point-point edges (EDGE_PRIOR_XY,
// EDGE_POINTXY, EDGE_POINTXYZ, EDGE_POINTXYZ_PRIOR), bearing-only,
// calibration, offset and projection edges (EDGE_BEARING_SE2_XY,
// EDGE_SE2_XY_CALIB, EDGE_SE2_OFFSET, EDGE_SE2_POINTXY_OFFSET,
// EDGE_SE3_OFFSET, EDGE_PROJECT_*), PARAMS_SE2OFFSET and the other camera
// parameters, and any other tag.
//
// The information matrices (upper triangle, row by row; for SE3 in the order
// x y z, then rotation) become the isotropic precisions of the SE-Sync model
// (Rosen et al., IJRR 2019) following the reference implementation:
//
//   2D: tau = 2 / trace(inverse(I_tt)),   kappa = I33;
//   3D: tau = 3 / trace(inverse(I_tt)),   kappa = 3 / (2 trace(inverse(I_RR))),
//
// and a landmark measurement's (or position prior's) d x d matrix I gives
// nu = d / trace(inverse(I)), the translational convention.
//
// Vertex ids are arbitrary non-negative integers (sparse ids are fine);
// poses and landmarks share one id space, as in g2o. The dense pose order is
// the order of the pose VERTEX lines if the file has any, else the order of
// first appearance in the edges and priors; the dense landmark order is the
// order of the landmark VERTEX lines if the file has any, else the order of
// first appearance in the landmark edges. Quaternions within 1e-2 of unit
// length are normalized; others are an error.
//
// The reader rejects, with a message "PATH:LINE: what is wrong": malformed,
// short or over-long lines, non-numeric tokens, NaN/Inf, bad quaternions,
// information matrices whose translational or rotational diagonal block is not
// positive definite (the full matrix may be indefinite: its cross terms are
// not used; see G2oReadSummary; pose priors: each block positive definite or
// zero), mixed 2D/3D tags, self-loops, unsupported tags (unless skipped by
// option; the legacy 3D TORO tags VERTEX3/EDGE3 are always rejected), edges
// to vertices (landmarks) without a VERTEX line when the file has VERTEX
// lines for other poses (landmarks), duplicate VERTEX ids (also between a
// pose and a landmark), an id used both as a pose and as a landmark,
// landmarks that no edge observes, undefined or duplicate parameter ids,
// EDGE_SE3_PRIOR offsets with a translation, FIX together with priors (the
// priors fix the gauge), files without edges, and disconnected graphs
// (poses and landmarks; priors connect their poses through the world frame;
// the translational terms must be connected too, see
// TranslationalComponents in pose_graph.h), unless
// G2oReadOptions::allow_disconnected is set. The result always passes
// ValidatePoseGraph() (with require_connected = !allow_disconnected).
//
// Every writer replaces its output file atomically (temporary file + rename):
// on failure no partial file is left behind.

#ifndef CERES_SESYNC_G2O_IO_H_
#define CERES_SESYNC_G2O_IO_H_

#include <istream>
#include <map>
#include <string>

#include "ceres_sesync/pose_graph.h"

namespace ceres_sesync {

struct G2oReadOptions {
  // Unsupported tags (any tag not listed above, e.g. EDGE_BEARING_SE2_XY,
  // EDGE_POINTXYZ_PRIOR or EDGE_PROJECT_DEPTH) are an error by default. If
  // true, such lines are skipped instead, counted in G2oReadSummary and
  // reported with a glog warning. The legacy 3D TORO tags VERTEX3/EDGE3 are
  // rejected either way.
  bool skip_unsupported_tags = false;
  // A disconnected measurement graph (including VERTEX lines without edges)
  // is an error by default. If true it is accepted; the result then passes
  // ValidatePoseGraph with ValidationOptions::require_connected false and can
  // be solved per connected component (component_solver.h).
  bool allow_disconnected = false;
};

struct G2oReadSummary {
  // Number of poses (distinct vertex ids) in the graph.
  int num_vertices = 0;
  // Number of pose-pose measurements (edge lines), parallel edges included.
  int num_edges = 0;
  // Number of landmarks (distinct landmark ids).
  int num_landmarks = 0;
  // Number of pose-landmark measurements (EDGE_SE2_XY / EDGE_SE3_TRACKXYZ).
  int num_landmark_edges = 0;
  // Number of pose priors (EDGE_PRIOR_SE2, EDGE_PRIOR_SE2_XY,
  // EDGE_SE3_PRIOR, EDGE_SE3_XYZ_PRIOR lines).
  int num_priors = 0;
  // Number of PARAMS_SE3OFFSET lines.
  int num_offset_parameters = 0;
  // Number of lines skipped because of G2oReadOptions::skip_unsupported_tags.
  int num_skipped_lines = 0;
  // Skipped lines per tag.
  std::map<std::string, int> skipped_tags;
  // Number of quaternions whose length differed from 1 by more than 1e-12
  // and that were normalized.
  int num_normalized_quaternions = 0;
  // Number of edges whose full information matrix is not positive definite
  // although its translational and rotational blocks are (e.g. 5021 edges of
  // cubicle.g2o). Only those blocks enter kappa and tau, so such edges are
  // accepted; the cross terms are ignored as for every edge. Pose priors
  // with a zero block count here if their cross terms are not zero.
  int num_indefinite_information = 0;
  // Whether the file has a FIX line (see PoseGraph::fixed_pose).
  bool has_fix = false;
};

// Reads the g2o file at `path` into `graph` (which is overwritten). Returns
// false with a message "PATH:LINE: ..." in `error` (if not null) on any
// problem; `graph` is then unspecified. `summary` (if not null) describes what
// was read.
bool ReadG2oFile(const std::string& path, const G2oReadOptions& options,
                 PoseGraph* graph, std::string* error,
                 G2oReadSummary* summary = nullptr);

// As ReadG2oFile, reading from a stream; `name_for_messages` stands for the
// file name in error messages.
bool ReadG2o(std::istream& in, const std::string& name_for_messages,
             const G2oReadOptions& options, PoseGraph* graph,
             std::string* error, G2oReadSummary* summary = nullptr);

// The isotropic precisions of a symmetric information matrix in g2o's order
// (translation block first; 3 x 3 for d = 2, 6 x 6 for d = 3), with the
// SE-Sync reference convention that reproduces the paper's objective values:
//   d = 2: tau = 2 / tr(I_tt^-1), kappa = I_33;
//   d = 3: tau = 3 / tr(I_tt^-1), kappa = 3 / (2 tr(I_RR^-1)).
// Only the translation and rotation blocks enter; they must be positive
// definite (the full matrix need not be). Returns false with a message
// otherwise, or if the entries or the precisions are not finite.
bool IsotropicPrecisions(const Eigen::MatrixXd& information, double* kappa,
                         double* tau, std::string* error);

// The isotropic precision nu = d / tr(I^-1) of a positive definite d x d
// translational information matrix I (d = 2 or 3): the weight of a landmark
// measurement or a position prior. Returns false with a message if I is not
// positive definite or nu is not finite.
bool TranslationalPrecision(const Eigen::MatrixXd& information, double* nu,
                            std::string* error);

// Writes the whole graph to `path`: VERTEX lines for `poses` if it is not
// empty (one per pose, with the original vertex ids, in dense order), one
// EDGE line per measurement with an isotropic information matrix that
// reproduces kappa and tau under the reading convention above (2D: I_tt =
// tau I, I33 = kappa; 3D: I_tt = tau I, I_RR = 2 kappa I), and a FIX line if
// graph.fixed_pose >= 0. Numbers are written in the shortest form that reads
// back to the same double. `poses` must be empty or hold one pose of the
// graph's dimension per vertex. Returns false with a message on failure.
//
// Landmark measurements and priors are written too (EDGE_SE2_XY /
// EDGE_SE3_TRACKXYZ with I = nu I; position priors as EDGE_PRIOR_SE2_XY /
// EDGE_SE3_XYZ_PRIOR, the others as EDGE_PRIOR_SE2 / EDGE_SE3_PRIOR with a
// zero translational block for rotation-only priors); 3D files that need it
// start with "PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1" (the identity offset, used
// by every 3D landmark edge and prior). The five-argument form also writes
// VERTEX_XY / VERTEX_TRACKXYZ lines (original landmark ids, dense order) for
// `landmarks` if it is not empty (it must then hold one position per
// landmark); the four-argument form writes none.
bool WriteG2oFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error);
bool WriteG2oFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, const LandmarkPositions& landmarks,
                  std::string* error);

// Writes only VERTEX lines (original ids, dense order) for `poses`, one per
// pose of `graph`. Returns false with a message on failure.
bool WriteG2oPoses(const std::string& path, const PoseGraph& graph,
                   const Poses& poses, std::string* error);

// Writes the VERTEX lines of a solution: one per pose (as WriteG2oPoses),
// then one VERTEX_XY / VERTEX_TRACKXYZ line per landmark (original ids,
// dense order). `solution` must hold one pose per pose and one position per
// landmark of `graph`. Returns false with a message on failure.
bool WriteG2oSolution(const std::string& path, const PoseGraph& graph,
                      const Solution& solution, std::string* error);

// Reads the VERTEX lines of a poses file (for instance an optimizer's output)
// and matches them by id to the poses of `graph`; `poses` gets one pose per
// dense index. EDGE, prior, PARAMS_SE3OFFSET, FIX and landmark VERTEX lines
// in that file are ignored; any other tag is an error. Returns false with a
// message "PATH:LINE: ..." for unknown or duplicate ids, a dimension that
// differs from the graph's, malformed lines, NaN/Inf, bad quaternions, and
// (naming one missing id) poses of `graph` that the file does not contain.
bool ReadG2oPoses(const std::string& path, const PoseGraph& graph, Poses* poses,
                  std::string* error);

// As ReadG2oPoses, and also reads the landmark VERTEX lines (VERTEX_XY /
// VERTEX_TRACKXYZ) into solution->landmarks, matched by id to the landmarks
// of `graph`; every landmark of `graph` must have one (the message names a
// missing one), and a landmark id that `graph` does not have is an error.
bool ReadG2oSolution(const std::string& path, const PoseGraph& graph,
                     Solution* solution, std::string* error);

// Writes a TUM trajectory: one line "timestamp tx ty tz qx qy qz qw" per pose
// in dense order, with timestamp = vertex id. 2D poses are written with z = 0
// and the quaternion of the rotation by theta about z. Returns false with a
// message on failure.
bool WriteTumFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_G2O_IO_H_
