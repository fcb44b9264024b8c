// Uses the installed library: builds a 3-pose 2D pose graph with exact
// measurements, writes it as g2o, reads it back and evaluates the objective.
// Returns 0 on success.

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "Eigen/Geometry"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"

namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "consumer: %s\n", message.c_str());
  return 1;
}

}  // namespace

int main() {
  using ceres_sesync::Pose;
  using ceres_sesync::Poses;

  // Ground truth and exact measurements R_ij = R_i^T R_j,
  // t_ij = R_i^T (t_j - t_i): the objective vanishes at the ground truth.
  const Poses truth = {
      {Eigen::Rotation2Dd(0.0).toRotationMatrix(), Eigen::Vector2d(0, 0)},
      {Eigen::Rotation2Dd(0.3).toRotationMatrix(), Eigen::Vector2d(1, 0)},
      {Eigen::Rotation2Dd(-0.5).toRotationMatrix(), Eigen::Vector2d(1, 2)},
  };
  ceres_sesync::PoseGraph graph;
  graph.dimension = 2;
  for (int64_t id : {10, 20, 30}) graph.AddVertex(id);
  for (auto [i, j] : {std::pair{0, 1}, {1, 2}, {0, 2}}) {
    ceres_sesync::RelativePoseMeasurement m;
    m.i = i;
    m.j = j;
    m.R = truth[i].R.transpose() * truth[j].R;
    m.t = truth[i].R.transpose() * (truth[j].t - truth[i].t);
    m.kappa = 10 * (i + 1);
    m.tau = 5;
    graph.measurements.push_back(m);
  }

  const std::string path =
      (std::filesystem::temp_directory_path() /
       ("ceres_sesync_consumer_" + std::to_string(getpid()) + ".g2o"))
          .string();
  std::string error;
  if (!ceres_sesync::WriteG2oFile(path, graph, truth, &error))
    return Fail(error);
  ceres_sesync::PoseGraph read;
  const bool ok = ceres_sesync::ReadG2oFile(path, {}, &read, &error);
  std::filesystem::remove(path);
  if (!ok) return Fail(error);
  if (read.dimension != 2 || read.num_poses != 3 ||
      read.measurements.size() != 3 || read.initial_poses.size() != 3) {
    return Fail("unexpected counts after reading back");
  }

  const Poses identity = ceres_sesync::IdentityPoses(2, 3);
  const double at_identity = ceres_sesync::EvaluateObjective(read, identity);
  const double expected = ceres_sesync::EvaluateObjective(graph, identity);
  const double at_truth = ceres_sesync::EvaluateObjective(read, truth);
  std::printf("consumer: F(identity) = %.17g, F(truth) = %.3g\n", at_identity,
              at_truth);
  // Exact measurements: F(truth) is rounding noise; the round trip keeps
  // F(identity) to ~1e-15 relative (1e-12 leaves ample margin).
  if (!(at_truth < 1e-20)) return Fail("F(truth) is not ~0");
  if (!(at_identity > 1 &&
        std::abs(at_identity - expected) <= 1e-12 * expected)) {
    return Fail("F(identity) changed in the round trip");
  }
  return 0;
}
