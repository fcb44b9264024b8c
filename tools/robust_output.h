// The robust solve's outputs for `ceres_sesync solve --robust`: the
// --known_inliers flag, the JSON keys and the per-edge CSV report.

#ifndef CERES_SESYNC_TOOLS_ROBUST_OUTPUT_H_
#define CERES_SESYNC_TOOLS_ROBUST_OUTPUT_H_

#include <string>

#include "ceres_sesync/internal/json_writer.h"
#include "ceres_sesync/robust_solver.h"

namespace ceres_sesync::tools {

// "odometry" or "none"; false for anything else.
bool ParseKnownInliers(const std::string& name,
                       RobustSolverOptions::KnownInliers* known_inliers);

// Adds to the solve's JSON: "robust": true, "robust_status",
// "inlier_threshold", "gnc_iterations", "consistency_rounds", "readmissions",
// "removals", "num_inliers", "num_outliers", "outlier_edges" (0-based indices
// of the rejected measurements in the order of the file's pose-pose EDGE
// lines), with landmarks or priors "outlier_landmark_measurements" and
// "outlier_priors" (0-based, in the order of the file's landmark and prior
// EDGE lines), and "edges" (one object per term, measurements first:
// kind (measurement|landmark|prior), index, weight, inlier, known_inlier,
// rotation_residual_deg, translation_residual, cost, threshold).
void AddRobustJson(const RobustSolverSummary& summary,
                   internal::JsonWriter* json);

// Writes the per-edge verdicts as CSV (header line, then one line per term:
// the measurements in file order, then the landmark measurements, then the
// priors): edge,vertex_i,vertex_j,weight,inlier,known_inlier,
// rotation_residual_deg,translation_residual,cost,kind,index,threshold
// (edge: the line's term number; index: within its kind). Atomic.
bool WriteEdgeReport(const std::string& path,
                     const RobustSolverSummary& summary, std::string* error);

}  // namespace ceres_sesync::tools

#endif  // CERES_SESYNC_TOOLS_ROBUST_OUTPUT_H_
