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
#include "ceres_sesync/internal/openmp_teams.h"

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

// Rotation matrix of a 2D angle.
template <typename T>
Eigen::Matrix<T, 2, 2> AngleToRotation(const T* theta) {
  using std::cos;
  using std::sin;
  const T c = cos(theta[0]), s = sin(theta[0]);
  Eigen::Matrix<T, 2, 2> R;
  R << c, -s, s, c;
  return R;
}

// R(theta) in 2D, R(q) in 3D.
template <int D, typename T>
Eigen::Matrix<T, D, D> BlockRotation(const T* r) {
  if constexpr (D == 2) {
    return AngleToRotation(r);
  } else {
    return QuaternionToRotation(r);
  }
}

// Residual of one landmark measurement over (t_i, rotation_i, p_l):
// sqrt(nu) (p_l - t_i - R_i z).
template <int D>
class LandmarkResidual {
 public:
  explicit LandmarkResidual(const LandmarkMeasurement& m)
      : z_(m.z), sqrt_nu_(std::sqrt(m.nu)) {}

  template <typename T>
  bool operator()(const T* ti, const T* ri, const T* pl, T* residual) const {
    const Eigen::Matrix<T, D, D> Ri = BlockRotation<D>(ri);
    const Eigen::Matrix<T, D, 1> e =
        Eigen::Map<const Eigen::Matrix<T, D, 1>>(pl) -
        Eigen::Map<const Eigen::Matrix<T, D, 1>>(ti) -
        Ri * z_.template cast<T>();
    for (int r = 0; r < D; ++r) residual[r] = sqrt_nu_ * e[r];
    return true;
  }

 private:
  const Eigen::Matrix<double, D, 1> z_;
  const double sqrt_nu_;
};

// Rotation part of a prior over rotation_i: sqrt(kappa) vec(R_i - R~).
template <int D>
class RotationPriorResidual {
 public:
  explicit RotationPriorResidual(const PosePrior& p)
      : R_(p.R), sqrt_kappa_(std::sqrt(p.kappa)) {}

  template <typename T>
  bool operator()(const T* ri, T* residual) const {
    const Eigen::Matrix<T, D, D> E =
        BlockRotation<D>(ri) - R_.template cast<T>();
    for (int c = 0; c < D; ++c) {
      for (int r = 0; r < D; ++r) residual[D * c + r] = sqrt_kappa_ * E(r, c);
    }
    return true;
  }

 private:
  const Eigen::Matrix<double, D, D> R_;
  const double sqrt_kappa_;
};

// Position part of a prior over t_i: sqrt(tau) (t_i - g).
template <int D>
class PositionPriorResidual {
 public:
  explicit PositionPriorResidual(const PosePrior& p)
      : g_(p.t), sqrt_tau_(std::sqrt(p.tau)) {}

  template <typename T>
  bool operator()(const T* ti, T* residual) const {
    for (int r = 0; r < D; ++r) residual[r] = sqrt_tau_ * (ti[r] - T(g_[r]));
    return true;
  }

 private:
  const Eigen::Matrix<double, D, 1> g_;
  const double sqrt_tau_;
};

int GaugePose(const PoseGraph& graph) {
  return graph.fixed_pose >= 0 ? graph.fixed_pose : 0;
}

// What the Ceres problem holds constant (see BuildCeresProblem).
struct Gauge {
  int pose = -1;               // Pose whose translation is held, or -1.
  bool hold_rotation = false;  // Whether that pose's rotation is held too.
};

Gauge GaugeOf(const PoseGraph& graph) {
  if (graph.fixed_pose >= 0 || graph.priors.empty()) {
    return {GaugePose(graph), true};
  }
  for (const PosePrior& p : graph.priors) {
    if (p.has_position()) return {};  // The priors fix the gauge.
  }
  return {0, false};  // Rotation priors only: the translation is free.
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

// The loss of `loss`'s type with a^2 = `threshold` (owned by the problem),
// or null for least squares (no type, or threshold 0).
ceres::LossFunction* MakeLoss(const CeresRobustLoss& loss, double threshold) {
  if (!(threshold > 0)) return nullptr;
  const double a = std::sqrt(threshold);
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
  landmarks.clear();
  return true;
}

bool CeresPoseBlocks::FromSolution(int d, const Solution& solution,
                                   std::string* error) {
  if (!FromPoses(d, solution.poses, error)) return false;
  std::vector<double> p(static_cast<size_t>(d) * solution.landmarks.size());
  for (size_t l = 0; l < solution.landmarks.size(); ++l) {
    const Eigen::VectorXd& x = solution.landmarks[l];
    if (x.size() != d || !x.allFinite()) {
      if (error) {
        *error = "landmark " + std::to_string(l) +
                 " is not a finite position of dimension " + std::to_string(d);
      }
      return false;
    }
    for (int k = 0; k < d; ++k) p[d * l + k] = x[k];
  }
  landmarks = std::move(p);
  return true;
}

LandmarkPositions CeresPoseBlocks::ToLandmarks() const {
  LandmarkPositions positions(num_landmarks());
  for (int l = 0; l < num_landmarks(); ++l) {
    positions[l] = Eigen::Map<const Eigen::VectorXd>(
        landmarks.data() + dimension * l, dimension);
  }
  return positions;
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
      blocks->rotations.size() != static_cast<size_t>(d == 2 ? n : 4 * n) ||
      blocks->landmarks.size() !=
          static_cast<size_t>(d) * graph.num_landmarks) {
    return fail("parameter blocks do not match the graph's size");
  }
  if (graph.fixed_pose >= n) return fail("fixed_pose is out of range");
  if (loss.type != CeresRobustLoss::Type::kNone &&
      !(loss.threshold > 0 && std::isfinite(loss.threshold))) {
    return fail("a robust loss needs a positive finite threshold");
  }
  if (!(loss.landmark_threshold >= 0 &&
        std::isfinite(loss.landmark_threshold)) ||
      !(loss.prior_threshold >= 0 && std::isfinite(loss.prior_threshold))) {
    return fail("landmark and prior loss thresholds must be finite and >= 0");
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
  for (int l = 0; l < graph.num_landmarks; ++l) {
    problem->AddParameterBlock(blocks->landmark(l), d);
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
    problem->AddResidualBlock(cost, MakeLoss(loss, loss.threshold),
                              blocks->translation(m.i), blocks->rotation(m.i),
                              blocks->translation(m.j), blocks->rotation(m.j));
  }
  for (const LandmarkMeasurement& m : graph.landmark_measurements) {
    ceres::CostFunction* cost;
    if (d == 2) {
      cost = new ceres::AutoDiffCostFunction<LandmarkResidual<2>, 2, 2, 1, 2>(
          new LandmarkResidual<2>(m));
    } else {
      cost = new ceres::AutoDiffCostFunction<LandmarkResidual<3>, 3, 3, 4, 3>(
          new LandmarkResidual<3>(m));
    }
    problem->AddResidualBlock(cost, MakeLoss(loss, loss.landmark_threshold),
                              blocks->translation(m.i), blocks->rotation(m.i),
                              blocks->landmark(m.l));
  }
  for (const PosePrior& p : graph.priors) {
    if (p.has_rotation()) {
      ceres::CostFunction* cost;
      if (d == 2) {
        cost = new ceres::AutoDiffCostFunction<RotationPriorResidual<2>, 4, 1>(
            new RotationPriorResidual<2>(p));
      } else {
        cost = new ceres::AutoDiffCostFunction<RotationPriorResidual<3>, 9, 4>(
            new RotationPriorResidual<3>(p));
      }
      problem->AddResidualBlock(cost, MakeLoss(loss, loss.prior_threshold),
                                blocks->rotation(p.i));
    }
    if (p.has_position()) {
      ceres::CostFunction* cost;
      if (d == 2) {
        cost = new ceres::AutoDiffCostFunction<PositionPriorResidual<2>, 2, 2>(
            new PositionPriorResidual<2>(p));
      } else {
        cost = new ceres::AutoDiffCostFunction<PositionPriorResidual<3>, 3, 3>(
            new PositionPriorResidual<3>(p));
      }
      problem->AddResidualBlock(cost, MakeLoss(loss, loss.prior_threshold),
                                blocks->translation(p.i));
    }
  }
  const Gauge gauge = GaugeOf(graph);
  if (gauge.pose >= 0) {
    problem->SetParameterBlockConstant(blocks->translation(gauge.pose));
    if (gauge.hold_rotation) {
      problem->SetParameterBlockConstant(blocks->rotation(gauge.pose));
    }
  }
  return true;
}

bool SolveWithCeres(const PoseGraph& graph, const Poses& initial,
                    const CeresBaselineOptions& options, Poses* result,
                    CeresBaselineSummary* summary, std::string* error) {
  if (graph.num_landmarks > 0) {
    if (error) {
      *error =
          "the graph has landmarks: use the SolveWithCeres overload that "
          "takes and returns a Solution (poses and landmark positions)";
    }
    return false;
  }
  Solution solution;
  if (!SolveWithCeres(graph, Solution{initial, {}}, options,
                      result ? &solution : nullptr, summary, error)) {
    return false;
  }
  if (result) *result = std::move(solution.poses);
  return true;
}

bool SolveWithCeres(const PoseGraph& graph, const Solution& initial,
                    const CeresBaselineOptions& options, Solution* result,
                    CeresBaselineSummary* summary, std::string* error) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (static_cast<int>(initial.poses.size()) != graph.num_poses) {
    return fail("initial poses must have one pose per vertex");
  }
  if (static_cast<int>(initial.landmarks.size()) != graph.num_landmarks) {
    return fail(
        "initial landmark positions must have one position per "
        "landmark");
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
  if (!blocks.FromSolution(graph.dimension, initial, &why)) {
    return fail("invalid initial poses or landmarks: " + why);
  }
  ceres::Problem problem;
  if (!BuildCeresProblem(graph, &blocks, &problem, &why, options.loss)) {
    return fail(why);
  }

  ceres::Solver::Summary ceres_summary;
  {
    // Its sparse Cholesky is CHOLMOD's supernodal one: the same OpenMP teams
    // as in SE-Sync's factorizations, kept to one thread the same way
    // (openmp_teams.h), so the two are compared on equal terms.
    internal::ScopedSerialOpenMpTeams serial_teams;
    ceres::Solve(solver_options, &problem, &ceres_summary);
  }
  if (ceres_summary.termination_type == ceres::FAILURE ||
      !ceres_summary.IsSolutionUsable()) {
    return fail("Ceres failed: " + ceres_summary.message);
  }
  Solution solution{blocks.ToPoses(), blocks.ToLandmarks()};
  if (summary) {
    summary->initial_robust_objective = 2 * ceres_summary.initial_cost;
    summary->final_robust_objective = 2 * ceres_summary.final_cost;
    const bool robust = options.loss.type != CeresRobustLoss::Type::kNone;
    summary->initial_objective = robust ? EvaluateObjective(graph, initial)
                                        : summary->initial_robust_objective;
    summary->final_objective = robust ? EvaluateObjective(graph, solution)
                                      : summary->final_robust_objective;
    summary->iterations = ceres_summary.num_successful_steps +
                          ceres_summary.num_unsuccessful_steps;
    summary->time_s = ceres_summary.total_time_in_seconds;
    summary->solver_summary = std::move(ceres_summary);
  }
  if (result) *result = std::move(solution);
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
  auto valid_pose = [d](const Pose& p) {
    return p.R.rows() == d && p.R.cols() == d && p.t.size() == d;
  };
  const bool has_initial = static_cast<int>(graph.initial_poses.size()) == n;
  // Roots: the gauge pose, then (for components reached only through the
  // world frame) every pose with a prior, in prior order.
  std::vector<int> roots;
  if (graph.fixed_pose >= 0 && graph.fixed_pose < n) {
    roots.push_back(graph.fixed_pose);
  } else if (!graph.priors.empty()) {
    int root = -1;
    for (const PosePrior& p : graph.priors) {  // Prefer a full pose prior.
      if (p.i >= 0 && p.i < n && p.has_rotation() && p.has_position()) {
        root = p.i;
        break;
      }
    }
    roots.push_back(root >= 0 ? root : 0);
  } else {
    roots.push_back(0);
  }
  for (const PosePrior& p : graph.priors) {
    if (p.i >= 0 && p.i < n) roots.push_back(p.i);
  }
  // Places a root: its initial pose if there is one, else the identity with
  // the rotation and position of its first priors.
  auto place = [&](int root) {
    if (has_initial && valid_pose(graph.initial_poses[root])) {
      poses[root] = graph.initial_poses[root];
      return;
    }
    bool rotation = false, position = false;
    for (const PosePrior& p : graph.priors) {
      if (p.i != root) continue;
      if (!rotation && p.has_rotation() && p.R.rows() == d && p.R.cols() == d) {
        poses[root].R = p.R;
        rotation = true;
      }
      if (!position && p.has_position() && p.t.size() == d) {
        poses[root].t = p.t;
        position = true;
      }
    }
  };
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
  for (const int root : roots) {
    if (visited[root]) continue;
    place(root);
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
  }
  return poses;
}

LandmarkPositions InitialLandmarkPositions(const PoseGraph& graph,
                                           const Poses& poses) {
  const int d = graph.dimension;
  const int L = std::max(0, graph.num_landmarks);
  LandmarkPositions positions(L, Eigen::VectorXd::Zero(std::max(d, 0)));
  std::vector<char> placed(L, 0);
  const int n = static_cast<int>(poses.size());
  for (const LandmarkMeasurement& m : graph.landmark_measurements) {
    if (m.l < 0 || m.l >= L || placed[m.l] || m.i < 0 || m.i >= n) continue;
    const Pose& x = poses[m.i];
    if (x.R.rows() != d || x.R.cols() != d || x.t.size() != d ||
        m.z.size() != d) {
      continue;
    }
    positions[m.l] = x.t + x.R * m.z;
    placed[m.l] = 1;
  }
  return positions;
}

}  // namespace ceres_sesync
