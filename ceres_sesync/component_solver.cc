#include "ceres_sesync/component_solver.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>

namespace ceres_sesync {

std::vector<PoseGraphComponent> SplitIntoComponents(const PoseGraph& graph) {
  std::vector<int> label;
  const int k = ConnectedComponents(graph, &label);
  std::vector<PoseGraphComponent> parts(k);
  std::vector<int> local(graph.num_poses);
  for (int v = 0; v < graph.num_poses; ++v) {
    PoseGraphComponent& c = parts[label[v]];
    local[v] = static_cast<int>(c.poses.size());
    c.poses.push_back(v);
    c.graph.dimension = graph.dimension;
    const int64_t id = v < static_cast<int>(graph.vertex_ids.size())
                           ? graph.vertex_ids[v]
                           : static_cast<int64_t>(v);
    c.graph.vertex_ids.push_back(id);
    c.graph.index_of_vertex_id.emplace(id, local[v]);
    ++c.graph.num_poses;
    if (static_cast<int>(graph.initial_poses.size()) == graph.num_poses) {
      c.graph.initial_poses.push_back(graph.initial_poses[v]);
    }
    if (v == graph.fixed_pose) c.graph.fixed_pose = local[v];
  }
  for (int e = 0; e < static_cast<int>(graph.measurements.size()); ++e) {
    const RelativePoseMeasurement& m = graph.measurements[e];
    if (m.i < 0 || m.j < 0 || m.i >= graph.num_poses ||
        m.j >= graph.num_poses) {
      continue;
    }
    PoseGraphComponent& c = parts[label[m.i]];
    c.measurements.push_back(e);
    RelativePoseMeasurement copy = m;
    copy.i = local[m.i];
    copy.j = local[m.j];
    c.graph.measurements.push_back(std::move(copy));
  }
  return parts;
}

Poses SolveByComponent(const PoseGraph& graph, const SolverOptions& options,
                       ComponentsSummary* summary) {
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                         start)
        .count();
  };
  ComponentsSummary& s = *summary;
  s = ComponentsSummary();
  s.dimension = graph.dimension;
  s.num_poses = graph.num_poses;
  s.num_measurements = static_cast<int>(graph.measurements.size());
  ValidationOptions validation;
  validation.require_connected = false;
  if (!ValidatePoseGraph(graph, validation, &s.message)) {
    s.status = SolverSummary::Status::kInvalidInput;
    return {};
  }
  if (graph.has_landmarks_or_priors()) {
    // SplitIntoComponents carries poses and measurements only: refuse
    // rather than drop the landmark and prior terms.
    s.status = SolverSummary::Status::kInvalidInput;
    s.message =
        "solving by component does not support landmarks and priors; solve "
        "a connected graph with them as a whole";
    return {};
  }
  std::vector<PoseGraphComponent> parts = SplitIntoComponents(graph);
  const int k = static_cast<int>(parts.size());
  Poses poses(graph.num_poses);
  s.status = SolverSummary::Status::kCertifiedOptimum;
  bool all_exact_zero = true;  // Every component's relative bound is 0.
  for (int c = 0; c < k; ++c) {
    PoseGraphComponent& part = parts[c];
    SolverOptions component_options = options;
    if (options.max_time_s > 0) {
      component_options.max_time_s =
          std::max(1e-3, options.max_time_s - elapsed());
    }
    if (options.progress) {
      component_options.progress = [&options, c, k](const SolverProgress& p) {
        SolverProgress q = p;
        q.component = c;
        q.num_components = k;
        options.progress(q);
      };
    }
    ComponentsSummary::Component result;
    const Poses x = Solve(part.graph, component_options, &result.summary);
    if (result.summary.status == SolverSummary::Status::kInvalidInput) {
      // Cannot happen for a validated graph, but never return partial poses.
      s.status = SolverSummary::Status::kInvalidInput;
      s.message =
          "component " + std::to_string(c) + ": " + result.summary.message;
      s.components.clear();
      return {};
    }
    for (size_t v = 0; v < part.poses.size(); ++v) {
      poses[part.poses[v]] = x[v];
    }
    result.poses = std::move(part.poses);
    result.num_measurements = static_cast<int>(part.measurements.size());
    const int gauge = part.graph.fixed_pose >= 0 ? part.graph.fixed_pose : 0;
    result.gauge_vertex_id = part.graph.vertex_ids[gauge];
    const SolverSummary& r = result.summary;
    s.objective += r.objective;
    s.lower_bound += r.lower_bound;
    all_exact_zero = all_exact_zero && r.relative_suboptimality_bound == 0;
    if (s.certified() && !r.certified()) s.status = r.status;
    s.components.push_back(std::move(result));
  }
  s.suboptimality_bound = std::max(0.0, s.objective - s.lower_bound);
  s.relative_suboptimality_bound =
      s.lower_bound > 0 ? s.suboptimality_bound / s.lower_bound
      : all_exact_zero  ? 0
                        : std::numeric_limits<double>::infinity();
  s.total_time_s = elapsed();
  return poses;
}

std::string ComponentsSummary::StatusString() const {
  SolverSummary s;
  s.status = status;
  return s.StatusString();
}

std::string ComponentsSummary::BriefReport() const {
  char buf[512];
  if (status == SolverSummary::Status::kInvalidInput) {
    std::snprintf(buf, sizeof(buf), "SE-Sync by component: INVALID_INPUT: %s",
                  message.c_str());
    return buf;
  }
  int certified_components = 0;
  for (const Component& c : components) {
    certified_components += c.summary.certified();
  }
  std::snprintf(buf, sizeof(buf),
                "SE-Sync by component: %s, %d of %d components certified, "
                "F(x) = %.10g, lower bound %.10g, relative suboptimality <= "
                "%.2e, %.3f s",
                StatusString().c_str(), certified_components,
                static_cast<int>(components.size()), objective, lower_bound,
                relative_suboptimality_bound, total_time_s);
  return buf;
}

std::string ComponentsSummary::FullReport() const {
  std::string out;
  char buf[512];
  auto line = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof(buf), format, args...);
    out += buf;
  };
  out += "\nSE-Sync Report by Connected Component\n";
  out += "-------------------------------------\n";
  line("%-34s %d\n", "Dimension", dimension);
  line("%-34s %d\n", "Poses", num_poses);
  line("%-34s %d\n", "Measurements", num_measurements);
  if (status == SolverSummary::Status::kInvalidInput) {
    line("%-34s %s\n", "Error", message.c_str());
    return out;
  }
  line("%-34s %d\n", "Connected components",
       static_cast<int>(components.size()));
  out += "\n";
  line("  %5s %7s %7s %12s %4s %6s %16s %16s %10s %8s %s\n", "comp", "poses",
       "edges", "gauge vertex", "rank", "iters", "F(x)", "lower bound",
       "rel. bound", "time [s]", "status");
  for (size_t c = 0; c < components.size(); ++c) {
    const Component& k = components[c];
    const SolverSummary& s = k.summary;
    line("  %5d %7d %7d %12lld %4d %6d %16.10g %16.10g %10.3e %8.3f %s\n",
         static_cast<int>(c), static_cast<int>(k.poses.size()),
         k.num_measurements, static_cast<long long>(k.gauge_vertex_id),
         s.final_rank, s.iterations, s.objective, s.lower_bound,
         s.relative_suboptimality_bound, s.total_time_s,
         s.StatusString().c_str());
  }
  out += "\nSolution (sums over the components)\n";
  line("%-34s %.12g\n", "Objective F(x)", objective);
  line("%-34s %.12g\n", "Lower bound", lower_bound);
  line("%-34s %.3e\n", "Suboptimality bound", suboptimality_bound);
  line("%-34s %.3e\n", "Relative suboptimality bound",
       relative_suboptimality_bound);
  line("%-34s %.4f\n", "Total time (s)", total_time_s);
  line("\n%-34s %s\n", "Status", StatusString().c_str());
  return out;
}

}  // namespace ceres_sesync
