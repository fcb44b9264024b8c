// Outlier benchmark (issue #13): the shared datasets with wrong loop
// closures added by the outlier generator (outlier_generator.h), solved by
//  - sesync:         plain SE-Sync, Solve() on the corrupted graph;
//  - gnc:            the robust solve, SolveRobust() (GNC-TLS, defaults);
//  - lm-huber-chordal, lm-cauchy-chordal, lm-huber-odometry,
//    lm-cauchy-odometry: Ceres Levenberg-Marquardt with ceres::HuberLoss /
//    CauchyLoss on every measurement (ceres_baseline.h; scale a^2 = the
//    robust solve's TLS threshold c^2) from the chordal initialization of
//    the corrupted graph or from dead reckoning along its odometry (edges
//    i, i+1: never corrupted).
//
//   outliers [--quick] [--datasets LIST] [--fractions LIST]
//            [--clustered_fractions LIST] [--cluster_size K] [--seeds N]
//            [--methods LIST] [--dataset_thresholds NAME=C2,...]
//            [--ceres_max_time S] [--sesync_max_time S] [--child_timeout S]
//            [--max_memory_gb G] [--num_threads N] [--out_dir DIR]
//            [--out_name NAME]
//
// The reference of each dataset is the clean graph's certified optimum x*
// (Solve(); a dataset whose clean solve is not certified is skipped). For
// every dataset, mode (random, clustered), fraction and seed (1..N), the
// corrupted graph is the clean one plus the generated outliers; every
// method's result x is compared with x* after gauge alignment (the rotation
// A = Proj_SO(d)(sum_i R*_i R_i^T), then b = mean_i(t*_i - A t_i)):
//  - max rotation error: max_i angle(R*_i^T A R_i), degrees;
//  - max translation error: max_i |A t_i + b - t*_i|;
//  - clean objective gap: (F_clean(x) - F*) / F*, F_clean the clean graph's
//    objective (12);
//  - outlier precision and recall: the rejected measurements (the robust
//    solve's verdicts; for the other methods those with f_k > c^2 at their
//    result, f_k the measurement's term of eq. (12)) against the added ones;
//    plain SE-Sync rejects nothing (precision undefined, recall 0);
//  - TLS vs truth: (T(x) - T(x*)) / T(x*), T the TLS cost sum_k min(f_k,
//    c^2) on the corrupted graph (odometry terms f_k in full, as the robust
//    solve's known inliers). Negative: the result beats the true labels at
//    this threshold, so a precision or recall shortfall is the TLS model's
//    at c^2 (e.g. manhattan's default c^2), not GNC missing its optimum;
//  - time: the method's wall time (Ceres: including its initialization).
// A run succeeds when precision and recall are >= 0.99 and the clean
// objective gap is <= 1e-6 (the goal). A method's breakdown point
// on a dataset and mode is the smallest fraction at which a seed fails;
// "holds to" is the largest fraction below it.
//
// Every run is a child process (fork: it inherits the clean graph and x*,
// generates its corrupted graph, runs one method) with --max_memory_gb of
// address space and --child_timeout seconds, so a run that needs too much
// (random outliers fill the sparse factorizations of every method: city10000
// with 50% of its closures wrong has 57x the Cholesky entries of the clean
// graph) fails alone and is reported.
//
// Output in --out_dir: NAME.csv (one row per run), NAME.md (tables, also
// printed); bench/plot_outliers.py draws NAME_random.png and
// NAME_clustered.png from the CSV.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Geometry"
#include "Eigen/SVD"
#include "bench/bench_util.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/outlier_generator.h"
#include "ceres_sesync/robust_solver.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(quick, false,
            "Smoke run (seconds): CSAIL and smallGrid3D, 30% random, one "
            "seed.");
DEFINE_string(datasets,
              "CSAIL,intel,manhattan,kitti_00,city10000,ais2klinik,"
              "tinyGrid3D,smallGrid3D,parking-garage,sphere2500,torus3D,"
              "cubicle",
              "Datasets (names of ../shared/datasets/NAME.g2o).");
DEFINE_string(data_dir, CERES_SESYNC_DATA_DIR, "Directory of the datasets.");
DEFINE_string(fractions, "0.1,0.3,0.5,0.7,0.9",
              "Random-mode outlier fractions (of the output's loop "
              "closures).");
DEFINE_string(clustered_fractions, "0.1,0.3,0.5",
              "Clustered-mode fractions (empty: no clustered runs).");
DEFINE_int32(cluster_size, 10, "Wrong closures per clustered group.");
DEFINE_int32(seeds, 3, "Seeds 1..N per dataset, mode and fraction.");
DEFINE_string(methods,
              "sesync,gnc,lm-huber-chordal,lm-cauchy-chordal,"
              "lm-huber-odometry,lm-cauchy-odometry",
              "Methods (see the top of bench/outliers.cc).");
DEFINE_string(dataset_thresholds, "",
              "Per-dataset TLS threshold c^2 overrides, NAME=C2,... (default: "
              "RobustSolverOptions' chi-square quantile everywhere).");
DEFINE_double(ceres_max_time, 60, "Ceres time limit per run, seconds.");
DEFINE_double(sesync_max_time, 0,
              "SE-Sync time limit per solve (0: none; the robust solve "
              "applies it to each weighted solve).");
DEFINE_double(child_timeout, 1800, "Seconds before a run is killed.");
DEFINE_double(max_memory_gb, 8, "Address-space limit per run, GiB.");
DEFINE_int32(num_threads, 1, "Threads of every method.");
DEFINE_string(out_dir, ".", "Directory for the outputs.");
DEFINE_string(out_name, "outliers", "Base name of the outputs.");

namespace ceres_sesync {
namespace {

using bench::Clock;
using bench::CsvField;
using bench::Fmt;
using bench::SecondsSince;

constexpr double kPi = 3.14159265358979323846;

// What a child reports through its pipe (plain data, fixed size).
struct RunResult {
  int m = 0, added = 0, rejected = 0, true_rejected = 0;
  double precision = NAN, recall = NAN;
  double max_rotation_error_deg = NAN, max_translation_error = NAN;
  double clean_objective = NAN, clean_gap = NAN;
  // TLS cost sum_k min(f_k, c^2) on the corrupted graph (odometry: f_k, as
  // known inliers) at the result and at the clean optimum x*.
  double tls_cost = NAN, truth_tls_cost = NAN;
  double time_s = NAN;
  int certified = 0, gnc_iterations = -1;
  char status[160] = {};
};

// (T(x) - T(x*)) / T(x*): see "TLS vs truth" at the top.
double TlsVsTruth(const RunResult& r) {
  return (r.tls_cost - r.truth_tls_cost) / r.truth_tls_cost;
}

void SetStatus(RunResult* r, const std::string& status) {
  std::snprintf(r->status, sizeof(r->status), "%s", status.c_str());
}

struct Dataset {
  std::string name;
  PoseGraph graph;
  Poses optimum;
  double objective = 0;
  double threshold = 0;  // c^2.
};

struct Cell {
  std::string dataset, mode, method;
  double fraction = 0;
  int seed = 0;
};

// Max rotation (degrees) and translation errors of x against x* after the
// gauge alignment described at the top.
void PoseErrors(const Poses& x, const Poses& ref, double* rotation_deg,
                double* translation) {
  const int n = static_cast<int>(ref.size()), d = ref[0].R.rows();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d, d);
  for (int i = 0; i < n; ++i) M += ref[i].R * x[i].R.transpose();
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(
      M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(d, d);
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) {
    S(d - 1, d - 1) = -1;
  }
  const Eigen::MatrixXd A = svd.matrixU() * S * svd.matrixV().transpose();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(d);
  for (int i = 0; i < n; ++i) b += ref[i].t - A * x[i].t;
  b /= n;
  *rotation_deg = *translation = 0;
  for (int i = 0; i < n; ++i) {
    const Eigen::MatrixXd E = ref[i].R.transpose() * A * x[i].R;
    double angle;
    if (d == 2) {
      angle = std::abs(std::atan2(E(1, 0), E(0, 0)));
    } else {
      const Eigen::Matrix3d E3 = E;
      angle = Eigen::AngleAxisd(Eigen::Quaterniond(E3).normalized()).angle();
    }
    *rotation_deg = std::max(*rotation_deg, angle * 180 / kPi);
    *translation = std::max(*translation, (A * x[i].t + b - ref[i].t).norm());
  }
}

// Dead reckoning along the odometry: the corrupted graph's edges i, i+1
// composed from the root (OdometryInitialization on them alone).
Poses OdometryOnly(const PoseGraph& graph) {
  PoseGraph chain = graph;
  chain.measurements.clear();
  for (const RelativePoseMeasurement& e : graph.measurements) {
    if (IsOdometry(e)) chain.measurements.push_back(e);
  }
  return OdometryInitialization(chain);
}

RunResult RunMethod(const Dataset& data, const Cell& cell) {
  RunResult r;
  OutlierOptions o;
  o.mode = cell.mode == "clustered" ? OutlierOptions::Mode::kClustered
                                    : OutlierOptions::Mode::kRandom;
  o.fraction = cell.fraction;
  o.cluster_size = FLAGS_cluster_size;
  o.seed = cell.seed;
  PoseGraph graph;
  std::vector<int> added;
  std::string error;
  if (!AddOutliers(data.graph, o, &graph, &added, &error)) {
    SetStatus(&r, "generate: " + error);
    return r;
  }
  const size_t m = graph.measurements.size();
  r.m = static_cast<int>(m);
  r.added = static_cast<int>(added.size());
  std::vector<char> rejected(m, 0);
  Poses x;
  const auto start = Clock::now();
  if (cell.method == "sesync") {
    SolverOptions options;
    options.num_threads = FLAGS_num_threads;
    options.max_time_s = FLAGS_sesync_max_time;
    SolverSummary s;
    x = Solve(graph, options, &s);
    r.time_s = SecondsSince(start);
    r.certified = s.certified();
    SetStatus(&r, s.StatusString());
  } else if (cell.method == "gnc") {
    RobustSolverOptions options;
    options.solver_options.num_threads = FLAGS_num_threads;
    options.solver_options.max_time_s = FLAGS_sesync_max_time;
    options.inlier_threshold = data.threshold;
    RobustSolverSummary s;
    x = SolveRobust(graph, options, &s);
    r.time_s = SecondsSince(start);
    r.certified = s.certified();
    r.gnc_iterations = s.iterations;
    for (int k : s.outlier_edges) rejected[k] = 1;
    SetStatus(&r, s.StatusString() + "/" + s.inlier_summary.StatusString());
    if (x.empty()) return r;
  } else {
    Poses initial;
    if (cell.method.find("chordal") != std::string::npos) {
      if (!ChordalInitialization(graph, &initial, &error)) {
        SetStatus(&r, "chordal: " + error);
        return r;
      }
    } else {
      initial = OdometryOnly(graph);
    }
    CeresBaselineOptions options;
    options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
    options.loss.type = cell.method.find("huber") != std::string::npos
                            ? CeresRobustLoss::Type::kHuber
                            : CeresRobustLoss::Type::kCauchy;
    options.loss.threshold = data.threshold;
    options.max_solver_time_s = FLAGS_ceres_max_time;
    options.num_threads = FLAGS_num_threads;
    CeresBaselineSummary summary;
    if (!SolveWithCeres(graph, initial, options, &x, &summary, &error)) {
      SetStatus(&r, "ceres: " + error);
      return r;
    }
    r.time_s = SecondsSince(start);
    SetStatus(&r, bench::CeresStatus(summary));
  }
  auto term = [&](const Poses& poses, size_t k) {
    const RelativePoseMeasurement& e = graph.measurements[k];
    const Pose& a = poses[e.i];
    const Pose& b = poses[e.j];
    return e.kappa * (b.R - a.R * e.R).squaredNorm() +
           e.tau * (b.t - a.t - a.R * e.t).squaredNorm();
  };
  auto tls = [&](const Poses& poses) {
    double cost = 0;
    for (size_t k = 0; k < m; ++k) {
      const double f = term(poses, k);
      cost +=
          IsOdometry(graph.measurements[k]) ? f : std::min(f, data.threshold);
    }
    return cost;
  };
  r.tls_cost = tls(x);
  r.truth_tls_cost = tls(data.optimum);
  if (cell.method != "gnc") {
    for (size_t k = 0; k < m && cell.method != "sesync"; ++k) {
      rejected[k] = term(x, k) > data.threshold;
    }
  }
  for (size_t k = 0; k < m; ++k) {
    if (!rejected[k]) continue;
    ++r.rejected;
    r.true_rejected += k >= data.graph.measurements.size();
  }
  // A graph too small for the fraction gets no outliers (tinyGrid3D at 10%:
  // 0 of its 3 closures); then rejecting nothing is exact, not undefined.
  r.precision = r.rejected > 0
                    ? static_cast<double>(r.true_rejected) / r.rejected
                    : (r.added == 0 ? 1.0 : NAN);
  r.recall = r.added > 0 ? static_cast<double>(r.true_rejected) / r.added : 1.0;
  PoseErrors(x, data.optimum, &r.max_rotation_error_deg,
             &r.max_translation_error);
  r.clean_objective = EvaluateObjective(data.graph, x);
  r.clean_gap = (r.clean_objective - data.objective) / data.objective;
  return r;
}

bool RunInChild(const Dataset& data, const Cell& cell, RunResult* result) {
  *result = RunResult();
  std::string failure;
  if (bench::RunInChildProcess(
          FLAGS_child_timeout, FLAGS_max_memory_gb,
          [&] { return RunMethod(data, cell); }, result, &failure)) {
    return !std::isnan(result->time_s);
  }
  *result = RunResult();
  SetStatus(result, failure);
  return false;
}

bool Success(const RunResult& r) {
  return r.precision >= 0.99 && r.recall >= 0.99 && r.clean_gap <= 1e-6;
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

struct Row {
  Cell cell;
  RunResult result;
  bool ok = false;
};

int Main() {
  if (FLAGS_quick) {
    FLAGS_datasets = "CSAIL,smallGrid3D";
    FLAGS_fractions = "0.3";
    FLAGS_clustered_fractions = "";
    FLAGS_seeds = 1;
  }
  std::map<std::string, double> overrides;
  for (const std::string& item : Split(FLAGS_dataset_thresholds)) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos) {
      std::fprintf(stderr, "--dataset_thresholds: expected NAME=C2, got %s\n",
                   item.c_str());
      return 2;
    }
    overrides[item.substr(0, eq)] = std::stod(item.substr(eq + 1));
  }
  const std::vector<std::string> methods = Split(FLAGS_methods);
  const std::set<std::string> known = {"sesync",
                                       "gnc",
                                       "lm-huber-chordal",
                                       "lm-cauchy-chordal",
                                       "lm-huber-odometry",
                                       "lm-cauchy-odometry"};
  for (const std::string& method : methods) {
    if (!known.count(method)) {
      std::fprintf(stderr, "unknown method '%s'\n", method.c_str());
      return 2;
    }
  }
  std::vector<std::pair<std::string, double>> grid;
  for (double f : bench::ParseDoubles(FLAGS_fractions)) {
    grid.emplace_back("random", f);
  }
  for (double f : bench::ParseDoubles(FLAGS_clustered_fractions)) {
    grid.emplace_back("clustered", f);
  }
  std::filesystem::create_directories(FLAGS_out_dir);
  const std::string csv_path = FLAGS_out_dir + "/" + FLAGS_out_name + ".csv";
  std::ofstream csv(csv_path);
  csv << "dataset,d,n,m_clean,threshold,mode,fraction,seed,method,added,"
         "rejected,true_rejected,precision,recall,max_rotation_error_deg,"
         "max_translation_error,clean_objective,clean_optimum,clean_gap,"
         "tls_cost,truth_tls_cost,time_s,certified,gnc_iterations,success,"
         "status\n";
  std::vector<Row> rows;
  std::vector<Dataset> datasets;
  for (const std::string& name : Split(FLAGS_datasets)) {
    Dataset data;
    data.name = name;
    std::string error;
    const std::string path = FLAGS_data_dir + "/" + name + ".g2o";
    if (!ReadG2oFile(path, {}, &data.graph, &error)) {
      std::printf("%s: skipped (%s)\n", name.c_str(), error.c_str());
      continue;
    }
    SolverOptions options;
    options.num_threads = FLAGS_num_threads;
    SolverSummary s;
    data.optimum = Solve(data.graph, options, &s);
    if (!s.certified()) {
      std::printf("%s: skipped (clean solve %s)\n", name.c_str(),
                  s.StatusString().c_str());
      continue;
    }
    data.objective = s.objective;
    RobustSolverOptions robust;
    data.threshold = overrides.count(name)
                         ? overrides[name]
                         : InlierThreshold(robust, data.graph.dimension);
    std::printf("%s: n %d, m %zu, clean optimum %.10g (certified), c^2 %.4g\n",
                name.c_str(), data.graph.num_poses,
                data.graph.measurements.size(), data.objective, data.threshold);
    std::fflush(stdout);
    for (const auto& [mode, fraction] : grid) {
      for (int seed = 1; seed <= FLAGS_seeds; ++seed) {
        for (const std::string& method : methods) {
          Row row;
          row.cell = {name, mode, method, fraction, seed};
          row.ok = RunInChild(data, row.cell, &row.result);
          const RunResult& r = row.result;
          std::printf(
              "  %-9s %.2f seed %d %-19s P %6s R %6s rot %9s deg trans %9s "
              "gap %9s TLS-truth %9s %8s s %s%s\n",
              mode.c_str(), fraction, seed, method.c_str(),
              Fmt("%.4f", r.precision).c_str(), Fmt("%.4f", r.recall).c_str(),
              Fmt("%.3g", r.max_rotation_error_deg).c_str(),
              Fmt("%.3g", r.max_translation_error).c_str(),
              Fmt("%.2e", r.clean_gap).c_str(),
              Fmt("%.2e", TlsVsTruth(r)).c_str(), Fmt("%.3f", r.time_s).c_str(),
              r.status, row.ok && Success(r) ? "  ok" : "");
          std::fflush(stdout);
          csv << CsvField(name) << "," << data.graph.dimension << ","
              << data.graph.num_poses << "," << data.graph.measurements.size()
              << "," << Fmt("%.10g", data.threshold) << "," << mode << ","
              << fraction << "," << seed << "," << method << "," << r.added
              << "," << r.rejected << "," << r.true_rejected << ","
              << Fmt("%.6f", r.precision) << "," << Fmt("%.6f", r.recall) << ","
              << Fmt("%.6g", r.max_rotation_error_deg) << ","
              << Fmt("%.6g", r.max_translation_error) << ","
              << Fmt("%.12g", r.clean_objective) << ","
              << Fmt("%.12g", data.objective) << "," << Fmt("%.6g", r.clean_gap)
              << "," << Fmt("%.12g", r.tls_cost) << ","
              << Fmt("%.12g", r.truth_tls_cost) << "," << Fmt("%.6f", r.time_s)
              << "," << r.certified << "," << r.gnc_iterations << ","
              << (row.ok && Success(r)) << "," << CsvField(r.status) << "\n";
          csv.flush();
          rows.push_back(row);
        }
      }
    }
    data.graph = PoseGraph();  // The child copies are gone; free memory.
    datasets.push_back(std::move(data));
  }

  // Tables: per dataset, mode, fraction and method, over the seeds.
  std::ostringstream md;
  md << "# Outlier benchmark\n\n`"
     << "outliers";
  if (FLAGS_quick) md << " --quick";
  md << " --datasets " << FLAGS_datasets << " --fractions " << FLAGS_fractions
     << " --clustered_fractions '" << FLAGS_clustered_fractions << "' --seeds "
     << FLAGS_seeds << "`";
  if (!FLAGS_dataset_thresholds.empty()) {
    md << " with --dataset_thresholds " << FLAGS_dataset_thresholds;
  }
  md << "\n\nSuccess: precision and recall >= 0.99 and clean objective gap "
        "<= 1e-6. Per cell: successes / seeds, the worst precision and "
        "recall, the median max rotation error, translation error, clean "
        "gap, TLS vs truth ((T(x) - T(x*)) / T(x*), T the TLS cost at c^2: "
        "negative when the result beats the true labels) and time over the "
        "seeds.\n\n";
  md << "| dataset | mode | fraction | method | success | P min | R min | "
        "rot err [deg] | trans err | clean gap | TLS vs truth | time [s] |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::map<std::tuple<std::string, std::string, double, std::string>,
           std::vector<const Row*>>
      cells;
  for (const Row& row : rows) {
    cells[{row.cell.dataset, row.cell.mode, row.cell.fraction, row.cell.method}]
        .push_back(&row);
  }
  for (const Dataset& data : datasets) {
    for (const auto& [mode, fraction] : grid) {
      for (const std::string& method : methods) {
        const auto& runs = cells[{data.name, mode, fraction, method}];
        if (runs.empty()) continue;
        int ok = 0;
        double p_min = INFINITY, r_min = INFINITY;
        std::vector<double> rot, trans, gap, tls, time;
        std::string failure;
        for (const Row* row : runs) {
          const RunResult& r = row->result;
          ok += row->ok && Success(r);
          if (!row->ok && failure.empty()) failure = r.status;
          p_min = std::min(p_min, std::isnan(r.precision) ? 0 : r.precision);
          r_min = std::min(r_min, std::isnan(r.recall) ? 0 : r.recall);
          if (!row->ok) continue;
          rot.push_back(r.max_rotation_error_deg);
          trans.push_back(r.max_translation_error);
          gap.push_back(r.clean_gap);
          tls.push_back(TlsVsTruth(r));
          time.push_back(r.time_s);
        }
        md << "| " << data.name << " | " << mode << " | " << fraction << " | "
           << method << " | " << ok << "/" << runs.size() << " | "
           << Fmt("%.3f", p_min) << " | " << Fmt("%.3f", r_min) << " | "
           << Fmt("%.3g", bench::Median(rot)) << " | "
           << Fmt("%.3g", bench::Median(trans)) << " | "
           << Fmt("%.1e", bench::Median(gap)) << " | "
           << Fmt("%.1e", bench::Median(tls)) << " | "
           << Fmt("%.2f", bench::Median(time))
           << (failure.empty() ? "" : " (" + failure + ")") << " |\n";
      }
    }
  }

  // Breakdown: the largest fraction up to which every seed succeeds, by
  // the goal and by precision and recall alone (M-estimators never recover
  // the clean optimum exactly, so the goal is out of their reach by design).
  auto holds_table = [&](const char* title, auto success) {
    md << "\n## " << title << "\n\n| dataset | mode |";
    for (const std::string& method : methods) md << " " << method << " |";
    md << "\n|---|---|";
    for (size_t q = 0; q < methods.size(); ++q) md << "---|";
    md << "\n";
    for (const Dataset& data : datasets) {
      for (const std::string mode : {"random", "clustered"}) {
        std::vector<double> fractions;
        for (const auto& [g_mode, f] : grid) {
          if (g_mode == mode) fractions.push_back(f);
        }
        if (fractions.empty()) continue;
        std::sort(fractions.begin(), fractions.end());
        md << "| " << data.name << " | " << mode << " |";
        for (const std::string& method : methods) {
          double holds = NAN;
          for (double f : fractions) {
            const auto& runs = cells[{data.name, mode, f, method}];
            const bool all =
                !runs.empty() &&
                std::all_of(runs.begin(), runs.end(), [&](const Row* row) {
                  return row->ok && success(row->result);
                });
            if (!all) break;
            holds = f;
          }
          md << " "
             << (std::isnan(holds) ? std::string("-")
                                   : Fmt("%.0f%%", 100 * holds))
             << " |";
        }
        md << "\n";
      }
    }
  };
  holds_table(
      "Holds to: the goal (largest fraction with every seed successful at "
      "it and below; '-' none)",
      Success);
  holds_table(
      "Holds to: precision and recall >= 0.99 only (clean objective not "
      "required)",
      [](const RunResult& r) {
        return r.precision >= 0.99 && r.recall >= 0.99;
      });
  const std::string text = md.str();
  std::printf("\n%s", text.c_str());
  std::ofstream(FLAGS_out_dir + "/" + FLAGS_out_name + ".md") << text;
  std::printf("\nwrote %s and %s/%s.md\n", csv_path.c_str(),
              FLAGS_out_dir.c_str(), FLAGS_out_name.c_str());
  return 0;
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  gflags::SetUsageMessage("outlier benchmark (see bench/outliers.cc)");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  FLAGS_minloglevel = google::GLOG_ERROR;
  return ceres_sesync::Main();
}
