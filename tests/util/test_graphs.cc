#include "tests/util/test_graphs.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "Eigen/Dense"
#include "ceres_sesync/langevin.h"

namespace ceres_sesync::test_util {

Eigen::MatrixXd RandomRotation(int d, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd G(d, d);
  for (int k = 0; k < d * d; ++k) G.data()[k] = normal(*rng);
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(G);
  Eigen::MatrixXd Q = qr.householderQ();
  const Eigen::MatrixXd R = qr.matrixQR().triangularView<Eigen::Upper>();
  for (int k = 0; k < d; ++k) {
    if (R(k, k) < 0) Q.col(k) *= -1;
  }
  if (Q.determinant() < 0) Q.col(0) *= -1;
  return Q;
}

Poses RandomPoses(int d, int n, double translation_scale,
                  std::mt19937_64* rng) {
  std::uniform_real_distribution<double> uniform(-translation_scale,
                                                 translation_scale);
  Poses poses(n);
  for (Pose& p : poses) {
    p.R = RandomRotation(d, rng);
    p.t.resize(d);
    for (int a = 0; a < d; ++a) p.t(a) = uniform(*rng);
  }
  return poses;
}

namespace {

RelativePoseMeasurement ExactMeasurement(const Poses& truth, int i, int j,
                                         double kappa, double tau) {
  RelativePoseMeasurement e;
  e.i = i;
  e.j = j;
  e.R = truth[i].R.transpose() * truth[j].R;
  e.t = truth[i].R.transpose() * (truth[j].t - truth[i].t);
  e.kappa = kappa;
  e.tau = tau;
  return e;
}

}  // namespace

PoseGraph RandomPoseGraph(const RandomGraphOptions& options,
                          Poses* ground_truth) {
  const int d = options.dimension, n = options.num_poses;
  std::mt19937_64 rng(options.seed);
  const Poses truth = RandomPoses(d, n, options.translation_scale, &rng);
  PoseGraph graph;
  graph.dimension = d;
  for (int k = 0; k < n; ++k) graph.AddVertex(k);
  std::vector<std::pair<int, int>> edges;
  for (int k = 1; k < n; ++k) {
    const int parent = options.chain
                           ? k - 1
                           : std::uniform_int_distribution<int>(0, k - 1)(rng);
    edges.emplace_back(parent, k);
  }
  if (n >= 2) {
    std::uniform_int_distribution<int> pick(0, n - 1);
    for (int c = 0; c < options.num_loop_closures; ++c) {
      int i = pick(rng), j = pick(rng);
      while (j == i) j = pick(rng);
      edges.emplace_back(i, j);
    }
  }
  std::normal_distribution<double> normal;
  for (auto [i, j] : edges) {
    if (std::uniform_int_distribution<int>(0, 1)(rng)) std::swap(i, j);
    RelativePoseMeasurement e =
        ExactMeasurement(truth, i, j, options.kappa, options.tau);
    if (!options.noiseless) {
      e.R = e.R * SampleIsotropicLangevin(d, options.kappa, &rng);
      for (int a = 0; a < d; ++a) {
        e.t(a) += normal(rng) / std::sqrt(options.tau);
      }
    }
    graph.measurements.push_back(e);
  }
  if (ground_truth) *ground_truth = truth;
  return graph;
}

PoseGraph RandomLandmarkGraph(const RandomLandmarkGraphOptions& options,
                              Solution* truth) {
  Solution x;
  PoseGraph graph = RandomPoseGraph(options.poses, &x.poses);
  const int d = graph.dimension, n = graph.num_poses;
  const bool noisy = !options.poses.noiseless;
  std::mt19937_64 rng(options.poses.seed + 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<double> uniform(
      -options.poses.translation_scale, options.poses.translation_scale);
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::normal_distribution<double> normal;
  auto noise = [&](double precision) {
    Eigen::VectorXd v(d);
    for (int a = 0; a < d; ++a) {
      v(a) = noisy ? normal(rng) / std::sqrt(precision) : 0.0;
    }
    return v;
  };
  for (int l = 0; l < options.num_landmarks; ++l) {
    graph.AddLandmark(n + l);
    Eigen::VectorXd p(d);
    for (int a = 0; a < d; ++a) p(a) = uniform(rng);
    x.landmarks.push_back(p);
    for (int k = 0; k < options.observations_per_landmark; ++k) {
      LandmarkMeasurement m;
      m.i = pick(rng);
      m.l = l;
      m.z =
          x.poses[m.i].R.transpose() * (p - x.poses[m.i].t) + noise(options.nu);
      m.nu = options.nu;
      graph.landmark_measurements.push_back(m);
    }
  }
  auto add_prior = [&](bool rotation, bool position) {
    PosePrior prior;
    prior.i = pick(rng);
    const Pose& pose = x.poses[prior.i];
    if (rotation) {
      prior.kappa = options.prior_kappa;
      prior.R = pose.R;
      if (noisy) {
        prior.R = prior.R * SampleIsotropicLangevin(d, prior.kappa, &rng);
      }
    }
    if (position) {
      prior.tau = options.prior_tau;
      prior.t = pose.t + noise(prior.tau);
    }
    graph.priors.push_back(prior);
  };
  for (int k = 0; k < options.num_position_priors; ++k) add_prior(false, true);
  for (int k = 0; k < options.num_rotation_priors; ++k) add_prior(true, false);
  for (int k = 0; k < options.num_pose_priors; ++k) add_prior(true, true);
  if (truth) *truth = std::move(x);
  return graph;
}

void MakeMeasurementsExact(const Poses& truth, PoseGraph* graph) {
  for (RelativePoseMeasurement& e : graph->measurements) {
    e = ExactMeasurement(truth, e.i, e.j, e.kappa, e.tau);
  }
}

Eigen::MatrixXd StackRotations(const Poses& poses) {
  const int n = static_cast<int>(poses.size());
  const int d = n > 0 ? static_cast<int>(poses[0].R.rows()) : 0;
  Eigen::MatrixXd R(d, d * n);
  for (int i = 0; i < n; ++i) R.middleCols(d * i, d) = poses[i].R;
  return R;
}

Eigen::MatrixXd StackTranslations(const Poses& poses) {
  const int n = static_cast<int>(poses.size());
  const int d = n > 0 ? static_cast<int>(poses[0].t.size()) : 0;
  Eigen::MatrixXd T(d, n);
  for (int i = 0; i < n; ++i) T.col(i) = poses[i].t;
  return T;
}

Poses PosesFromMatrices(const Eigen::MatrixXd& R, const Eigen::MatrixXd& T) {
  const int d = static_cast<int>(R.rows());
  const int n = static_cast<int>(T.cols());
  Poses poses(n);
  for (int i = 0; i < n; ++i) {
    poses[i].R = R.middleCols(d * i, d);
    poses[i].t = T.col(i);
  }
  return poses;
}

double GaugeInvariantPoseDistance(const Poses& a, const Poses& b) {
  if (a.size() != b.size() || a.empty()) return INFINITY;
  double worst = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const Eigen::MatrixXd ra = a[0].R.transpose() * a[i].R;
    const Eigen::MatrixXd rb = b[0].R.transpose() * b[i].R;
    const Eigen::VectorXd ta = a[0].R.transpose() * (a[i].t - a[0].t);
    const Eigen::VectorXd tb = b[0].R.transpose() * (b[i].t - b[0].t);
    worst = std::max({worst, (ra - rb).norm(), (ta - tb).norm()});
  }
  return worst;
}

namespace {

// M += w E E^T, touching only the rows where E is nonzero (E, a residual's
// selector, has at most a few; the full-size product would cost O(size^2)
// per term and a size x size temporary). Same sum as the dense product.
void AddWeightedGram(double w, const Eigen::MatrixXd& E, Eigen::MatrixXd* M) {
  std::vector<int> rows;
  for (int r = 0; r < E.rows(); ++r) {
    if (!E.row(r).isZero(0)) rows.push_back(r);
  }
  for (int a : rows) {
    for (int b : rows) (*M)(a, b) += w * E.row(a).dot(E.row(b));
  }
}

}  // namespace

Eigen::MatrixXd DenseDataMatrix(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses;
  const int size = n + d * n;
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(size, size);
  for (const RelativePoseMeasurement& m : graph.measurements) {
    // X E = R_j - R_i R~ with X = [T R]: E selects block j, minus block i
    // times R~.
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(size, d);
    E.middleRows(n + d * m.j, d) += Eigen::MatrixXd::Identity(d, d);
    E.middleRows(n + d * m.i, d) -= m.R;
    AddWeightedGram(m.kappa, E, &M);
    // X e = t_j - t_i - R_i t~.
    Eigen::VectorXd e = Eigen::VectorXd::Zero(size);
    e(m.j) += 1;
    e(m.i) -= 1;
    e.segment(n + d * m.i, d) -= m.t;
    AddWeightedGram(m.tau, e, &M);
  }
  return M;
}

Eigen::MatrixXd DenseLandmarkDataMatrix(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses, L = graph.num_landmarks;
  const int tw = n + L;                              // Column of t_w.
  auto rot = [&](int i) { return tw + 1 + d * i; };  // R_i; R_w = rot(n).
  const int size = tw + 1 + d * (n + 1);
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(size, size);
  for (const RelativePoseMeasurement& m : graph.measurements) {
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(size, d);
    E.middleRows(rot(m.j), d) += I;
    E.middleRows(rot(m.i), d) -= m.R;
    AddWeightedGram(m.kappa, E, &M);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(size);
    e(m.j) += 1;
    e(m.i) -= 1;
    e.segment(rot(m.i), d) -= m.t;
    AddWeightedGram(m.tau, e, &M);
  }
  for (const LandmarkMeasurement& m : graph.landmark_measurements) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(size);
    e(n + m.l) += 1;
    e(m.i) -= 1;
    e.segment(rot(m.i), d) -= m.z;
    AddWeightedGram(m.nu, e, &M);
  }
  for (const PosePrior& p : graph.priors) {
    if (p.kappa > 0) {
      Eigen::MatrixXd E = Eigen::MatrixXd::Zero(size, d);
      E.middleRows(rot(p.i), d) += I;
      E.middleRows(rot(n), d) -= p.R;
      AddWeightedGram(p.kappa, E, &M);
    }
    if (p.tau > 0) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(size);
      e(p.i) += 1;
      e(tw) -= 1;
      e.segment(rot(n), d) -= p.t;
      AddWeightedGram(p.tau, e, &M);
    }
  }
  return M;
}

Eigen::MatrixXd StackLandmarkSolution(const PoseGraph& graph,
                                      const Solution& solution) {
  const int d = graph.dimension, n = graph.num_poses, L = graph.num_landmarks;
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(d, n + L + 1 + d * (n + 1));
  for (int i = 0; i < n; ++i) {
    X.col(i) = solution.poses[i].t;
    X.middleCols(n + L + 1 + d * i, d) = solution.poses[i].R;
  }
  for (int l = 0; l < L; ++l) X.col(n + l) = solution.landmarks[l];
  X.rightCols(d) = Eigen::MatrixXd::Identity(d, d);  // R_w; t_w = 0.
  return X;
}

DenseLandmarkProblem BuildDenseLandmarkProblem(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses, L = graph.num_landmarks;
  const int tw = n + L;  // Column of t_w in DenseLandmarkDataMatrix.
  bool position_prior = false;
  for (const PosePrior& p : graph.priors) position_prior |= p.tau > 0;
  DenseLandmarkProblem out;
  for (int k = 0; k < n + L; ++k) out.translation_columns.push_back(k);
  if (position_prior) out.translation_columns.push_back(tw);
  for (int i = 0; i < n; ++i) out.rotation_columns.push_back(tw + 1 + d * i);
  if (!graph.priors.empty()) out.rotation_columns.push_back(tw + 1 + d * n);
  out.gauge_column = position_prior ? tw : 0;
  std::vector<int> reduced;
  for (int c : out.translation_columns) {
    if (c != out.gauge_column) reduced.push_back(c);
  }
  std::vector<int> rotations;
  for (int c : out.rotation_columns) {
    for (int a = 0; a < d; ++a) rotations.push_back(c + a);
  }
  const Eigen::MatrixXd M = DenseLandmarkDataMatrix(graph);
  const int t = static_cast<int>(reduced.size());
  const int r = static_cast<int>(rotations.size());
  out.Lbar.resize(t, t);
  out.Vbar.resize(t, r);
  out.D.resize(r, r);
  for (int a = 0; a < t; ++a) {
    for (int b = 0; b < t; ++b) out.Lbar(a, b) = M(reduced[a], reduced[b]);
    for (int b = 0; b < r; ++b) out.Vbar(a, b) = -M(reduced[a], rotations[b]);
  }
  for (int a = 0; a < r; ++a) {
    for (int b = 0; b < r; ++b) out.D(a, b) = M(rotations[a], rotations[b]);
  }
  out.Q = out.D;
  if (t > 0) out.Q -= out.Vbar.transpose() * out.Lbar.llt().solve(out.Vbar);
  out.Q = 0.5 * (out.Q + out.Q.transpose());
  return out;
}

Eigen::MatrixXd DenseLandmarkQ(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses, L = graph.num_landmarks;
  const Eigen::MatrixXd M = DenseLandmarkDataMatrix(graph);
  const int t = n + L + 1, r = d * (graph.priors.empty() ? n : n + 1);
  const Eigen::MatrixXd Mtt = M.topLeftCorner(t, t);
  const Eigen::MatrixXd Mtr = M.block(t, 0, r, t).transpose();
  const Eigen::MatrixXd Mrr = M.block(t, t, r, r);
  const Eigen::MatrixXd pinv =
      Mtt.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::MatrixXd Q = Mrr - Mtr.transpose() * pinv * Mtr;
  return 0.5 * (Q + Q.transpose());
}

Eigen::MatrixXd StackSolverRotations(const PoseGraph& graph,
                                     const Poses& poses) {
  const int d = graph.dimension, n = graph.num_poses;
  const int blocks = graph.priors.empty() ? n : n + 1;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(d, d * blocks);
  for (int i = 0; i < n; ++i) R.middleCols(d * i, d) = poses[i].R;
  if (blocks > n) R.rightCols(d).setIdentity();
  return R;
}

Eigen::MatrixXd DenseQ(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses;
  const Eigen::MatrixXd M = DenseDataMatrix(graph);
  const Eigen::MatrixXd Mtt = M.topLeftCorner(n, n);
  const Eigen::MatrixXd Mtr = M.topRightCorner(n, d * n);
  const Eigen::MatrixXd Mrr = M.bottomRightCorner(d * n, d * n);
  const Eigen::MatrixXd pinv =
      Mtt.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::MatrixXd Q = Mrr - Mtr.transpose() * pinv * Mtr;
  return 0.5 * (Q + Q.transpose());
}

Eigen::MatrixXd DenseQFromPaper(const PoseGraph& graph) {
  const int d = graph.dimension, n = graph.num_poses;
  const int m = static_cast<int>(graph.measurements.size());
  // Rotational connection Laplacian L(G^rho), eq. (14).
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(d * n, d * n);
  // Incidence A (n x m), Omega^{1/2}, T (m x dn), eqs. (16)-(19).
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, m);
  Eigen::MatrixXd sqrt_omega = Eigen::MatrixXd::Zero(m, m);
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(m, d * n);
  for (int k = 0; k < m; ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
    L.block(d * e.i, d * e.i, d, d) += e.kappa * I;
    L.block(d * e.j, d * e.j, d, d) += e.kappa * I;
    L.block(d * e.i, d * e.j, d, d) -= e.kappa * e.R;
    L.block(d * e.j, d * e.i, d, d) -= e.kappa * e.R.transpose();
    A(e.i, k) = -1;
    A(e.j, k) = 1;
    sqrt_omega(k, k) = std::sqrt(e.tau);
    T.block(k, d * e.i, 1, d) = -e.t.transpose();
  }
  // Pi = I - B^+ B for B = A Omega^{1/2}: the projector onto ker(B).
  const Eigen::MatrixXd B = A * sqrt_omega;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(B, Eigen::ComputeFullV);
  const Eigen::VectorXd s = svd.singularValues();
  const double tol = 1e-10 * s(0);
  int rank = 0;
  while (rank < s.size() && s(rank) > tol) ++rank;
  const Eigen::MatrixXd Vr = svd.matrixV().leftCols(rank);
  const Eigen::MatrixXd Pi =
      Eigen::MatrixXd::Identity(m, m) - Vr * Vr.transpose();
  const Eigen::MatrixXd W = sqrt_omega * T;
  Eigen::MatrixXd Q = L + W.transpose() * Pi * W;
  return 0.5 * (Q + Q.transpose());
}

double DenseMinEigenvalue(const Eigen::MatrixXd& S,
                          Eigen::VectorXd* eigenvector) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
  if (eigenvector) *eigenvector = eig.eigenvectors().col(0);
  return eig.eigenvalues()(0);
}

Eigen::MatrixXd BlockDiagonalToDense(const Eigen::MatrixXd& Lambda, int d) {
  const int dn = static_cast<int>(Lambda.cols());
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(dn, dn);
  for (int i = 0; i < dn / d; ++i) {
    out.block(d * i, d * i, d, d) = Lambda.middleCols(d * i, d);
  }
  return out;
}

}  // namespace ceres_sesync::test_util
