#include "ceres_sesync/robust_solver.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include "Eigen/Eigenvalues"
#include "Eigen/Geometry"
#include "ceres_sesync/internal/chi_square.h"
#include "ceres_sesync/internal/measurement_weights.h"
#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/staircase.h"
#include "ceres_sesync/stiefel_manifold.h"

namespace ceres_sesync {
namespace {

using Clock = std::chrono::steady_clock;
using internal::MeasurementWeights;
constexpr double kPi = 3.14159265358979323846;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// The TLS surrogate rho_mu(r^2) and its Black-Rangarajan weight (Yang et
// al. 2020, eqs. for the TLS case), both continuous in r^2.
double TlsSurrogate(double r2, double mu, double c2) {
  if (r2 <= mu / (mu + 1) * c2) return r2;
  if (r2 >= (mu + 1) / mu * c2) return c2;
  return 2 * std::sqrt(c2 * r2 * mu * (mu + 1)) - mu * (c2 + r2);
}

double TlsWeight(double r2, double mu, double c2) {
  if (r2 <= mu / (mu + 1) * c2) return 1;
  if (r2 >= (mu + 1) / mu * c2) return 0;
  return std::clamp(std::sqrt(c2 * mu * (mu + 1) / r2) - mu, 0.0, 1.0);
}

// Degrees of freedom of term k's f_k under the noise model: an edge
// d(d+1)/2, a landmark measurement d, a prior d(d-1)/2 for its rotation
// plus d for its position.
int TermDegreesOfFreedom(const PoseGraph& graph, size_t k) {
  const int d = graph.dimension;
  const size_t m = graph.measurements.size();
  if (k < m) return d * (d + 1) / 2;
  if (k < internal::PriorTerm(graph, 0)) return d;
  const PosePrior& p = graph.priors[k - internal::PriorTerm(graph, 0)];
  return (p.has_rotation() ? d * (d - 1) / 2 : 0) + (p.has_position() ? d : 0);
}

double RotationAngle(const Eigen::MatrixXd& M) {
  if (M.rows() == 2) return std::abs(std::atan2(M(1, 0), M(0, 0)));
  const Eigen::Matrix3d R = M;
  return Eigen::AngleAxisd(Eigen::Quaterniond(R).normalized()).angle();
}

// Y without its negligible directions: with Y = U S V^T, the top k rows of
// U^T Y, k the number of singular values above `tolerance` times the
// largest (at least min_rank), each block projected back to St(d, k). A
// warm start that keeps what the previous solve found but not the rank its
// staircase needed for a problem that is no longer there.
Eigen::MatrixXd ReduceRank(const Eigen::MatrixXd& Y, int d, int min_rank,
                           double tolerance) {
  const int r = static_cast<int>(Y.rows());
  if (r <= min_rank) return Y;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> gram(Y * Y.transpose());
  const Eigen::VectorXd& lambda = gram.eigenvalues();  // Ascending.
  int k = 0;
  while (k < r && lambda[r - 1 - k] > tolerance * tolerance * lambda[r - 1])
    ++k;
  k = std::max(k + 1, min_rank);
  if (k >= r) return Y;
  const Eigen::MatrixXd X = gram.eigenvectors().rightCols(k).transpose() * Y;
  Eigen::MatrixXd out;
  ProjectToStiefelProduct(X, d, &out);
  return out;
}

// Singular values below this fraction of the largest are dropped from the
// warm start (their directions change F by ~1e-6 of it).
constexpr double kRankTolerance = 1e-3;

// A landmark all of whose observations have weight 0 (or are rejected) is
// free: its position no longer depends on the rest. One observation alone
// is fit exactly (f_k = 0 wherever the rest is: the landmark is placed at
// it), and as a leaf of the translational graph it changes nothing else,
// so TLS keeps one of them at no cost. Sets `values` (weights, or
// accepted flags) of the observation with the smallest f_k of every such
// landmark to `one`.
template <typename T>
void KeepLandmarksObserved(const PoseGraph& graph, const std::vector<double>& f,
                           std::vector<T>* values, T one) {
  const size_t m = graph.measurements.size();
  std::vector<int> best(graph.num_landmarks, -1);
  std::vector<char> observed(graph.num_landmarks, 0);
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    const int l = graph.landmark_measurements[q].l;
    if ((*values)[m + q] > 0) observed[l] = 1;
    if (best[l] < 0 || f[m + q] < f[m + best[l]]) best[l] = static_cast<int>(q);
  }
  for (int l = 0; l < graph.num_landmarks; ++l) {
    if (!observed[l] && best[l] >= 0) (*values)[m + best[l]] = one;
  }
}

// The consistency rounds' choice for the landmark measurements, at the
// poses of x: each landmark placed alone where the TLS cost of its
// observations, sum_q min(f_q, c_q^2), is lowest among its current position
// and the positions its observations imply (t_i + R_i z_q, where f_q = 0),
// the current one on ties; then accepted iff f_q <= c_q^2 there. At the
// current position this is the rule for every other term. It moves a
// landmark that GNC left at a minority of its observations (wrong
// associations outnumber the true ones of a landmark seen by few poses,
// and one of them, fit exactly, can hold it) to a larger consistent group.
// Lowers the TLS cost at the poses of x, like the rule itself.
void LandmarkConsensus(const PoseGraph& graph, const Solution& x,
                       const std::vector<double>& c2,
                       std::vector<char>* accepted) {
  const size_t m = graph.measurements.size();
  std::vector<std::vector<int>> observations(graph.num_landmarks);
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    observations[graph.landmark_measurements[q].l].push_back(
        static_cast<int>(q));
  }
  std::vector<Eigen::VectorXd> implied;  // t_i + R_i z_q.
  for (int l = 0; l < graph.num_landmarks; ++l) {
    const std::vector<int>& obs = observations[l];
    implied.clear();
    for (int q : obs) {
      const LandmarkMeasurement& o = graph.landmark_measurements[q];
      implied.push_back(x.poses[o.i].t + x.poses[o.i].R * o.z);
    }
    auto tls = [&](const Eigen::VectorXd& p) {
      double cost = 0;
      for (size_t a = 0; a < obs.size(); ++a) {
        const double f = graph.landmark_measurements[obs[a]].nu *
                         (p - implied[a]).squaredNorm();
        cost += std::min(f, c2[m + obs[a]]);
      }
      return cost;
    };
    const Eigen::VectorXd* best = &x.landmarks[l];
    double best_cost = tls(*best);
    for (const Eigen::VectorXd& p : implied) {
      const double cost = tls(p);
      if (cost < best_cost) {
        best_cost = cost;
        best = &p;
      }
    }
    for (size_t a = 0; a < obs.size(); ++a) {
      const double f = graph.landmark_measurements[obs[a]].nu *
                       (*best - implied[a]).squaredNorm();
      (*accepted)[m + obs[a]] = f <= c2[m + obs[a]];
    }
  }
}

bool Binary(const MeasurementWeights& w, double tolerance) {
  return std::all_of(w.begin(), w.end(),
                     [&](double x) { return std::min(x, 1 - x) <= tolerance; });
}

// Verdicts, counts and diagnostics at `x` for the final `weights` and the
// rounded inlier set `accepted` (one per term), with thresholds `c2`.
void FillEdges(const PoseGraph& graph, const Solution& x,
               const MeasurementWeights& weights,
               const std::vector<char>& known,
               const std::vector<char>& accepted, const std::vector<double>& c2,
               RobustSolverSummary* s) {
  using Kind = RobustSolverSummary::Edge::Kind;
  const Poses& poses = x.poses;
  const size_t m = graph.measurements.size();
  const size_t prior_begin = internal::PriorTerm(graph, 0);
  const std::vector<double> f = TermCosts(graph, x);
  s->edges.assign(f.size(), {});
  s->outlier_edges.clear();
  s->outlier_landmark_measurements.clear();
  s->outlier_priors.clear();
  s->num_inliers = s->num_outliers = 0;
  s->num_rejected_within_threshold = s->num_accepted_beyond_threshold = 0;
  auto pose_id = [&](int i) -> int64_t {
    return graph.vertex_ids.empty() ? i : graph.vertex_ids[i];
  };
  for (size_t k = 0; k < f.size(); ++k) {
    RobustSolverSummary::Edge& edge = s->edges[k];
    if (k < m) {
      const RelativePoseMeasurement& e = graph.measurements[k];
      const Pose& a = poses[e.i];
      const Pose& b = poses[e.j];
      edge.index = static_cast<int>(k);
      edge.vertex_i = pose_id(e.i);
      edge.vertex_j = pose_id(e.j);
      edge.rotation_residual_deg =
          RotationAngle(e.R.transpose() * a.R.transpose() * b.R) * (180 / kPi);
      edge.translation_residual = (b.t - a.t - a.R * e.t).norm();
    } else if (k < prior_begin) {
      const LandmarkMeasurement& o = graph.landmark_measurements[k - m];
      const Pose& a = poses[o.i];
      edge.kind = Kind::kLandmark;
      edge.index = static_cast<int>(k - m);
      edge.vertex_i = pose_id(o.i);
      edge.vertex_j =
          graph.landmark_ids.empty() ? o.l : graph.landmark_ids[o.l];
      edge.translation_residual = (x.landmarks[o.l] - a.t - a.R * o.z).norm();
    } else {
      const PosePrior& p = graph.priors[k - prior_begin];
      const Pose& a = poses[p.i];
      edge.kind = Kind::kPrior;
      edge.index = static_cast<int>(k - prior_begin);
      edge.vertex_i = edge.vertex_j = pose_id(p.i);
      if (p.has_rotation()) {
        edge.rotation_residual_deg =
            RotationAngle(p.R.transpose() * a.R) * (180 / kPi);
      }
      if (p.has_position()) edge.translation_residual = (a.t - p.t).norm();
    }
    edge.weight = weights.empty() ? 1.0 : weights[k];
    edge.inlier = accepted[k];
    edge.known_inlier = known[k];
    edge.cost = f[k];
    edge.threshold = c2[k];
    if (edge.inlier) {
      ++s->num_inliers;
      if (!edge.known_inlier && f[k] > c2[k]) {
        ++s->num_accepted_beyond_threshold;
      }
    } else {
      ++s->num_outliers;
      (edge.kind == Kind::kMeasurement ? s->outlier_edges
       : edge.kind == Kind::kLandmark  ? s->outlier_landmark_measurements
                                       : s->outlier_priors)
          .push_back(edge.index);
      if (f[k] <= c2[k]) ++s->num_rejected_within_threshold;
    }
  }
}

// The weighted problem GNC solves next: a Staircase over the measurements
// of its sparsity pattern. Re-weighting keeps the pattern (values only,
// symbolic analyses reused: Staircase::Reweight) while it holds every
// positively weighted measurement and few zero-weight ones. Otherwise the
// problem is rebuilt on the subgraph of positive weights: a zero-weight
// measurement contributes nothing but fill, and random wrong loop closures
// fill the factors badly (intel with 50% of its closures wrong: 9x the
// Cholesky entries of the clean graph's factor, city10000 57x).
class WeightedProblem {
 public:
  // Rebuild when more than this fraction of the pattern has weight 0.
  static constexpr double kShedFraction = 0.01;

  WeightedProblem(const PoseGraph& graph, const SolverOptions& options)
      : graph_(graph), options_(options) {}

  // The first problem: the whole graph, every weight 1.
  void Start(Clock::time_point start) {
    staircase_ = std::make_unique<internal::Staircase>(graph_, options_,
                                                       &summary_, start);
  }

  // The problem with `weights` (one per term of the graph) for the next
  // solve; false with a message if they leave the graph disconnected. The
  // first call builds the problem unless Start() did.
  bool SetWeights(const MeasurementWeights& weights, std::string* message) {
    if (!internal::CheckMeasurementWeights(graph_, weights, message)) {
      return false;
    }
    const size_t m = weights.size();
    if (staircase_ == nullptr) return Rebuild(weights, message);
    const size_t pattern = index_.empty() ? m : index_.size();
    size_t positive = 0, zero_in_pattern = 0;
    for (double w : weights) positive += w > 0;
    MeasurementWeights restricted(pattern);
    for (size_t q = 0; q < pattern; ++q) {
      restricted[q] = weights[index_.empty() ? q : index_[q]];
      zero_in_pattern += restricted[q] == 0;
    }
    const bool covers = pattern - zero_in_pattern == positive;
    if (covers && zero_in_pattern <= kShedFraction * pattern) {
      if (staircase_->Reweight(std::move(restricted))) return true;
      *message = summary_.message;
      return false;
    }
    ++rebuilds_;
    return Rebuild(weights, message);
  }

  internal::Staircase& staircase() { return *staircase_; }
  const SolverSummary& summary() const { return summary_; }
  int rebuilds() const { return rebuilds_; }

 private:
  // Builds the problem on the subgraph of positive weights (the same poses
  // and landmarks: CheckMeasurementWeights keeps every landmark observed).
  bool Rebuild(const MeasurementWeights& weights, std::string* message) {
    const size_t m = graph_.measurements.size();
    const size_t prior_begin = internal::PriorTerm(graph_, 0);
    staircase_.reset();  // First: it refers to the subgraph.
    if (sub_.num_poses == 0) {
      sub_ = graph_;  // Poses, ids, initial poses and FIX: Round()'s gauge.
    }
    sub_.measurements.clear();
    sub_.landmark_measurements.clear();
    sub_.priors.clear();
    index_.clear();
    MeasurementWeights sub_weights;
    bool all_one = true;
    for (size_t k = 0; k < weights.size(); ++k) {
      if (!(weights[k] > 0)) continue;
      index_.push_back(static_cast<int>(k));
      if (k < m) {
        sub_.measurements.push_back(graph_.measurements[k]);
      } else if (k < prior_begin) {
        sub_.landmark_measurements.push_back(
            graph_.landmark_measurements[k - m]);
      } else {
        sub_.priors.push_back(graph_.priors[k - prior_begin]);
      }
      sub_weights.push_back(weights[k]);
      all_one = all_one && weights[k] == 1;
    }
    if (all_one) sub_weights.clear();
    staircase_ = std::make_unique<internal::Staircase>(
        sub_, options_, &summary_, Clock::now(), std::move(sub_weights));
    if (staircase_->ok()) return true;
    *message = summary_.message;
    return false;
  }

  const PoseGraph& graph_;
  const SolverOptions& options_;
  PoseGraph sub_;           // The pattern's terms, once rebuilt.
  std::vector<int> index_;  // Pattern term -> graph's (empty: all).
  std::unique_ptr<internal::Staircase> staircase_;
  SolverSummary summary_;
  int rebuilds_ = 0;
};

std::string CheckOptions(const RobustSolverOptions& o, int d) {
  if (!std::isfinite(o.inlier_threshold)) {
    return "inlier_threshold must be finite";
  }
  if (o.inlier_threshold <= 0 &&
      !(o.inlier_probability > 0 && o.inlier_probability < 1)) {
    return "inlier_probability must be in (0, 1)";
  }
  if (!(o.mu_step > 1) || !std::isfinite(o.mu_step)) {
    return "mu_step must be a finite number > 1";
  }
  if (o.max_iterations < 0) return "max_iterations must be >= 0";
  if (!(o.max_time_s >= 0) || !std::isfinite(o.max_time_s)) {
    return "max_time_s must be a finite number >= 0";
  }
  if (o.initial_max_rank < 0) return "initial_max_rank must be >= 0";
  if (o.gnc_max_rank < 0) return "gnc_max_rank must be >= 0";
  if (!(o.gnc_relative_gradient_tolerance >= 0) ||
      !std::isfinite(o.gnc_relative_gradient_tolerance)) {
    return "gnc_relative_gradient_tolerance must be a finite number >= 0";
  }
  if (!(o.gnc_relative_decrease_tolerance >= 0 &&
        o.gnc_relative_decrease_tolerance < 1)) {
    return "gnc_relative_decrease_tolerance must be in [0, 1)";
  }
  if (o.gnc_threshold_fractions.empty()) {
    return "gnc_threshold_fractions must not be empty";
  }
  for (double fraction : o.gnc_threshold_fractions) {
    if (!(fraction > 0 && fraction <= 1)) {
      return "gnc_threshold_fractions must be in (0, 1]";
    }
  }
  if (o.max_consistency_rounds < 0) {
    return "max_consistency_rounds must be >= 0";
  }
  if (o.max_removal_trials < 0) {
    return "max_removal_trials must be >= 0";
  }
  if (o.max_readmission_trials < 0) {
    return "max_readmission_trials must be >= 0";
  }
  if (!(o.readmission_max_cost >= 0) ||
      !std::isfinite(o.readmission_max_cost)) {
    return "readmission_max_cost must be a finite number >= 0";
  }
  if (!(o.readmission_min_scale >= 0 && o.readmission_min_scale <= 1)) {
    return "readmission_min_scale must be in [0, 1]";
  }
  if (!(o.weight_tolerance >= 0 && o.weight_tolerance < 0.5)) {
    return "weight_tolerance must be in [0, 0.5)";
  }
  if (!(o.relative_cost_tolerance >= 0)) {
    return "relative_cost_tolerance must be >= 0";
  }
  if (d != 2 && d != 3) return "dimension must be 2 or 3";
  return "";
}

}  // namespace

bool IsOdometry(const RelativePoseMeasurement& measurement) {
  return std::abs(measurement.j - measurement.i) == 1;
}

double InlierThreshold(const RobustSolverOptions& options, int dimension) {
  if (!CheckOptions(options, dimension).empty()) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  if (options.inlier_threshold > 0) return options.inlier_threshold;
  return internal::ChiSquareQuantile(options.inlier_probability,
                                     dimension * (dimension + 1) / 2);
}

std::vector<double> TermCosts(const PoseGraph& graph, const Solution& x) {
  const Poses& poses = x.poses;
  std::vector<double> f(internal::NumWeightedTerms(graph));
  const size_t m = graph.measurements.size();
  for (size_t k = 0; k < m; ++k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    f[k] = e.kappa * (b.R - a.R * e.R).squaredNorm() +
           e.tau * (b.t - a.t - a.R * e.t).squaredNorm();
  }
  for (size_t q = 0; q < graph.landmark_measurements.size(); ++q) {
    const LandmarkMeasurement& o = graph.landmark_measurements[q];
    const Pose& a = poses[o.i];
    f[m + q] = o.nu * (x.landmarks[o.l] - a.t - a.R * o.z).squaredNorm();
  }
  for (size_t q = 0; q < graph.priors.size(); ++q) {
    const PosePrior& p = graph.priors[q];
    const Pose& a = poses[p.i];
    double& cost = f[internal::PriorTerm(graph, q)];
    if (p.has_rotation()) cost += p.kappa * (a.R - p.R).squaredNorm();
    if (p.has_position()) cost += p.tau * (a.t - p.t).squaredNorm();
  }
  return f;
}

std::vector<double> TermThresholds(const RobustSolverOptions& options,
                                   const PoseGraph& graph) {
  const int d = graph.dimension;
  if (!CheckOptions(options, d).empty()) return {};
  // The quantile once per number of degrees of freedom (a bisection each).
  std::vector<double> by_dofs(d * (d + 1) / 2 + 1, options.inlier_threshold);
  if (options.inlier_threshold <= 0) {
    for (size_t k = 1; k < by_dofs.size(); ++k) {
      by_dofs[k] = internal::ChiSquareQuantile(options.inlier_probability,
                                               static_cast<int>(k));
    }
  }
  std::vector<double> c2(internal::NumWeightedTerms(graph));
  for (size_t k = 0; k < c2.size(); ++k) {
    c2[k] = by_dofs[TermDegreesOfFreedom(graph, k)];
  }
  return c2;
}

namespace {

// One GNC schedule from the first solve's result, with its final inlier
// problem and consistency rounds.
struct GncRun {
  RobustSolverSummary::Run record;
  RobustSolverSummary::Status status = RobustSolverSummary::Status::kConverged;
  std::string message;
  Solution x;
  MeasurementWeights weights;
  std::vector<char> accepted;
  std::vector<RobustSolverSummary::Iteration> history;
  SolverSummary inlier_summary;
  bool weights_binary = false;
  // Seconds after the GNC steps: the inlier problem, the consistency rounds
  // and the re-admission trials.
  double inlier_time_s = 0;
  int pattern_rebuilds = 0;  // Of the run's problem.
};

// sum_k min(f_k, c_k^2) over the estimated terms plus f_k of the known
// inliers.
double TlsCost(const std::vector<double>& f, const std::vector<char>& known,
               const std::vector<double>& c2) {
  double cost = 0;
  for (size_t k = 0; k < f.size(); ++k) {
    cost += known[k] ? f[k] : std::min(f[k], c2[k]);
  }
  return cost;
}

}  // namespace

Poses SolveRobust(const PoseGraph& graph, const RobustSolverOptions& options,
                  RobustSolverSummary* summary) {
  Solution x;
  SolveRobust(graph, options, &x, summary);
  return std::move(x.poses);
}

void SolveRobust(const PoseGraph& graph, const RobustSolverOptions& options,
                 Solution* solution, RobustSolverSummary* summary) {
  const auto start = Clock::now();
  RobustSolverSummary& s = *summary;
  s = RobustSolverSummary();
  const int d = graph.dimension;
  const size_t m = graph.measurements.size();
  s.dimension = d;
  s.num_poses = graph.num_poses;
  s.num_measurements = static_cast<int>(m);
  s.num_landmark_measurements =
      static_cast<int>(graph.landmark_measurements.size());
  s.num_priors = static_cast<int>(graph.priors.size());
  auto finish = [&](RobustSolverSummary::Status status, Solution x) {
    s.status = status;
    s.total_time_s = Seconds(start);
    *solution = std::move(x);
  };
  s.message = CheckOptions(options, d);
  if (!s.message.empty()) {
    s.message = "robust solver options: " + s.message;
    return finish(RobustSolverSummary::Status::kInvalidInput, {});
  }
  s.inlier_threshold = InlierThreshold(options, d);
  // Every term's threshold c_k^2 (a relative pose measurement's is c^2),
  // and the loops' length: the number of terms.
  const size_t K = internal::NumWeightedTerms(graph);
  const std::vector<double> c2 = TermThresholds(options, graph);
  std::vector<int> dofs(K);
  for (size_t k = 0; k < K; ++k) dofs[k] = TermDegreesOfFreedom(graph, k);
  // The unknowns' degrees of freedom: d(d+1)/2 per pose and d per landmark,
  // less the gauge's d(d+1)/2 without priors; and the terms' in `set`.
  const long unknown_dofs =
      d * (d + 1) / 2 * (graph.num_poses - (graph.priors.empty() ? 1L : 0L)) +
      static_cast<long>(d) * graph.num_landmarks;
  auto accepted_dofs = [&](const std::vector<char>& set) {
    long sum = 0;
    for (size_t k = 0; k < K; ++k) sum += set[k] ? dofs[k] : 0;
    return sum;
  };

  // The first solve is Solve() itself up to initial_max_rank. GNC's
  // weighted solves then stop their local searches at
  // gnc_relative_gradient_tolerance or gnc_relative_decrease_tolerance, prove
  // their certificates in double only (they decide saddle escapes; no bound of
  // theirs is reported), climb to gnc_max_rank, with no certificate test
  // there, and round without refinement (gnc_refine_rounded_solution); each
  // final inlier problem is solved with the caller's options again.
  // The Staircase reads its options at every stage.
  SolverOptions first_options = options.solver_options;
  // The first solve and the GNC steps (below) run their descents to the
  // local solver's tests: their poses seed GNC, their bounds are not
  // reported.
  first_options.test_certificate_near_convergence = false;
  // Gives the next solve the time left (options.max_time_s) and says whether
  // any is left. solve_options.max_time_s is the caller's per-solve limit
  // or what remains of the whole, the smaller (the Staircase counts from the
  // re-weighting or rebuild that precedes each solve).
  auto budget = [&](SolverOptions& solve_options) {
    solve_options.max_time_s = options.solver_options.max_time_s;
    if (options.max_time_s <= 0) return true;
    const double left = options.max_time_s - Seconds(start);
    if (left <= 0) return false;
    if (solve_options.max_time_s <= 0 || left < solve_options.max_time_s) {
      solve_options.max_time_s = left;
    }
    return true;
  };
  budget(first_options);
  const int r0 = options.solver_options.initial_rank > 0
                     ? options.solver_options.initial_rank
                     : d + 2;
  first_options.max_rank = std::min(options.solver_options.max_rank,
                                    std::max(options.initial_max_rank, r0));
  WeightedProblem first_problem(graph, first_options);
  first_problem.Start(start);
  auto invalid = [&]() {
    s.message = first_problem.summary().message;
    s.initial_summary = first_problem.summary();
    return finish(RobustSolverSummary::Status::kInvalidInput, {});
  };
  if (!first_problem.staircase().ok()) return invalid();
  std::vector<char> known(K, 0);  // Landmark measurements, priors: never.
  for (size_t k = 0; k < m; ++k) {
    known[k] =
        options.known_inliers == RobustSolverOptions::KnownInliers::kOdometry &&
        IsOdometry(graph.measurements[k]);
  }
  if (first_problem.staircase().trivial()) {  // One pose, no measurements.
    s.initial_summary = s.inlier_summary = first_problem.summary();
    s.weights_binary = true;
    return finish(RobustSolverSummary::Status::kConverged,
                  first_problem.staircase().Trivial());
  }
  Eigen::MatrixXd Y0;
  if (!first_problem.staircase().Initialize(nullptr, &Y0)) return invalid();
  first_problem.staircase().Run(&Y0);
  Solution x0 = first_problem.staircase().Round(Y0);
  // Whether every estimated term has f_k <= fraction * c_k^2.
  auto within = [&](const std::vector<double>& f, double fraction) {
    for (size_t k = 0; k < K; ++k) {
      if (!known[k] && !(f[k] <= fraction * c2[k])) return false;
    }
    return true;
  };
  // The estimated term with the largest f_k / c_k^2 (-1: none), and the mu
  // at which GNC starts at thresholds fraction * c^2 from f: GNC's
  // g^2 / (2 max f_k - g^2) in the units of that term (Yang et al.'s
  // surrogate is homogeneous in (f_k, c_k^2)).
  auto worst = [&](const std::vector<double>& f) {
    int w = -1;
    for (size_t k = 0; k < K; ++k) {
      if (!known[k] && (w < 0 || f[k] / c2[k] > f[w] / c2[w])) {
        w = static_cast<int>(k);
      }
    }
    return w;
  };
  auto initial_mu = [&](const std::vector<double>& f, double fraction) {
    const int w = worst(f);
    const double g2 = fraction * c2[w];
    return g2 / (2 * f[w] - g2);
  };
  std::vector<double> f0 = TermCosts(graph, x0);
  first_options.max_rank = options.solver_options.max_rank;
  if (within(f0, 1) &&
      first_problem.summary().status ==
          SolverSummary::Status::kMaxRankReached &&
      first_problem.summary().final_rank < first_options.max_rank &&
      budget(first_options)) {
    // Every measurement fits: perhaps this is the inlier problem. The
    // staircase continues where a rank cap stopped it (as Solve() would).
    first_problem.staircase().Run(&Y0);
    x0 = first_problem.staircase().Round(Y0);
    f0 = TermCosts(graph, x0);
  }
  first_problem.staircase().Report(Y0, x0);
  s.initial_summary = first_problem.summary();
  s.initial_time_s = Seconds(start);
  if (within(f0, 1) && first_problem.summary().certified()) {
    // Every measurement fits the certified optimum of the whole problem:
    // accepting all of them is TLS-consistent, and this is the inlier
    // problem. (Uncertified, e.g. an inexact relaxation because a wrong
    // closure bends the map until it fits, GNC runs at the thresholds
    // below the largest f_k.)
    s.inlier_summary = first_problem.summary();
    s.total_time_s = Seconds(start);
    s.weights_binary = true;
    FillEdges(graph, x0, MeasurementWeights(K, 1.0), known,
              std::vector<char>(K, 1), c2, &s);
    return finish(RobustSolverSummary::Status::kConverged, std::move(x0));
  }
  if (!within(f0, options.gnc_threshold_fractions[0])) {
    s.initial_mu = initial_mu(f0, options.gnc_threshold_fractions[0]);
  }

  // GNC (Yang et al. 2020, Algorithm 1 with TLS) as in GTSAM's
  // GncOptimizer, from the first solve, at GNC threshold g2: weights from
  // the last estimate, weighted solve warm-started from the last factor
  // (its negligible directions dropped), mu update, convergence test; then
  // the accepted set's problem, certified, and the consistency rounds at c^2.
  // On `problem` (the first solve's or a problem of the run's own, built at
  // its first step) with `solve_options`, the options `problem` refers to,
  // and `base`, the caller's options as this run uses them.
  auto run_gnc = [&](double fraction, const SolverOptions& base,
                     SolverOptions& solve_options, WeightedProblem& problem,
                     const MeasurementWeights* start_set = nullptr) {
    const auto run_start = Clock::now();
    GncRun run;
    run.record.gnc_threshold = fraction * s.inlier_threshold;
    if (start_set == nullptr && within(f0, fraction)) {
      // Every TLS weight is 1 at any mu: GNC would solve the first problem
      // again. Its result stands for this run (consistent at c^2 >= g^2).
      run.x = x0;
      run.weights.assign(K, 1.0);
      run.accepted.assign(K, 1);
      run.weights_binary = true;
      run.inlier_summary = s.initial_summary;
      run.record.tls_cost = TlsCost(f0, known, c2);
      run.record.certified = run.inlier_summary.certified();
      run.record.time_s = Seconds(run_start);
      return run;
    }
    Eigen::MatrixXd Y = Y0;
    run.x = x0;
    std::vector<double> f = f0;
    run.weights.assign(K, 1.0);  // Of the last solved problem.
    bool reported = true;        // The first solve was reported.
    std::string message;
    auto disconnected = [&](const std::string& what) {
      run.status = RobustSolverSummary::Status::kInlierGraphDisconnected;
      run.message = what + message;
      run.record.time_s = Seconds(run_start);
      return run;
    };
    if (start_set != nullptr) {  // No GNC: its accepted set is given.
      run.weights = *start_set;
      run.status = RobustSolverSummary::Status::kConverged;
    } else {
      std::vector<double> g2(K);  // GNC's thresholds.
      for (size_t k = 0; k < K; ++k) g2[k] = fraction * c2[k];
      double mu = initial_mu(f0, fraction);
      auto surrogate = [&](double mu_k) {
        double cost = 0;
        for (size_t k = 0; k < K; ++k) {
          cost += known[k] ? f[k] : TlsSurrogate(f[k], mu_k, g2[k]);
        }
        return cost;
      };
      double previous_cost = surrogate(mu);
      run.status = RobustSolverSummary::Status::kMaxIterations;
      solve_options.proof_arithmetic = SolverOptions::ProofArithmetic::kDouble;
      solve_options.test_certificate_near_convergence = false;
      if (options.gnc_relative_gradient_tolerance > 0) {
        solve_options.relative_preconditioned_gradient_tolerance =
            options.gnc_relative_gradient_tolerance;
      }
      if (options.gnc_relative_decrease_tolerance > 0) {
        solve_options.relative_decrease_tolerance =
            options.gnc_relative_decrease_tolerance;
      }
      solve_options.refine_rounded_solution =
          options.gnc_refine_rounded_solution;
      solve_options.max_rank =
          std::min(options.solver_options.max_rank,
                   options.gnc_max_rank > 0 ? std::max(options.gnc_max_rank, r0)
                                            : r0 + 2);
      for (int it = 0; it < options.max_iterations; ++it) {
        if (!budget(solve_options)) {
          run.status = RobustSolverSummary::Status::kTimeLimit;
          break;
        }
        const auto step_start = Clock::now();
        MeasurementWeights next(K);
        for (size_t k = 0; k < K; ++k) {
          next[k] = known[k] ? 1.0 : TlsWeight(f[k], mu, g2[k]);
        }
        KeepLandmarksObserved(graph, f, &next, 1.0);
        if (!problem.SetWeights(next, &message)) {
          run.accepted.assign(K, 0);
          for (size_t k = 0; k < K; ++k) run.accepted[k] = next[k] > 0.5;
          run.weights = next;
          return disconnected("GNC step " + std::to_string(it + 1) + ": ");
        }
        run.weights = std::move(next);
        Y = ReduceRank(Y, d, r0, kRankTolerance);
        problem.staircase().Run(&Y, /*verify_at_max_rank=*/false);
        run.x = problem.staircase().Round(Y);
        reported = false;
        f = TermCosts(graph, run.x);
        const double cost = surrogate(mu);
        const SolverSummary& solve = problem.summary();
        RobustSolverSummary::Iteration record;
        record.mu = mu;
        record.surrogate_cost = cost;
        for (double w : run.weights) {
          record.num_zero_weights += w == 0;
          record.num_unit_weights += w == 1;
        }
        record.status = solve.status;
        record.rank = solve.final_rank;
        record.solver_iterations = solve.iterations;
        record.optimization_time_s = solve.optimization_time_s;
        record.verification_time_s = solve.verification_time_s;
        record.time_s = Seconds(step_start);
        run.history.push_back(record);
        run.record.iterations = it + 1;
        mu *= options.mu_step;
        if (Binary(run.weights, options.weight_tolerance) ||
            std::abs(cost - previous_cost) <=
                options.relative_cost_tolerance * previous_cost) {
          run.status = RobustSolverSummary::Status::kConverged;
          break;
        }
        previous_cost = cost;
      }
    }
    run.weights_binary = Binary(run.weights, options.weight_tolerance);
    const auto inlier_start = Clock::now();

    // The problem restricted to the accepted measurements (weights rounded
    // at 1/2), solved from the last factor with the caller's options (the
    // Staircase refers to solve_options, so it is restored in place).
    solve_options = base;
    run.accepted.assign(K, 0);
    for (size_t k = 0; k < K; ++k) run.accepted[k] = run.weights[k] > 0.5;
    KeepLandmarksObserved(graph, f, &run.accepted, char{1});
    auto record = [&]() {
      f = TermCosts(graph, run.x);
      run.record.tls_cost = TlsCost(f, known, c2);
      for (char a : run.accepted) run.record.num_outliers += !a;
      run.record.certified = run.inlier_summary.certified();
      run.record.time_s = Seconds(run_start);
      run.inlier_time_s = Seconds(inlier_start);
      return run;
    };
    if (run.status == RobustSolverSummary::Status::kTimeLimit ||
        !budget(solve_options)) {
      // Out of time: the last step's poses (the first solve's if none ran)
      // and its rounded weights; no inlier problem was solved, so its
      // summary proves nothing (the last step's is of a weighted problem).
      run.status = RobustSolverSummary::Status::kTimeLimit;
      run.message =
          "the time limit (max_time_s) ran out before the inlier problem "
          "was solved";
      SolverSummary& cut = run.inlier_summary;
      cut = SolverSummary();
      cut.status = SolverSummary::Status::kTimeLimit;
      cut.message = run.message;
      cut.dimension = d;
      cut.num_poses = graph.num_poses;
      cut.num_landmarks = graph.num_landmarks;
      const std::vector<double> costs = TermCosts(graph, run.x);
      for (size_t k = 0; k < K; ++k) {
        if (!run.accepted[k]) continue;
        ++(k < m                               ? cut.num_measurements
           : k < internal::PriorTerm(graph, 0) ? cut.num_landmark_measurements
                                               : cut.num_priors);
        cut.objective += costs[k];
      }
      cut.suboptimality_bound = cut.relative_suboptimality_bound = cut.eta =
          std::numeric_limits<double>::infinity();
      cut.proof_precision = "none";
      return record();
    }
    bool out_of_time = false;
    // The weights that restrict the problem to `set`.
    auto binary_weights = [&](const std::vector<char>& set) {
      MeasurementWeights binary(K);
      for (size_t k = 0; k < K; ++k) binary[k] = set[k] ? 1.0 : 0.0;
      return binary;
    };
    // Solves the problem restricted to `set` from *Y_io (updated in place).
    auto solve_set = [&](const std::vector<char>& set, Eigen::MatrixXd* Y_io,
                         Solution* x_out) {
      if (!problem.SetWeights(binary_weights(set), &message)) return false;
      *Y_io = ReduceRank(*Y_io, d, r0, kRankTolerance);
      problem.staircase().Run(Y_io);
      Solution x = problem.staircase().Round(*Y_io);
      problem.staircase().Continue(Y_io, &x);
      *x_out = std::move(x);
      reported = false;
      return true;
    };
    auto solve_accepted = [&]() { return solve_set(run.accepted, &Y, &run.x); };
    // Always a new solve, with the caller's options: the last GNC step
    // stopped at its own gradient tolerance and proved in double (with
    // max_iterations 0: the first solve stopped at initial_max_rank). From
    // its factor this costs about one verification.
    if (!solve_accepted()) {
      return disconnected("the accepted measurements: ");
    }
    // Consistency at c^2: accept exactly the measurements within it at the
    // inlier problem's optimum. Each change lowers the TLS cost (at fixed
    // poses the new set takes min(f_k, c^2) per measurement; the re-solve
    // lowers the accepted sum), so the rounds end.
    auto make_consistent = [&]() {
      for (int round = 0; round < options.max_consistency_rounds; ++round) {
        f = TermCosts(graph, run.x);
        std::vector<char> next(K);
        for (size_t k = 0; k < K; ++k) {
          next[k] = known[k] ? run.accepted[k] : f[k] <= c2[k];
        }
        LandmarkConsensus(graph, run.x, c2, &next);
        KeepLandmarksObserved(graph, f, &next, char{1});
        if (next == run.accepted) return true;
        if (!budget(solve_options)) {
          out_of_time = true;
          return true;
        }
        run.accepted = std::move(next);
        ++run.record.consistency_rounds;
        if (!solve_accepted()) {
          message =
              "consistency round " + std::to_string(round + 1) + ": " + message;
          return false;
        }
      }
      return true;
    };
    if (!make_consistent()) return disconnected("");
    // Re-admission trials: the rejected measurements with the smallest f_k
    // (within readmission_max_cost c^2), one at a time, each kept iff the
    // TLS cost at the optimum with it is lower and the accepted terms rise
    // by less than c^2 scaled by the variance factor
    // (readmission_min_scale). A rejected trial leaves the problem holding
    // it; the accepted set's optimum is solved again at the end (from its
    // factor: one more verification).
    std::vector<char> tried(K, 0);
    bool restore = false;
    // The accepted set's report, for a restore the time limit prevents.
    SolverSummary accepted_summary;
    auto report_accepted = [&]() {
      problem.staircase().Report(Y, run.x);
      reported = true;
      accepted_summary = problem.summary();
    };
    // (Only under a time limit: the report may tighten the proof in
    // double-double, which the final report does otherwise.)
    const bool snapshots = options.max_time_s > 0;
    if (snapshots &&
        (options.max_readmission_trials > 0 ||
         options.max_removal_trials > 0) &&
        !out_of_time) {
      report_accepted();
    }
    auto accepted_sum = [&](const std::vector<double>& costs,
                            const std::vector<char>& set) {
      double sum = 0;
      for (size_t k = 0; k < K; ++k) sum += set[k] ? costs[k] : 0.0;
      return sum;
    };
    // The accepted set's a-posteriori variance factor at its optimum (its
    // cost over its redundancy: the accepted terms' degrees of freedom
    // beyond the unknowns', d(d+1)/2 per measurement beyond a spanning tree
    // in a pose graph), clamped to [readmission_min_scale, 1].
    auto variance_scale = [&](double accepted_cost) {
      const double redundancy =
          static_cast<double>(accepted_dofs(run.accepted) - unknown_dofs);
      return redundancy > 0 ? std::clamp(accepted_cost / redundancy,
                                         options.readmission_min_scale, 1.0)
                            : 1.0;
    };
    for (int trial = 0; trial < options.max_readmission_trials; ++trial) {
      f = TermCosts(graph, run.x);
      const double accepted_cost = accepted_sum(f, run.accepted);
      const double scale = variance_scale(accepted_cost);
      int candidate = -1;
      for (size_t k = 0; k < K; ++k) {
        if (run.accepted[k] || known[k] || tried[k] ||
            !(f[k] <= options.readmission_max_cost * c2[k])) {
          continue;
        }
        if (candidate < 0 || f[k] / c2[k] < f[candidate] / c2[candidate]) {
          candidate = static_cast<int>(k);
        }
      }
      if (candidate < 0) break;
      if (!budget(solve_options)) {
        out_of_time = true;
        break;
      }
      tried[candidate] = 1;
      ++run.record.readmission_trials;
      std::vector<char> set = run.accepted;
      set[candidate] = 1;
      Eigen::MatrixXd Y_trial = Y;
      Solution x_trial;
      // Adding a measurement cannot disconnect the accepted graph.
      if (!solve_set(set, &Y_trial, &x_trial)) {
        return disconnected("re-admission trial: ");
      }
      const std::vector<double> f_trial = TermCosts(graph, x_trial);
      const double rise = accepted_sum(f_trial, set) - accepted_cost;
      // (A trial cut short by the time limit is not kept.)
      if (problem.summary().status != SolverSummary::Status::kTimeLimit &&
          TlsCost(f_trial, known, c2) < TlsCost(f, known, c2) &&
          rise < scale * c2[candidate]) {
        run.accepted = std::move(set);
        Y = std::move(Y_trial);
        run.x = std::move(x_trial);
        ++run.record.readmissions;
        restore = false;
        if (!make_consistent()) return disconnected("");
        if (snapshots) report_accepted();
      } else {
        restore = true;
      }
    }
    // Removal trials: the accepted terms (known inliers excepted) with the
    // largest f_k / c_k^2, one at a time: the accepted set without it is
    // solved and, if that lets a rejected term fit, made consistent (the
    // rounds may re-admit the candidate, and re-admit the terms that a wrong
    // measurement had bent the map away from), and kept iff the set
    // changed, the TLS cost is lower, the terms the rounds admitted fit as
    // the re-admission rule asks (the rise of the accepted cost from the set
    // without the candidate to the trial's result is below s sum c_k^2 over
    // them) and the new set's optimum is certified. A removal that would
    // disconnect the accepted graph is not tried.
    std::vector<char> removal_tried(K, 0);
    for (int trial = 0; trial < options.max_removal_trials && !out_of_time;
         ++trial) {
      f = TermCosts(graph, run.x);
      int candidate = -1;
      for (size_t k = 0; k < K; ++k) {
        if (!run.accepted[k] || known[k] || removal_tried[k]) continue;
        if (candidate < 0 || f[k] / c2[k] > f[candidate] / c2[candidate]) {
          candidate = static_cast<int>(k);
        }
      }
      if (candidate < 0) break;
      removal_tried[candidate] = 1;
      std::vector<char> set = run.accepted;
      set[candidate] = 0;
      std::string ignored;
      if (!internal::CheckMeasurementWeights(graph, binary_weights(set),
                                             &ignored)) {
        continue;
      }
      if (!budget(solve_options)) {
        out_of_time = true;
        break;
      }
      ++run.record.removal_trials;
      const double tls_before = TlsCost(f, known, c2);
      const double scale = variance_scale(accepted_sum(f, run.accepted));
      std::vector<char> saved_accepted = run.accepted;
      Eigen::MatrixXd saved_Y = Y;
      Solution saved_x = run.x;
      const int saved_rounds = run.record.consistency_rounds;
      SolverSummary saved_summary = accepted_summary;
      run.accepted = set;
      if (!solve_accepted()) {
        return disconnected("removal trial: ");
      }
      const std::vector<double> f_removed = TermCosts(graph, run.x);
      const double removed_cost = accepted_sum(f_removed, run.accepted);
      // The rounds run only if the removal lets a rejected term other than
      // the candidate fit within its c_k^2: otherwise they could only
      // reject more of the map the candidate held (many solves at scale for
      // a trial that is then rarely kept).
      bool admits = false;
      for (size_t k = 0; k < K && !admits; ++k) {
        admits = !set[k] && !known[k] && static_cast<int>(k) != candidate &&
                 f_removed[k] <= c2[k];
      }
      const bool consistent = admits && make_consistent();
      const std::vector<double> f_trial = TermCosts(graph, run.x);
      double admitted_c2 = 0;
      for (size_t k = 0; k < K; ++k) {
        if (run.accepted[k] && !set[k]) admitted_c2 += c2[k];
      }
      const double rise = accepted_sum(f_trial, run.accepted) - removed_cost;
      // (A trial cut short by the time limit is not kept.
      // Nor one whose rounds re-admitted the candidate and nothing else
      // changed: the same set, its cost lower only by round-off.)
      bool kept =
          consistent && !out_of_time &&
          problem.summary().status != SolverSummary::Status::kTimeLimit &&
          run.accepted != saved_accepted &&
          TlsCost(f_trial, known, c2) < tls_before &&
          rise <= scale * admitted_c2;
      if (kept) {
        // Only to a set whose optimum is certified: a wrong measurement
        // that bends the map to fit tends to leave the relaxation inexact.
        report_accepted();
        kept = problem.summary().certified();
      }
      if (kept) {
        ++run.record.removals;
        restore = false;
      } else {
        run.accepted = std::move(saved_accepted);
        Y = std::move(saved_Y);
        run.x = std::move(saved_x);
        run.record.consistency_rounds = saved_rounds;
        accepted_summary = std::move(saved_summary);
        message.clear();
        restore = true;
      }
    }
    if (restore && !budget(solve_options)) {
      // No time to solve the accepted set again: its last report stands
      // (run.x and Y are still its optimum).
      out_of_time = true;
      run.inlier_summary = accepted_summary;
    } else {
      if (restore && !solve_accepted()) {
        return disconnected("the accepted measurements: ");
      }
      if (!reported) problem.staircase().Report(Y, run.x);
      run.inlier_summary = problem.summary();
    }
    if (out_of_time) {
      run.message =
          "the time limit (max_time_s) stopped the consistency rounds or "
          "re-admission trials after GNC";
    }
    return record();
  };

  // Every schedule. The first run continues the first solve's problem; each
  // other run builds a problem of its own, so that no run depends on another
  // and they can go at once: with T >= 2 threads (solver_options.num_threads),
  // W = min(T, runs) runs at a time, ~T / W threads each. The kernels' results
  // do not depend on the thread count, so the runs' results are the same as
  // one after another; a run's problem (data matrices, factors) lives while
  // it runs. The calling thread runs the first run (SolverOptions::progress
  // is called from it alone); callbacks are serialized.
  // Landmark graphs: one more run, without GNC, from a start that the
  // least-squares fit of every term does not decide. The graph without its
  // landmarks (odometry, loop closures, priors) is solved robustly first;
  // at its poses each landmark is placed where most of its observations
  // agree (LandmarkConsensus); the terms accepted so are the run's set,
  // which the consistency rounds and re-admission trials then refine like
  // a GNC run's. False if the graph without landmarks cannot be solved
  // (e.g. its poses are connected only through landmarks).
  auto consensus_start = [&](const SolverOptions& base,
                             MeasurementWeights* set) {
    PoseGraph poses_only = graph;
    poses_only.num_landmarks = 0;
    poses_only.landmark_measurements.clear();
    poses_only.landmark_ids.clear();
    poses_only.index_of_landmark_id.clear();
    poses_only.initial_landmarks.clear();
    RobustSolverOptions nested = options;
    nested.solver_options = base;
    if (options.max_time_s > 0) {  // What is left of the whole limit.
      nested.max_time_s = options.max_time_s - Seconds(start);
      if (!(nested.max_time_s > 0)) return false;
    }
    RobustSolverSummary nested_summary;
    Solution nested_x;
    SolveRobust(poses_only, nested, &nested_x, &nested_summary);
    if (nested_summary.status != RobustSolverSummary::Status::kConverged &&
        nested_summary.status != RobustSolverSummary::Status::kMaxIterations) {
      return false;
    }
    std::vector<char> accepted(K, 0);
    for (size_t k = 0; k < m; ++k) accepted[k] = nested_summary.edges[k].inlier;
    for (size_t q = 0; q < graph.priors.size(); ++q) {
      accepted[internal::PriorTerm(graph, q)] =
          nested_summary.edges[m + q].inlier;
    }
    // Each landmark at its least-squares position, then moved by the
    // consensus.
    Solution x{std::move(nested_x.poses), {}};
    x.landmarks = OptimalLandmarkPositions(graph, x.poses);
    LandmarkConsensus(graph, x, c2, &accepted);
    KeepLandmarksObserved(graph, TermCosts(graph, x), &accepted, char{1});
    set->assign(accepted.begin(), accepted.end());
    return true;
  };

  const auto gnc_start = Clock::now();
  const size_t num_gnc_runs = options.gnc_threshold_fractions.size();
  const size_t num_runs = num_gnc_runs + (graph.num_landmarks > 0 ? 1 : 0);
  const int threads =
      internal::ResolveNumThreads(options.solver_options.num_threads);
  const int workers = static_cast<int>(
      std::min<size_t>(num_runs, static_cast<size_t>(threads)));
  std::vector<std::optional<GncRun>> runs(num_runs);  // Empty: not run.
  std::mutex callback_mutex;
  // Set when a run has thrown: the others stop at their next progress report
  // (every trust-region iteration) by throwing RunCancelled.
  std::atomic<bool> cancelled(false);
  struct RunCancelled {};
  auto execute = [&](size_t q, bool on_caller) {
    SolverOptions base = options.solver_options;
    if (workers > 1) {
      // (The calling thread takes what does not divide evenly.)
      base.num_threads =
          threads / workers + (on_caller ? threads % workers : 0);
      base.progress = [user = on_caller ? options.solver_options.progress
                                        : nullptr,
                       &cancelled](const SolverProgress& progress) {
        if (cancelled) throw RunCancelled();
        if (user) user(progress);
      };
      if (base.callback) {
        base.callback = [inner = options.solver_options.callback,
                         &callback_mutex](int rank, int iteration, double f,
                                          double gradient_norm,
                                          double trust_radius) {
          std::lock_guard<std::mutex> lock(callback_mutex);
          return inner(rank, iteration, f, gradient_norm, trust_radius);
        };
      }
    }
    // Out of time: the runs so far (at least one) compete.
    SolverOptions run_options = base;
    if (q > 0 && !budget(run_options)) return;
    std::optional<WeightedProblem> own;  // Built at the run's first step.
    if (q > 0) own.emplace(graph, run_options);
    if (q == 0) first_options = base;
    SolverOptions& solve_options = own ? run_options : first_options;
    WeightedProblem& problem = own ? *own : first_problem;
    GncRun run;
    if (q < num_gnc_runs) {
      run = run_gnc(options.gnc_threshold_fractions[q], base, solve_options,
                    problem);
    } else {
      MeasurementWeights start_set;
      if (!consensus_start(base, &start_set)) return;
      run = run_gnc(0, base, solve_options, problem, &start_set);
    }
    run.record.status = run.status;
    run.pattern_rebuilds = problem.rebuilds();
    runs[q] = std::move(run);
  };
  {
    // An exception (std::bad_alloc, a throwing callback, Python's Ctrl-C
    // through the progress hook) in any run reaches the caller once every
    // thread has stopped: the first one thrown; runs not yet started are
    // skipped, running ones stop at their next progress report.
    std::atomic<size_t> next(1);
    std::mutex error_mutex;
    std::exception_ptr error;
    auto guarded = [&](auto&& work) {
      try {
        work();
      } catch (const RunCancelled&) {
        // Another run's exception is on its way.
      } catch (...) {
        next = num_runs;  // No run starts after it.
        {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
        }
        cancelled = true;
      }
    };
    auto rest = [&](bool on_caller) {
      guarded([&] {
        for (size_t q; (q = next++) < num_runs;) execute(q, on_caller);
      });
    };
    std::vector<std::thread> helpers;
    for (int w = 1; w < workers; ++w) helpers.emplace_back(rest, false);
    guarded([&] { execute(0, true); });
    rest(true);
    for (std::thread& helper : helpers) helper.join();
    if (error) std::rethrow_exception(error);
  }
  // The lowest TLS cost at c^2 wins (the first on ties).
  GncRun best;
  int best_index = -1;
  for (size_t q = 0; q < num_runs; ++q) {
    if (!runs[q]) continue;
    GncRun& run = *runs[q];
    s.runs.push_back(run.record);
    s.pattern_rebuilds += run.pattern_rebuilds;
    // A finished run beats one the time limit cut short (its verdicts are
    // rounded weights, its inlier problem unsolved), which beats a
    // disconnected one; then the lower TLS cost wins.
    auto tier = [](RobustSolverSummary::Status status) {
      switch (status) {
        case RobustSolverSummary::Status::kInlierGraphDisconnected:
          return 0;
        case RobustSolverSummary::Status::kTimeLimit:
          return 1;
        default:
          return 2;
      }
    };
    const int run_tier = tier(run.status);
    const int best_tier = best_index < 0 ? -1 : tier(best.status);
    if (run_tier > best_tier || (run_tier == best_tier && run_tier > 0 &&
                                 run.record.tls_cost < best.record.tls_cost)) {
      best = std::move(run);
      best_index = static_cast<int>(q);
    }
  }
  s.gnc_time_s = Seconds(gnc_start);
  s.concurrent_runs = workers;
  s.inlier_time_s = best.inlier_time_s;
  s.selected_run = best_index;
  s.gnc_threshold = best.record.gnc_threshold;
  s.iterations = best.record.iterations;
  s.consistency_rounds = best.record.consistency_rounds;
  s.readmissions = best.record.readmissions;
  s.removals = best.record.removals;
  s.history = std::move(best.history);
  if (!s.history.empty()) s.initial_mu = s.history[0].mu;
  s.weights_binary = best.weights_binary;
  s.message = best.message;
  s.inlier_summary = best.inlier_summary;
  FillEdges(graph, best.x, best.weights, known, best.accepted, c2, &s);
  return finish(best.status, std::move(best.x));
}

const char* RobustSolverSummary::Edge::KindString() const {
  switch (kind) {
    case Kind::kLandmark:
      return "landmark";
    case Kind::kPrior:
      return "prior";
    case Kind::kMeasurement:
      break;
  }
  return "measurement";
}

bool RobustSolverSummary::certified() const {
  return (status == Status::kConverged || status == Status::kMaxIterations) &&
         inlier_summary.certified();
}

std::string RobustSolverSummary::StatusString() const {
  switch (status) {
    case Status::kConverged:
      return "CONVERGED";
    case Status::kMaxIterations:
      return "MAX_ITERATIONS";
    case Status::kInlierGraphDisconnected:
      return "INLIER_GRAPH_DISCONNECTED";
    case Status::kTimeLimit:
      return "TIME_LIMIT";
    case Status::kInvalidInput:
      return "INVALID_INPUT";
  }
  return "UNKNOWN";
}

std::string RobustSolverSummary::BriefReport() const {
  char buf[768];
  if (status == Status::kInvalidInput ||
      status == Status::kInlierGraphDisconnected ||
      status == Status::kTimeLimit) {
    std::snprintf(buf, sizeof(buf), "SE-Sync GNC-TLS: %s: %s",
                  StatusString().c_str(), message.c_str());
    return buf;
  }
  const bool other_terms = num_landmark_measurements > 0 || num_priors > 0;
  std::snprintf(
      buf, sizeof(buf),
      "SE-Sync GNC-TLS: %s after %d GNC iterations, %d of %d %s "
      "rejected (c^2 = %.4g); the optimum of the problem restricted to the "
      "accepted edges is %s: %s, F = %.10g, relative suboptimality <= "
      "%.2e, %.3f s",
      StatusString().c_str(), iterations, num_outliers,
      num_measurements + num_landmark_measurements + num_priors,
      other_terms ? "terms" : "measurements", inlier_threshold,
      inlier_summary.certified() ? "certified" : "NOT certified",
      inlier_summary.StatusString().c_str(), inlier_summary.objective,
      inlier_summary.relative_suboptimality_bound, total_time_s);
  return buf;
}

std::string RobustSolverSummary::FullReport(bool all_edges) const {
  std::string out;
  char buf[512];
  auto line = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof(buf), format, args...);
    out += buf;
  };
  out +=
      "\nSE-Sync GNC-TLS Robust Solver Report\n"
      "------------------------------------\n";
  line("%-34s %d\n", "Dimension", dimension);
  line("%-34s %d\n", "Poses", num_poses);
  line("%-34s %d\n", "Measurements", num_measurements);
  if (num_landmark_measurements > 0) {
    line("%-34s %d\n", "Landmark measurements", num_landmark_measurements);
  }
  if (num_priors > 0) line("%-34s %d\n", "Priors", num_priors);
  if (status == Status::kInvalidInput) {
    line("%-34s %s\n", "Error", message.c_str());
    return out;
  }
  line("%-34s %.6g\n", "TLS threshold c^2 on f_k", inlier_threshold);
  if (num_landmark_measurements > 0 || num_priors > 0) {
    out +=
        "  (landmark measurements and priors: the same quantile of their "
        "own degrees of freedom, column c_k^2 below)\n";
  }
  out += "\nFirst solve (all weights 1: plain SE-Sync)\n";
  line("  %s\n", initial_summary.BriefReport().c_str());
  out += "\nGraduated non-convexity: runs (the lowest TLS cost is kept)\n";
  line("  %4s %11s %24s %6s %6s %9s %18s %9s %9s\n", "run", "GNC c^2", "status",
       "iters", "rounds", "rejected", "TLS cost at c^2", "certified",
       "time [s]");
  for (size_t q = 0; q < runs.size(); ++q) {
    const Run& r = runs[q];
    RobustSolverSummary status_only;
    status_only.status = r.status;
    line("  %4d %11.4g %24s %6d %6d %9d %18.10g %9s %9.3f%s\n",
         static_cast<int>(q + 1), r.gnc_threshold,
         status_only.StatusString().c_str(), r.iterations, r.consistency_rounds,
         r.num_outliers, r.tls_cost, r.certified ? "yes" : "no", r.time_s,
         static_cast<int>(q) == selected_run ? "  <- selected" : "");
  }
  out += "\nSelected run's GNC steps\n";
  line("%-34s %.3e\n", "Initial mu", initial_mu);
  line("  %4s %11s %18s %8s %8s %5s %6s %9s %10s %9s %s\n", "iter", "mu",
       "surrogate", "w = 0", "w = 1", "rank", "iters", "opt. [s]", "verif. [s]",
       "time [s]", "solve");
  for (size_t t = 0; t < history.size(); ++t) {
    const Iteration& h = history[t];
    SolverSummary status_only;
    status_only.status = h.status;
    line("  %4d %11.4e %18.10g %8d %8d %5d %6d %9.4f %10.4f %9.4f %s\n",
         static_cast<int>(t + 1), h.mu, h.surrogate_cost, h.num_zero_weights,
         h.num_unit_weights, h.rank, h.solver_iterations, h.optimization_time_s,
         h.verification_time_s, h.time_s, status_only.StatusString().c_str());
  }
  line("%-34s %s\n", "Final weights binary", weights_binary ? "yes" : "no");
  line("%-34s %d accepted, %d rejected\n",
       num_landmark_measurements > 0 || num_priors > 0 ? "Terms"
                                                       : "Measurements",
       num_inliers, num_outliers);
  if (num_landmark_measurements > 0 || num_priors > 0) {
    line("%-34s %d measurements, %d landmark measurements, %d priors\n",
         "  rejected", static_cast<int>(outlier_edges.size()),
         static_cast<int>(outlier_landmark_measurements.size()),
         static_cast<int>(outlier_priors.size()));
  }
  line("%-34s %d\n", "Consistency rounds", consistency_rounds);
  const bool selected =
      selected_run >= 0 && selected_run < static_cast<int>(runs.size());
  line("%-34s %d (of %d trials)\n", "Re-admitted measurements", readmissions,
       selected ? runs[selected_run].readmission_trials : 0);
  line("%-34s %d (of %d trials)\n", "Removed measurements", removals,
       selected ? runs[selected_run].removal_trials : 0);
  line("%-34s %d rejected with f_k <= c^2, %d accepted with f_k > c^2\n",
       "Consistency at the result", num_rejected_within_threshold,
       num_accepted_beyond_threshold);
  line("%-34s %d\n", "Sparsity pattern rebuilds", pattern_rebuilds);
  if (status == Status::kInlierGraphDisconnected) {
    line("\n%-34s %s\n", "Status", StatusString().c_str());
    line("%-34s %s\n", "", message.c_str());
    return out;
  }
  if (status == Status::kTimeLimit) {
    out +=
        "\nProblem restricted to the accepted edges: not solved (the time "
        "limit ran out during GNC; the verdicts are the last step's rounded "
        "weights)\n";
  } else {
    out += "\nProblem restricted to the accepted edges";
    out += inlier_summary.FullReport();
  }
  out += "\nPer-edge verdicts";
  out += all_edges ? " (all)\n" : " (rejected)\n";
  line("  %11s %8s %10s %10s %9s %12s %12s %12s %9s %s\n", "kind", "index",
       "vertex i", "vertex j", "weight", "rot. [deg]", "trans.", "f_k", "c_k^2",
       "verdict");
  for (size_t k = 0; k < edges.size(); ++k) {
    const Edge& e = edges[k];
    if (!all_edges && e.inlier) continue;
    line("  %11s %8d %10lld %10lld %9.3g %12.4g %12.4g %12.4g %9.4g %s\n",
         e.KindString(), e.index, static_cast<long long>(e.vertex_i),
         static_cast<long long>(e.vertex_j), e.weight, e.rotation_residual_deg,
         e.translation_residual, e.cost, e.threshold,
         e.inlier ? (e.known_inlier ? "inlier (known)" : "inlier") : "outlier");
  }
  out += "\nTime (seconds)\n";
  line("%-34s %.4f\n", "  First solve", initial_time_s);
  line("%-34s %.4f\n",
       concurrent_runs > 1
           ? ("  GNC runs (" + std::to_string(concurrent_runs) + " at once)")
                 .c_str()
           : "  GNC runs",
       gnc_time_s);
  line("%-34s %.4f\n", "    selected run after GNC", inlier_time_s);
  line("%-34s %.4f\n", "Total", total_time_s);
  line("\n%-34s %s\n", "Status", StatusString().c_str());
  if (!message.empty()) line("%-34s %s\n", "", message.c_str());
  if (status != Status::kTimeLimit) {
    line(
        "%-34s the optimum of the problem restricted to the accepted edges "
        "is %s (%s); this is not a certificate for the TLS problem\n",
        "", inlier_summary.certified() ? "certified" : "not certified",
        inlier_summary.StatusString().c_str());
  }
  return out;
}

}  // namespace ceres_sesync
