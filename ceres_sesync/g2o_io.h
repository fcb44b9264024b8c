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
//
// The information matrices (upper triangle, row by row; for SE3 in the order
// x y z, then rotation) become the isotropic precisions of the SE-Sync model
// (Rosen et al., IJRR 2019) following the reference implementation:
//
//   2D: tau = 2 / trace(inverse(I_tt)),   kappa = I33;
//   3D: tau = 3 / trace(inverse(I_tt)),   kappa = 3 / (2 trace(inverse(I_RR))).
//
// Vertex ids are arbitrary non-negative integers (sparse ids are fine). The
// dense pose order is the order of the VERTEX lines if the file has any, else
// the order of first appearance in the edges. Quaternions within 1e-2 of unit
// length are normalized; others are an error.
//
// The reader rejects, with a message "PATH:LINE: what is wrong": malformed,
// short or over-long lines, non-numeric tokens, NaN/Inf, bad quaternions,
// information matrices whose translational or rotational diagonal block is not
// positive definite (the full matrix may be indefinite: its cross terms are
// not used; see G2oReadSummary), mixed 2D/3D tags,
// self-loops, unsupported tags (unless skipped by option; the legacy 3D TORO
// tags VERTEX3/EDGE3 are always rejected), edges to vertices without a VERTEX
// line when the file has VERTEX lines, duplicate VERTEX ids, files without
// edges, and disconnected measurement graphs (unless allowed by option). The
// result always passes ValidatePoseGraph() (without the connectivity check
// when G2oReadOptions::allow_disconnected is set).
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
  // Unsupported tags (landmarks and priors such as VERTEX_XY, EDGE_SE2_XY,
  // EDGE_SE3_PRIOR, and any unknown tag) are an error by default. If true,
  // such lines are skipped instead, counted in G2oReadSummary and reported
  // with a glog warning. The legacy 3D TORO tags VERTEX3/EDGE3 are rejected
  // either way.
  bool skip_unsupported_tags = false;
  // A disconnected measurement graph (including VERTEX lines without edges)
  // is an error by default. If true it is accepted; the result then passes
  // ValidatePoseGraph(graph, error, /*require_connected=*/false) and can be
  // solved per connected component (component_solver.h).
  bool allow_disconnected = false;
};

struct G2oReadSummary {
  // Number of poses (distinct vertex ids) in the graph.
  int num_vertices = 0;
  // Number of measurements (edge lines), parallel edges included.
  int num_edges = 0;
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
  // accepted; the cross terms are ignored as for every edge.
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

// Writes the whole graph to `path`: VERTEX lines for `poses` if it is not
// empty (one per pose, with the original vertex ids, in dense order), one
// EDGE line per measurement with an isotropic information matrix that
// reproduces kappa and tau under the reading convention above (2D: I_tt =
// tau I, I33 = kappa; 3D: I_tt = tau I, I_RR = 2 kappa I), and a FIX line if
// graph.fixed_pose >= 0. Numbers are written in the shortest form that reads
// back to the same double. `poses` must be empty or hold one pose of the
// graph's dimension per vertex. Returns false with a message on failure.
bool WriteG2oFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error);

// Writes only VERTEX lines (original ids, dense order) for `poses`, one per
// pose of `graph`. Returns false with a message on failure.
bool WriteG2oPoses(const std::string& path, const PoseGraph& graph,
                   const Poses& poses, std::string* error);

// Reads the VERTEX lines of a poses file (for instance an optimizer's output)
// and matches them by id to the poses of `graph`; `poses` gets one pose per
// dense index. EDGE and FIX lines in that file are ignored; any other tag is
// an error. Returns false with a message "PATH:LINE: ..." for unknown or
// duplicate ids, a dimension that differs from the graph's, malformed lines,
// NaN/Inf, bad quaternions, and (naming one missing id) poses of `graph` that
// the file does not contain.
bool ReadG2oPoses(const std::string& path, const PoseGraph& graph, Poses* poses,
                  std::string* error);

// Writes a TUM trajectory: one line "timestamp tx ty tz qx qy qz qw" per pose
// in dense order, with timestamp = vertex id. 2D poses are written with z = 0
// and the quaternion of the rotation by theta about z. Returns false with a
// message on failure.
bool WriteTumFile(const std::string& path, const PoseGraph& graph,
                  const Poses& poses, std::string* error);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_G2O_IO_H_
