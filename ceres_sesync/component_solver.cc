#include "ceres_sesync/component_solver.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

namespace ceres_sesync {

std::vector<PoseGraphComponent> SplitIntoComponents(const PoseGraph& graph) {
  std::vector<int> label;  // Poses 0..n-1, then landmarks.
  const int k = ConnectedComponents(graph, &label);
  const int n = graph.num_poses;
  std::vector<PoseGraphComponent> parts(k);
  std::vector<int> local(n);
  for (int v = 0; v < n; ++v) {
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
    if (static_cast<int>(graph.initial_poses.size()) == n) {
      c.graph.initial_poses.push_back(graph.initial_poses[v]);
    }
    if (v == graph.fixed_pose) c.graph.fixed_pose = local[v];
  }
  const int L = static_cast<int>(label.size()) - n;
  std::vector<int> local_landmark(L);
  for (int l = 0; l < L; ++l) {
    PoseGraphComponent& c = parts[label[n + l]];
    c.landmarks.push_back(l);
    const int64_t id = l < static_cast<int>(graph.landmark_ids.size())
                           ? graph.landmark_ids[l]
                           : static_cast<int64_t>(l);
    local_landmark[l] = c.graph.num_landmarks++;
    c.graph.landmark_ids.push_back(id);
    c.graph.index_of_landmark_id.emplace(id, local_landmark[l]);
    if (static_cast<int>(graph.initial_landmarks.size()) == L) {
      c.graph.initial_landmarks.push_back(graph.initial_landmarks[l]);
    }
  }
  auto is_pose = [n](int i) { return i >= 0 && i < n; };
  for (int e = 0; e < static_cast<int>(graph.measurements.size()); ++e) {
    const RelativePoseMeasurement& m = graph.measurements[e];
    if (!is_pose(m.i) || !is_pose(m.j)) continue;
    PoseGraphComponent& c = parts[label[m.i]];
    c.measurements.push_back(e);
    RelativePoseMeasurement copy = m;
    copy.i = local[m.i];
    copy.j = local[m.j];
    c.graph.measurements.push_back(std::move(copy));
  }
  for (int q = 0; q < static_cast<int>(graph.landmark_measurements.size());
       ++q) {
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    if (!is_pose(o.i) || o.l < 0 || o.l >= L) continue;
    PoseGraphComponent& c = parts[label[o.i]];
    c.landmark_measurements.push_back(q);
    LandmarkMeasurement copy = o;
    copy.i = local[o.i];
    copy.l = local_landmark[o.l];
    c.graph.landmark_measurements.push_back(std::move(copy));
  }
  for (int q = 0; q < static_cast<int>(graph.priors.size()); ++q) {
    const PosePrior& p = graph.priors[q];
    if (!is_pose(p.i)) continue;
    PoseGraphComponent& c = parts[label[p.i]];
    c.priors.push_back(q);
    PosePrior copy = p;
    copy.i = local[p.i];
    c.graph.priors.push_back(std::move(copy));
  }
  return parts;
}

Poses SolveByComponent(const PoseGraph& graph, const SolverOptions& options,
                       ComponentsSummary* summary) {
  Solution solution;
  SolveByComponent(graph, options, &solution, summary);
  return std::move(solution.poses);
}

void SolveByComponent(const PoseGraph& graph, const SolverOptions& options,
                      Solution* solution, ComponentsSummary* summary) {
  *solution = Solution();
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
  s.num_landmarks = graph.num_landmarks;
  s.num_landmark_measurements =
      static_cast<int>(graph.landmark_measurements.size());
  s.num_priors = static_cast<int>(graph.priors.size());
  ValidationOptions validation;
  validation.require_connected = false;
  if (!ValidatePoseGraph(graph, validation, &s.message)) {
    s.status = SolverSummary::Status::kInvalidInput;
    return;
  }
  std::vector<PoseGraphComponent> parts = SplitIntoComponents(graph);
  const int k = static_cast<int>(parts.size());
  Solution whole;
  whole.poses.resize(graph.num_poses);
  whole.landmarks.resize(graph.num_landmarks);
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
    Solution x;
    Solve(part.graph, component_options, &x, &result.summary);
    if (result.summary.status == SolverSummary::Status::kInvalidInput) {
      // A component the whole graph's validation does not see (a component
      // whose translations are not connected), but never partial poses.
      s.status = SolverSummary::Status::kInvalidInput;
      s.message =
          "component " + std::to_string(c) + ": " + result.summary.message;
      s.components.clear();
      return;
    }
    for (size_t v = 0; v < part.poses.size(); ++v) {
      whole.poses[part.poses[v]] = x.poses[v];
    }
    for (size_t l = 0; l < part.landmarks.size(); ++l) {
      whole.landmarks[part.landmarks[l]] = x.landmarks[l];
    }
    result.poses = std::move(part.poses);
    result.landmarks = std::move(part.landmarks);
    result.num_measurements = static_cast<int>(part.measurements.size());
    result.num_landmark_measurements =
        static_cast<int>(part.landmark_measurements.size());
    result.num_priors = static_cast<int>(part.priors.size());
    const int gauge = part.graph.fixed_pose >= 0 ? part.graph.fixed_pose : 0;
    result.gauge_vertex_id =
        part.priors.empty() ? part.graph.vertex_ids[gauge] : -1;
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
  *solution = std::move(whole);
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
  const bool extended =
      num_landmarks > 0 || num_landmark_measurements > 0 || num_priors > 0;
  if (extended) {
    line("%-34s %d\n", "Landmarks", num_landmarks);
    line("%-34s %d\n", "Landmark measurements", num_landmark_measurements);
    line("%-34s %d\n", "Priors", num_priors);
  }
  if (status == SolverSummary::Status::kInvalidInput) {
    line("%-34s %s\n", "Error", message.c_str());
    return out;
  }
  line("%-34s %d\n", "Connected components",
       static_cast<int>(components.size()));
  out += "\n";
  line("  %5s %7s %7s", "comp", "poses", "edges");
  if (extended) line(" %9s %9s %6s", "landmarks", "lm. obs.", "priors");
  line(" %12s %4s %6s %16s %16s %10s %8s %s\n", "gauge vertex", "rank", "iters",
       "F(x)", "lower bound", "rel. bound", "time [s]", "status");
  for (size_t c = 0; c < components.size(); ++c) {
    const Component& k = components[c];
    const SolverSummary& s = k.summary;
    line("  %5d %7d %7d", static_cast<int>(c), static_cast<int>(k.poses.size()),
         k.num_measurements);
    if (extended) {
      line(" %9d %9d %6d", static_cast<int>(k.landmarks.size()),
           k.num_landmark_measurements, k.num_priors);
    }
    const std::string gauge =
        k.num_priors > 0 ? "world" : std::to_string(k.gauge_vertex_id);
    line(" %12s %4d %6d %16.10g %16.10g %10.3e %8.3f %s\n", gauge.c_str(),
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
