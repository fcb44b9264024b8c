// Solving a disconnected pose graph one connected component at a time.
//
//   ceres_sesync::G2oReadOptions read_options;
//   read_options.allow_disconnected = true;
//   ceres_sesync::ReadG2oFile(path, read_options, &graph, &error);
//   ceres_sesync::ComponentsSummary summary;
//   ceres_sesync::Poses poses =
//       ceres_sesync::SolveByComponent(graph, options, &summary);
//   std::cout << summary.FullReport();
//
// A component is a maximal set of poses and landmarks linked by relative pose
// measurements and landmark measurements; priors link their poses to the
// world frame, so all poses with priors are in one component. No term links
// two components, so the objective (pose_graph.h's F) is the sum of the
// components' objectives and each component without priors has its own
// gauge: the relative placement of two components is not observable. Each
// component is solved by Solve() as a graph of its own (with its landmarks
// and priors), in its own gauge: the world frame if it has the priors, else
// its FIX pose if it holds the graph's, else its first pose (smallest index),
// at that pose's initial value if the graph has VERTEX poses, else at the
// identity (its landmarks move with its poses). The optimum of the whole graph
// is the sum of the components' optima, so the sum of their proven lower
// bounds is a proven lower bound of the whole.

#ifndef CERES_SESYNC_COMPONENT_SOLVER_H_
#define CERES_SESYNC_COMPONENT_SOLVER_H_

#include <cstdint>
#include <string>
#include <vector>

#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"

namespace ceres_sesync {

// One connected component of a pose graph.
struct PoseGraphComponent {
  // Dense indices (into the whole graph) of the component's poses, ascending:
  // poses[k] is pose k of `graph`.
  std::vector<int> poses;
  // Indices of the component's measurements in the whole graph, ascending:
  // measurements[k] is measurement k of `graph`.
  std::vector<int> measurements;
  // The same for its landmarks (landmarks[k] is landmark k of `graph`), its
  // landmark measurements and its priors.
  std::vector<int> landmarks;
  std::vector<int> landmark_measurements;
  std::vector<int> priors;
  // The component as a graph of its own (local indices; vertex and landmark
  // ids, initial poses and landmark positions, and the FIX pose, if it is in
  // this component, carried over).
  PoseGraph graph;
};

// Splits `graph` into its connected components (ConnectedComponents()),
// ordered by their first pose. The graph need not be valid (measurements
// whose indices are out of range are left out).
std::vector<PoseGraphComponent> SplitIntoComponents(const PoseGraph& graph);

struct ComponentsSummary {
  struct Component {
    std::vector<int> poses;      // As PoseGraphComponent::poses.
    std::vector<int> landmarks;  // As PoseGraphComponent::landmarks.
    int num_measurements = 0, num_landmark_measurements = 0, num_priors = 0;
    // Vertex id of the component's gauge pose (see above); -1 for the
    // component with the priors (they place it in the world frame).
    int64_t gauge_vertex_id = 0;
    SolverSummary summary;  // Solve() on the component.
  };

  // kCertifiedOptimum if every component is certified, kInvalidInput if the
  // graph is invalid (message; no component is solved), else the status of
  // the first component that is not certified.
  SolverSummary::Status status = SolverSummary::Status::kInvalidInput;
  std::string message;
  int dimension = 0, num_poses = 0, num_measurements = 0;
  int num_landmarks = 0, num_landmark_measurements = 0, num_priors = 0;
  std::vector<Component> components;
  // Sums over the components: F(x) of the returned poses, the proven lower
  // bound on the optimum, their difference, and that relative to the lower
  // bound (0 when every component's bound is 0, +inf for a bound of 0 with a
  // positive objective).
  double objective = 0;
  double lower_bound = 0;
  double suboptimality_bound = 0;
  double relative_suboptimality_bound = 0;
  double total_time_s = 0;

  bool certified() const {
    return status == SolverSummary::Status::kCertifiedOptimum;
  }
  // As SolverSummary::StatusString().
  std::string StatusString() const;
  std::string BriefReport() const;
  // A table with one row per component, then the totals.
  std::string FullReport() const;
};

// Validates `graph` (all of ValidatePoseGraph but connectivity), splits it
// into its connected components and solves each with Solve() and `options`
// (one at a time; a max_time_s limit counts for the whole call). *solution
// gets one pose per pose of `graph` and one position per landmark (both empty
// on invalid input). options.progress, if set, receives each component's
// reports with SolverProgress::component and num_components filled in.
void SolveByComponent(const PoseGraph& graph, const SolverOptions& options,
                      Solution* solution, ComponentsSummary* summary);
// The same, returning the poses only.
Poses SolveByComponent(const PoseGraph& graph, const SolverOptions& options,
                       ComponentsSummary* summary);

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_COMPONENT_SOLVER_H_
