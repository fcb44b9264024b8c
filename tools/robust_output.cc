#include "tools/robust_output.h"

#include <cstdio>

#include "ceres_sesync/internal/file_util.h"

namespace ceres_sesync::tools {

bool ParseKnownInliers(const std::string& name,
                       RobustSolverOptions::KnownInliers* known_inliers) {
  if (name == "odometry") {
    *known_inliers = RobustSolverOptions::KnownInliers::kOdometry;
  } else if (name == "none") {
    *known_inliers = RobustSolverOptions::KnownInliers::kNone;
  } else {
    return false;
  }
  return true;
}

void AddRobustJson(const RobustSolverSummary& summary,
                   internal::JsonWriter* json) {
  json->Bool("robust", true);
  json->String("robust_status", summary.StatusString());
  if (!summary.message.empty()) json->String("robust_message", summary.message);
  json->Number("inlier_threshold", summary.inlier_threshold);
  json->Int("gnc_iterations", summary.iterations);
  json->Int("consistency_rounds", summary.consistency_rounds);
  json->Int("readmissions", summary.readmissions);
  json->Int("removals", summary.removals);
  json->Int("num_inliers", summary.num_inliers);
  json->Int("num_outliers", summary.num_outliers);
  json->BeginArray("outlier_edges");
  for (int k : summary.outlier_edges) json->Int(k);
  json->EndArray();
  if (summary.num_landmark_measurements > 0 || summary.num_priors > 0) {
    json->BeginArray("outlier_landmark_measurements");
    for (int k : summary.outlier_landmark_measurements) json->Int(k);
    json->EndArray();
    json->BeginArray("outlier_priors");
    for (int k : summary.outlier_priors) json->Int(k);
    json->EndArray();
  }
  json->BeginArray("edges");
  for (const RobustSolverSummary::Edge& e : summary.edges) {
    json->BeginObject();
    json->String("kind", e.KindString());
    json->Int("index", e.index);
    json->Number("weight", e.weight);
    json->Bool("inlier", e.inlier);
    json->Bool("known_inlier", e.known_inlier);
    json->Number("rotation_residual_deg", e.rotation_residual_deg);
    json->Number("translation_residual", e.translation_residual);
    json->Number("cost", e.cost);
    json->Number("threshold", e.threshold);
    json->EndObject();
  }
  json->EndArray();
}

bool WriteEdgeReport(const std::string& path,
                     const RobustSolverSummary& summary, std::string* error) {
  std::string csv =
      "edge,vertex_i,vertex_j,weight,inlier,known_inlier,"
      "rotation_residual_deg,translation_residual,cost,kind,index,threshold\n";
  char line[320];
  for (size_t k = 0; k < summary.edges.size(); ++k) {
    const RobustSolverSummary::Edge& e = summary.edges[k];
    std::snprintf(line, sizeof(line),
                  "%zu,%lld,%lld,%.17g,%d,%d,%.17g,%.17g,%.17g,%s,%d,%.17g\n",
                  k, static_cast<long long>(e.vertex_i),
                  static_cast<long long>(e.vertex_j), e.weight,
                  e.inlier ? 1 : 0, e.known_inlier ? 1 : 0,
                  e.rotation_residual_deg, e.translation_residual, e.cost,
                  e.KindString(), e.index, e.threshold);
    csv += line;
  }
  return internal::WriteFileAtomically(path, csv, error);
}

}  // namespace ceres_sesync::tools
