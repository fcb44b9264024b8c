#include "ceres_sesync/ceres_baseline.h"

#include <cmath>
#include <cstdio>
#include <memory>
#include <queue>
#include <sstream>

#include "Eigen/Geometry"
#include "Eigen/SVD"
#include "ceres/autodiff_cost_function.h"
#include "ceres/loss_function.h"
#include "ceres/manifold.h"
#include "ceres/types.h"

namespace ceres_sesync {

namespace {

// Residual of one 2D measurement over (t_i, theta_i, t_j, theta_j).
class Pose2Residual {
 public:
  Pose2Residual(const RelativePoseMeasurement& m)
      : R_(m.R),
        t_(m.t),
        sqrt_kappa_(std::sqrt(m.kappa)),
        sqrt_tau_(std::sqrt(m.tau)) {}

  template <typename T>
  bool operator()(const T* ti, const T* theta_i, const T* tj, const T* theta_j,
                  T* residual) const {
    using std::cos;
    using std::sin;
    Eigen::Matrix<T, 2, 2> Ri, Rj;
    const T ci = cos(theta_i[0]), si = sin(theta_i[0]);
    const T cj = cos(theta_j[0]), sj = sin(theta_j[0]);
    Ri << ci, -si, si, ci;
    Rj << cj, -sj, sj, cj;
    const Eigen::Matrix<T, 2, 2> E = Rj - Ri * R_.cast<T>();
    const Eigen::Matrix<T, 2, 1> e =
        Eigen::Map<const Eigen::Matrix<T, 2, 1>>(tj) -
        Eigen::Map<const Eigen::Matrix<T, 2, 1>>(ti) - Ri * t_.cast<T>();
    for (int c = 0; c < 2; ++c) {
      for (int r = 0; r < 2; ++r) residual[2 * c + r] = sqrt_kappa_ * E(r, c);
    }
    residual[4] = sqrt_tau_ * e[0];
    residual[5] = sqrt_tau_ * e[1];
    return true;
  }

 private:
  const Eigen::Matrix2d R_;
  const Eigen::Vector2d t_;
  const double sqrt_kappa_, sqrt_tau_;
};

// Rotation matrix of the (not necessarily unit) quaternion q = (x, y, z, w):
// the homogeneous form divided by |q|^2, exact on the unit sphere.
template <typename T>
Eigen::Matrix<T, 3, 3> QuaternionToRotation(const T* q) {
  const T x = q[0], y = q[1], z = q[2], w = q[3];
  const T s = T(1) / (x * x + y * y + z * z + w * w);
  Eigen::Matrix<T, 3, 3> R;
  R << w * w + x * x - y * y - z * z, T(2) * (x * y - w * z),
      T(2) * (x * z + w * y),  //
      T(2) * (x * y + w * z), w * w - x * x + y * y - z * z,
      T(2) * (y * z - w * x),  //
      T(2) * (x * z - w * y), T(2) * (y * z + w * x),
      w * w - x * x - y * y + z * z;
  return s * R;
}

// Residual of one 3D measurement over (t_i, q_i, t_j, q_j).
class Pose3Residual {
 public:
  Pose3Residual(const RelativePoseMeasurement& m)
      : R_(m.R),
        t_(m.t),
        sqrt_kappa_(std::sqrt(m.kappa)),
        sqrt_tau_(std::sqrt(m.tau)) {}

  template <typename T>
  bool operator()(const T* ti, const T* qi, const T* tj, const T* qj,
                  T* residual) const {
    const Eigen::Matrix<T, 3, 3> Ri = QuaternionToRotation(qi);
    const Eigen::Matrix<T, 3, 3> Rj = QuaternionToRotation(qj);
    const Eigen::Matrix<T, 3, 3> E = Rj - Ri * R_.cast<T>();
    const Eigen::Matrix<T, 3, 1> e =
        Eigen::Map<const Eigen::Matrix<T, 3, 1>>(tj) -
        Eigen::Map<const Eigen::Matrix<T, 3, 1>>(ti) - Ri * t_.cast<T>();
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) residual[3 * c + r] = sqrt_kappa_ * E(r, c);
    }
    for (int r = 0; r < 3; ++r) residual[9 + r] = sqrt_tau_ * e[r];
    return true;
  }

 private:
  const Eigen::Matrix3d R_;
  const Eigen::Vector3d t_;
  const double sqrt_kappa_, sqrt_tau_;
};

int GaugePose(const PoseGraph& graph) {
  return graph.fixed_pose >= 0 ? graph.fixed_pose : 0;
}

// Nearest rotation (Frobenius) to a 3x3 matrix.
Eigen::Matrix3d ProjectToSO3(const Eigen::Matrix3d& M) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) =
      (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1 : 1;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

// The loss of `loss` (owned by the problem), or null for least squares.
ceres::LossFunction* MakeLoss(const CeresRobustLoss& loss) {
  const double a = std::sqrt(loss.threshold);
  switch (loss.type) {
    case CeresRobustLoss::Type::kNone:
      return nullptr;
    case CeresRobustLoss::Type::kHuber:
      return new ceres::HuberLoss(a);
    case CeresRobustLoss::Type::kCauchy:
      return new ceres::CauchyLoss(a);
  }
  return nullptr;
}

const char* MethodName(const ceres::Solver::Summary& s) {
  if (s.trust_region_strategy_type == ceres::DOGLEG) {
    return s.dogleg_type == ceres::TRADITIONAL_DOGLEG ? "PDL-GN" : "dogleg";
  }
  return "LM";
}

}  // namespace

bool CeresPoseBlocks::FromPoses(int d, const Poses& poses, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (d != 2 && d != 3) return fail("pose dimension must be 2 or 3");
  const int n = static_cast<int>(poses.size());
  std::vector<double> t(static_cast<size_t>(d) * n);
  std::vector<double> r(static_cast<size_t>(d == 2 ? 1 : 4) * n);
  for (int i = 0; i < n; ++i) {
    const Pose& p = poses[i];
    if (p.R.rows() != d || p.R.cols() != d || p.t.size() != d ||
        !p.R.allFinite() || !p.t.allFinite()) {
      std::ostringstream m;
      m << "pose " << i << " is not a finite pose of dimension " << d;
      return fail(m.str());
    }
    for (int k = 0; k < d; ++k) t[d * i + k] = p.t[k];
    if (d == 2) {
      r[i] = std::atan2(p.R(1, 0) - p.R(0, 1), p.R(0, 0) + p.R(1, 1));
    } else {
      const Eigen::Matrix3d M = p.R;
      Eigen::Quaterniond q(ProjectToSO3(M));
      q.normalize();
      for (int k = 0; k < 4; ++k) r[4 * i + k] = q.coeffs()[k];
    }
  }
  dimension = d;
  translations = std::move(t);
  rotations = std::move(r);
  return true;
}

Poses CeresPoseBlocks::ToPoses() const {
  const int n = num_poses();
  Poses poses(n);
  const int d = dimension;
  for (int i = 0; i < n; ++i) {
    poses[i].t =
        Eigen::Map<const Eigen::VectorXd>(translations.data() + d * i, d);
    if (d == 2) {
      const double c = std::cos(rotations[i]), s = std::sin(rotations[i]);
      poses[i].R.resize(2, 2);
      poses[i].R << c, -s, s, c;
    } else {
      poses[i].R = QuaternionToRotation(rotations.data() + 4 * i);
    }
  }
  return poses;
}

bool BuildCeresProblem(const PoseGraph& graph, CeresPoseBlocks* blocks,
                       ceres::Problem* problem, std::string* error,
                       const CeresRobustLoss& loss) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!blocks || !problem) return fail("null blocks or problem");
  std::string why;
  if (!ValidatePoseGraph(graph, &why))
    return fail("invalid pose graph: " + why);
  const int d = graph.dimension;
  const int n = graph.num_poses;
  if (blocks->dimension != d || blocks->num_poses() != n ||
      blocks->rotations.size() != static_cast<size_t>(d == 2 ? n : 4 * n)) {
    return fail("parameter blocks do not match the graph's size");
  }
  if (graph.fixed_pose >= n) return fail("fixed_pose is out of range");
  if (loss.type != CeresRobustLoss::Type::kNone &&
      !(loss.threshold > 0 && std::isfinite(loss.threshold))) {
    return fail("a robust loss needs a positive finite threshold");
  }
  for (int i = 0; i < n; ++i) {
    problem->AddParameterBlock(blocks->translation(i), d);
    if (d == 2) {
      problem->AddParameterBlock(blocks->rotation(i), 1);
    } else {
      problem->AddParameterBlock(blocks->rotation(i), 4,
                                 new ceres::EigenQuaternionManifold);
    }
  }
  for (const RelativePoseMeasurement& m : graph.measurements) {
    ceres::CostFunction* cost;
    if (d == 2) {
      cost = new ceres::AutoDiffCostFunction<Pose2Residual, 6, 2, 1, 2, 1>(
          new Pose2Residual(m));
    } else {
      cost = new ceres::AutoDiffCostFunction<Pose3Residual, 12, 3, 4, 3, 4>(
          new Pose3Residual(m));
    }
    problem->AddResidualBlock(cost, MakeLoss(loss), blocks->translation(m.i),
                              blocks->rotation(m.i), blocks->translation(m.j),
                              blocks->rotation(m.j));
  }
  const int gauge = GaugePose(graph);
  problem->SetParameterBlockConstant(blocks->translation(gauge));
  problem->SetParameterBlockConstant(blocks->rotation(gauge));
  return true;
}

bool SolveWithCeres(const PoseGraph& graph, const Poses& initial,
                    const CeresBaselineOptions& options, Poses* result,
                    CeresBaselineSummary* summary, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (static_cast<int>(initial.size()) != graph.num_poses) {
    return fail("initial poses must have one pose per vertex");
  }
  ceres::Solver::Options solver_options;
  solver_options.minimizer_type = ceres::TRUST_REGION;
  if (options.method == CeresBaselineOptions::Method::kPowellDogleg) {
    solver_options.trust_region_strategy_type = ceres::DOGLEG;
    solver_options.dogleg_type = ceres::TRADITIONAL_DOGLEG;
  } else {
    solver_options.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  }
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.gradient_tolerance = options.gradient_tolerance;
  solver_options.parameter_tolerance = options.parameter_tolerance;
  solver_options.max_num_iterations = options.max_num_iterations;
  solver_options.max_solver_time_in_seconds = options.max_solver_time_s;
  solver_options.num_threads = options.num_threads;
  solver_options.minimizer_progress_to_stdout = options.verbose;
  solver_options.logging_type =
      options.verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;
  std::string why;
  if (!solver_options.IsValid(&why)) {
    return fail("invalid Ceres options: " + why);
  }

  CeresPoseBlocks blocks;
  if (!blocks.FromPoses(graph.dimension, initial, &why)) {
    return fail("invalid initial poses: " + why);
  }
  ceres::Problem problem;
  if (!BuildCeresProblem(graph, &blocks, &problem, &why, options.loss)) {
    return fail(why);
  }

  ceres::Solver::Summary ceres_summary;
  ceres::Solve(solver_options, &problem, &ceres_summary);
  if (ceres_summary.termination_type == ceres::FAILURE ||
      !ceres_summary.IsSolutionUsable()) {
    return fail("Ceres failed: " + ceres_summary.message);
  }
  const Poses poses = blocks.ToPoses();
  if (summary) {
    summary->initial_robust_objective = 2 * ceres_summary.initial_cost;
    summary->final_robust_objective = 2 * ceres_summary.final_cost;
    const bool robust = options.loss.type != CeresRobustLoss::Type::kNone;
    summary->initial_objective = robust ? EvaluateObjective(graph, initial)
                                        : summary->initial_robust_objective;
    summary->final_objective = robust ? EvaluateObjective(graph, poses)
                                      : summary->final_robust_objective;
    summary->iterations = ceres_summary.num_successful_steps +
                          ceres_summary.num_unsuccessful_steps;
    summary->time_s = ceres_summary.total_time_in_seconds;
    summary->solver_summary = std::move(ceres_summary);
  }
  if (result) *result = poses;
  return true;
}

std::string CeresBaselineSummary::BriefReport() const {
  char buffer[256];
  std::snprintf(
      buffer, sizeof(buffer),
      "Ceres %s: F %.6e -> %.6e, %d iterations, %.3f s, %s",
      MethodName(solver_summary), initial_objective, final_objective,
      iterations, time_s,
      ceres::TerminationTypeToString(solver_summary.termination_type));
  return buffer;
}

Poses OdometryInitialization(const PoseGraph& graph) {
  const int d = graph.dimension;
  const int n = std::max(0, graph.num_poses);
  if (d != 2 && d != 3) return Poses(n);
  Poses poses = IdentityPoses(d, n);
  if (n == 0) return poses;
  int root = GaugePose(graph);
  if (root >= n) root = 0;
  auto valid_pose = [d](const Pose& p) {
    return p.R.rows() == d && p.R.cols() == d && p.t.size() == d;
  };
  if (static_cast<int>(graph.initial_poses.size()) == n &&
      valid_pose(graph.initial_poses[root])) {
    poses[root] = graph.initial_poses[root];
  }
  // Adjacency: (measurement index) per pose, in measurement order.
  std::vector<std::vector<int>> adjacent(n);
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    const RelativePoseMeasurement& m = graph.measurements[k];
    if (m.i < 0 || m.j < 0 || m.i >= n || m.j >= n || m.i == m.j) continue;
    if (m.R.rows() != d || m.R.cols() != d || m.t.size() != d) continue;
    adjacent[m.i].push_back(static_cast<int>(k));
    adjacent[m.j].push_back(static_cast<int>(k));
  }
  std::vector<char> visited(n, 0);
  std::queue<int> queue;
  queue.push(root);
  visited[root] = 1;
  while (!queue.empty()) {
    const int a = queue.front();
    queue.pop();
    for (int k : adjacent[a]) {
      const RelativePoseMeasurement& m = graph.measurements[k];
      const int b = m.i == a ? m.j : m.i;
      if (visited[b]) continue;
      visited[b] = 1;
      if (m.i == a) {  // forward: x_j = x_i * x~_ij
        poses[b].R = poses[a].R * m.R;
        poses[b].t = poses[a].t + poses[a].R * m.t;
      } else {  // backward: x_i = x_j * x~_ij^-1
        poses[b].R = poses[a].R * m.R.transpose();
        poses[b].t = poses[a].t - poses[b].R * m.t;
      }
      queue.push(b);
    }
  }
  return poses;
}

}  // namespace ceres_sesync
