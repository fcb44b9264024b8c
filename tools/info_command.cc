// `ceres_sesync info GRAPH.g2o [--json PATH] [--skip_unsupported_tags]`:
// reads a pose graph and describes it (dimension, sizes, connectivity, the
// range of the precisions kappa and tau, landmarks and their measurements'
// precisions nu, priors by kind, initial guess, FIX, skipped lines).

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/json_writer.h"
#include "ceres_sesync/pose_graph.h"
#include "tools/commands.h"

DEFINE_bool(skip_unsupported_tags, false,
            "Skip (and count) g2o lines with tags ceres_sesync does not "
            "support (e.g. bearing-only or projection edges) instead of "
            "rejecting the file.");

namespace ceres_sesync::tools {
namespace {

struct Range {
  double min = 0, median = 0, max = 0;
};

Range RangeOf(std::vector<double> values) {
  Range range;
  if (values.empty()) return range;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  range.min = values.front();
  range.max = values.back();
  range.median =
      n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  return range;
}

void AddRange(const char* key, const Range& range, internal::JsonWriter* json) {
  json->BeginObject(key);
  json->Number("min", range.min);
  json->Number("median", range.median);
  json->Number("max", range.max);
  json->EndObject();
}

}  // namespace

int RunInfo(const Args& args) {
  if (args.size() != 1) {
    std::fputs(
        "usage: ceres_sesync info GRAPH.g2o [--json PATH] "
        "[--skip_unsupported_tags]\n",
        stderr);
    return kUsageOrInputError;
  }
  const std::string& path = args[0];
  G2oReadOptions options;
  options.skip_unsupported_tags = FLAGS_skip_unsupported_tags;
  PoseGraph graph;
  G2oReadSummary summary;
  std::string error;
  const auto start = std::chrono::steady_clock::now();
  if (!ReadG2oFile(path, options, &graph, &error, &summary)) {
    std::fprintf(stderr, "ceres_sesync info: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  const double read_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
          .count();

  std::vector<double> kappas, taus;
  for (const auto& m : graph.measurements) {
    kappas.push_back(m.kappa);
    taus.push_back(m.tau);
  }
  const Range kappa = RangeOf(kappas);
  const Range tau = RangeOf(taus);
  std::vector<double> nus;
  for (const auto& m : graph.landmark_measurements) nus.push_back(m.nu);
  const Range nu = RangeOf(nus);
  int position_priors = 0, rotation_priors = 0, pose_priors = 0;
  for (const auto& p : graph.priors) {
    if (p.has_position() && p.has_rotation()) {
      ++pose_priors;
    } else if (p.has_position()) {
      ++position_priors;
    } else {
      ++rotation_priors;
    }
  }
  const bool has_initial_landmarks = !graph.initial_landmarks.empty();
  const int num_components = ConnectedComponents(graph, nullptr);
  const bool has_initial_guess = !graph.initial_poses.empty();

  std::printf("file:                      %s\n", path.c_str());
  std::printf("dimension:                 %d\n", graph.dimension);
  std::printf("poses:                     %d\n", graph.num_poses);
  std::printf("edges:                     %d\n", summary.num_edges);
  std::printf("connected components:      %d\n", num_components);
  std::printf("kappa min / median / max:  %.6g / %.6g / %.6g\n", kappa.min,
              kappa.median, kappa.max);
  std::printf("tau min / median / max:    %.6g / %.6g / %.6g\n", tau.min,
              tau.median, tau.max);
  std::printf("landmarks:                 %d\n", graph.num_landmarks);
  std::printf("landmark measurements:     %d\n", summary.num_landmark_edges);
  if (!nus.empty()) {
    std::printf("nu min / median / max:     %.6g / %.6g / %.6g\n", nu.min,
                nu.median, nu.max);
  }
  std::printf(
      "priors:                    %d (position %d, rotation %d, "
      "pose %d)\n",
      summary.num_priors, position_priors, rotation_priors, pose_priors);
  std::printf("initial guess:             %s\n",
              has_initial_guess ? "yes (VERTEX lines)" : "no");
  if (graph.num_landmarks > 0) {
    std::printf("landmark initial guess:    %s\n",
                has_initial_landmarks ? "yes (VERTEX lines)" : "no");
  }
  if (graph.fixed_pose >= 0) {
    std::printf("fixed vertex (FIX):        %lld\n",
                static_cast<long long>(graph.vertex_ids[graph.fixed_pose]));
  } else {
    std::printf("fixed vertex (FIX):        none\n");
  }
  std::printf("skipped lines:             %d\n", summary.num_skipped_lines);
  for (const auto& [tag, count] : summary.skipped_tags) {
    std::printf("  %-24s %d\n", tag.c_str(), count);
  }
  std::printf("normalized quaternions:    %d\n",
              summary.num_normalized_quaternions);
  std::printf("indefinite information:    %d (cross terms ignored)\n",
              summary.num_indefinite_information);
  std::printf("read time:                 %.3f s\n", read_seconds);

  if (!FLAGS_json.empty()) {
    internal::JsonWriter json;
    json.String("command", "info");
    json.String("file", path);
    json.Int("dimension", graph.dimension);
    json.Int("num_poses", graph.num_poses);
    json.Int("num_edges", summary.num_edges);
    json.Int("num_components", num_components);
    AddRange("kappa", kappa, &json);
    AddRange("tau", tau, &json);
    json.Int("num_landmarks", graph.num_landmarks);
    json.Int("num_landmark_measurements", summary.num_landmark_edges);
    if (!nus.empty()) {
      AddRange("nu", nu, &json);
    } else {
      json.Null("nu");
    }
    json.Int("num_priors", summary.num_priors);
    json.BeginObject("priors");
    json.Int("position", position_priors);
    json.Int("rotation", rotation_priors);
    json.Int("pose", pose_priors);
    json.EndObject();
    json.Bool("has_initial_guess", has_initial_guess);
    json.Bool("has_initial_landmarks", has_initial_landmarks);
    json.Bool("has_fix", summary.has_fix);
    if (graph.fixed_pose >= 0) {
      json.Int("fixed_vertex_id", graph.vertex_ids[graph.fixed_pose]);
    } else {
      json.Null("fixed_vertex_id");
    }
    json.Int("num_skipped_lines", summary.num_skipped_lines);
    json.BeginObject("skipped_tags");
    for (const auto& [tag, count] : summary.skipped_tags) json.Int(tag, count);
    json.EndObject();
    json.Int("num_normalized_quaternions", summary.num_normalized_quaternions);
    json.Int("num_indefinite_information", summary.num_indefinite_information);
    json.Number("read_seconds", read_seconds);
    if (!json.WriteToFile(FLAGS_json, &error)) {
      std::fprintf(stderr, "ceres_sesync info: cannot write --json: %s\n",
                   error.c_str());
      return kUsageOrInputError;
    }
  }
  return kSuccess;
}

}  // namespace ceres_sesync::tools
