// Benchmark: SE-Sync versus Ceres local search on the standard pose-graph
// datasets (Rosen et al., IJRR 2019, Section 6.2, Tables 1-2).
//
//   bench [--quick] [--repeats N] [--min_time S] [--out_dir DIR]
//         [--ceres_max_time S]
//         [--poses_dir DIR] [--sesync_only] [--methods LIST]
//         [--[no]lbfgs] [--lbfgs_max_time S] [--lbfgs_repeats N] [files...]
//
// Without files: every .g2o in CERES_SESYNC_DATA_DIR, sorted by name
// (--quick: tinyGrid3D, smallGrid3D, CSAIL, intel, one repeat).
//
// Per dataset, in one process (file reading is never timed):
//  - SE-Sync (default SolverOptions, chordal initialization); time = the
//    wall time of Solve(), which includes building the data matrices, the
//    initialization, the staircase, the certificate and the rounding. The
//    stage breakdown of the fastest repeat goes to bench_stages.csv.
//  - SE-Sync (Ceres LBFGS): the same Solve() with SolverOptions::local_solver
//    = kCeresLbfgs (ceres::GradientProblemSolver on StiefelProductManifold
//    as the staircase's local solver), chordal initialization, limited to
//    --lbfgs_max_time seconds (SolverOptions::max_time_s) and repeated
//    --lbfgs_repeats times (default 1). Off with --nolbfgs.
//  - Certify() of the SE-Sync solution (time), and of the file's own VERTEX
//    guess when it has one (expected NOT to certify: lower bound and relative
//    bound reported).
//  - Ceres PDL-GN and LM from the chordal initialization (time includes
//    computing it; chordal_time_s reports it separately) and from the file's
//    vertices (odometry composition if it has none), each followed by
//    Certify() of the result.
// Times are the minimum and median over the repeats (the machine is shared;
// the minimum is the least disturbed measurement). Runs from the file's
// initial guess are repeated --odometry_repeats times (default 1): several
// of them end at the time limit. --methods runs a subset (e.g.
// --methods sesync,lbfgs).
//
// Output in --out_dir: bench.md (Markdown table + summary), bench.csv,
// bench_stages.csv. The same Markdown is printed to stdout.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/certification.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(quick, false,
            "Only tinyGrid3D, smallGrid3D, CSAIL and intel, one repeat.");
DEFINE_int32(repeats, 3, "Timed repeats per method (min and median kept).");
DEFINE_double(min_time, 1.0,
              "SE-Sync, Certify, the chordal initialization and Ceres from "
              "it repeat beyond --repeats until their runs add up to this "
              "many seconds (at most 100 runs): the minimum over more runs "
              "filters machine noise on the millisecond-scale datasets.");
DEFINE_int32(num_threads, 1,
             "Threads for every method alike: SolverOptions::num_threads, "
             "CertifyOptions::num_threads and Ceres's num_threads.");
DEFINE_int32(odometry_repeats, 1,
             "Repeats of the Ceres runs from the file's initial guess "
             "(capped by --repeats).");
DEFINE_string(out_dir, ".",
              "Directory for bench.md, bench.csv, "
              "bench_stages.csv.");
DEFINE_double(ceres_max_time, 60,
              "Wall-clock limit of each Ceres solve in seconds; runs that "
              "hit it are marked 'timeout'.");
DEFINE_string(poses_dir, "",
              "If set, write the SE-Sync solution and the initial guess of "
              "each dataset as g2o VERTEX files DATASET_sesync.g2o and "
              "DATASET_initial.g2o here (for plot_trajectory.py).");
DEFINE_string(preconditioner, "auto",
              "SE-Sync's truncated-CG preconditioner: auto "
              "(SolverOptions::Preconditioner::kAutomatic, the default) or q "
              "(kRegularizedQ, the exact one alone), for A/B runs.");
DEFINE_bool(near_convergence_tests, false,
            "SE-Sync with SolverOptions::test_certificate_near_convergence "
            "(stop the first level once its certificate is provable; off by "
            "default), for A/B runs.");
DEFINE_bool(sesync_only, false,
            "Run only SE-Sync (for peak-memory measurements with "
            "/usr/bin/time -v); same as --methods sesync.");
DEFINE_string(methods, "sesync,lbfgs,ceres",
              "Comma-separated methods to run: sesync (SE-Sync and Certify "
              "of its solution), lbfgs (SE-Sync (Ceres LBFGS)), ceres "
              "(Certify of the file's guess, Ceres PDL-GN and LM from the "
              "chordal initialization and from the file's guess).");
DEFINE_bool(lbfgs, true,
            "Run SE-Sync with Ceres's LBFGS as the staircase's local solver "
            "(row 'SE-Sync (Ceres LBFGS)'); --nolbfgs skips it.");
DEFINE_double(lbfgs_max_time, 60,
              "Wall-clock limit (SolverOptions::max_time_s) of each SE-Sync "
              "(Ceres LBFGS) solve in seconds.");
DEFINE_int32(lbfgs_repeats, 1,
             "Repeats of SE-Sync (Ceres LBFGS) (capped by --repeats).");

namespace ceres_sesync {
namespace {

using bench::BlasLibrary;
using bench::CeresStatus;
using bench::Clock;
using bench::CsvField;
using bench::Fmt;
using bench::Median;
using bench::Min;
using bench::PeakRssMiB;
using bench::SecondsSince;
using bench::Sum;

// Whether to run repeat number `done` (0-based) given the time `spent` so
// far: at least `repeats` runs, more until --min_time (100 runs at most).
bool Again(int done, int repeats, double spent, bool extend = true) {
  return done < repeats || (extend && spent < FLAGS_min_time && done < 100);
}

// Optimal values of Tables 1-2 of the paper, as cited in
// ../shared/sesync-notes.md (rounded to four digits there).
const std::map<std::string, double>& PaperOptima() {
  static const std::map<std::string, double> optima = {
      {"CSAIL", 3.170e1},      {"intel", 5.235e1},
      {"manhattan", 6.432e3},  {"city10000", 6.386e2},
      {"ais2klinik", 1.885e2}, {"sphere2500", 1.687e3},
      {"torus3D", 2.423e4},    {"parking-garage", 1.263e0},
      {"cubicle", 7.171e2}};
  return optima;
}

// One row of the results table.
struct Row {
  std::string dataset;
  int n = 0, m = 0;
  std::string method;  // SE-Sync, SE-Sync (Ceres LBFGS), Certify, PDL-GN, LM.
  std::string init;    // chordal, vertices, odometry, sesync (for Certify).
  std::vector<double> times;
  double chordal_time_s = NAN;  // Part of `times` spent on the chordal init.
  double objective = NAN;
  std::string certified;  // yes / no / error / "".
  double lower_bound = NAN;
  double rel_subopt_bound = NAN;
  // The certificate's proof: arithmetic, factorizations (double +
  // double-double) and the double-double seconds.
  std::string proof;
  int iterations = -1;
  std::string status;    // converged / timeout / max_iterations / ...
  double speedup = NAN;  // time_min / SE-Sync time_min.
};

struct Stages {
  std::string dataset;
  std::string method;  // SE-Sync or SE-Sync (Ceres LBFGS).
  int n = 0, m = 0, d = 0;
  SolverSummary summary;
  double wall_s = 0;
};

std::string BaseName(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

// Fills the certification columns of `row` from Certify(graph, poses).
void CertifyInto(const PoseGraph& graph, const Poses& poses, Row* row,
                 double* time_s = nullptr) {
  Certificate certificate;
  std::string error;
  const auto start = Clock::now();
  CertifyOptions options;
  options.num_threads = FLAGS_num_threads;
  if (!Certify(graph, poses, options, &certificate, &error)) {
    row->certified = "error";
    row->status = "certify error: " + error;
    LOG(WARNING) << row->dataset << " " << row->method << "/" << row->init
                 << ": Certify failed: " << error;
    return;
  }
  if (time_s) *time_s = SecondsSince(start);
  row->certified = certificate.certified ? "yes" : "no";
  row->lower_bound = certificate.lower_bound;
  row->rel_subopt_bound = certificate.relative_suboptimality_bound;
  row->proof = certificate.proof_precision + " (" +
               std::to_string(certificate.factorizations) + "+" +
               std::to_string(certificate.extended_factorizations) + ", " +
               Fmt("%.3f", certificate.extended_proof_time_s) + " s)";
  const double tol = CertifyOptions().max_relative_suboptimality;
  if (certificate.certified &&
      !(certificate.relative_suboptimality_bound <= tol * (1 + 1e-9))) {
    // Certify's contract: certified implies bound <= tol. Flag, don't hide.
    row->certified = "yes (bound > tolerance!)";
    LOG(WARNING) << row->dataset << " " << row->method << "/" << row->init
                 << ": Certify says certified but its relative bound is "
                 << certificate.relative_suboptimality_bound;
  }
}

// Runs Ceres `repeats` times from `initial` (whose computation took
// `init_time_s`, added to each time) and certifies the result.
Row RunCeres(const PoseGraph& graph, const std::string& dataset,
             CeresBaselineOptions::Method method, const std::string& init,
             const Poses& initial, double init_time_s, int repeats) {
  Row row;
  row.dataset = dataset;
  row.n = graph.num_poses;
  row.m = static_cast<int>(graph.measurements.size());
  row.method =
      method == CeresBaselineOptions::Method::kPowellDogleg ? "PDL-GN" : "LM";
  row.init = init;
  if (init == "chordal") row.chordal_time_s = init_time_s;
  CeresBaselineOptions options;
  options.method = method;
  options.max_solver_time_s = FLAGS_ceres_max_time;
  options.num_threads = FLAGS_num_threads;
  Poses result;
  CeresBaselineSummary summary;
  for (int r = 0; Again(r, repeats, Sum(row.times), init == "chordal"); ++r) {
    std::string error;
    const auto start = Clock::now();
    if (!SolveWithCeres(graph, initial, options, &result, &summary, &error)) {
      row.status = "error: " + error;
      LOG(WARNING) << dataset << " " << row.method << "/" << init << ": "
                   << error;
      return row;
    }
    row.times.push_back(init_time_s + SecondsSince(start));
  }
  row.objective = EvaluateObjective(graph, result);
  row.iterations = summary.iterations;
  row.status = CeresStatus(summary);
  CertifyInto(graph, result, &row);
  std::fprintf(stderr,
               "  %-6s from %-8s  %8.3f s  F = %.6e  %s  certified=%s\n",
               row.method.c_str(), init.c_str(), Min(row.times), row.objective,
               row.status.c_str(), row.certified.c_str());
  return row;
}

// A short form of a level's termination message ("ceres LBFGS: Function
// tolerance reached. |cost_change|/cost: ..." -> "Function tolerance
// reached").
std::string ShortTermination(const std::string& termination) {
  std::string s = termination;
  const std::string prefix = "ceres LBFGS: ";
  if (s.rfind(prefix, 0) == 0) s = s.substr(prefix.size());
  return s.substr(0, s.find('.'));
}

// Runs Solve(graph, options) `repeats` times and fills `row` (named `method`)
// and `stage` (the fastest repeat); `poses` gets the solution. Returns false
// if the graph is invalid.
bool RunSESync(const PoseGraph& graph, const std::string& dataset,
               const std::string& method, const SolverOptions& options,
               int repeats, bool extend, Row* row, Stages* stage,
               Poses* poses) {
  row->dataset = stage->dataset = dataset;
  row->method = stage->method = method;
  row->n = stage->n = graph.num_poses;
  row->m = stage->m = static_cast<int>(graph.measurements.size());
  row->init = "chordal";
  stage->d = graph.dimension;
  for (int r = 0; Again(r, repeats, Sum(row->times), extend); ++r) {
    SolverSummary summary;
    const auto start = Clock::now();
    *poses = Solve(graph, options, &summary);
    const double wall = SecondsSince(start);
    row->times.push_back(wall);
    if (r == 0 || wall < stage->wall_s) {
      stage->summary = summary;
      stage->wall_s = wall;
    }
  }
  const SolverSummary& s = stage->summary;
  if (s.status == SolverSummary::Status::kInvalidInput) {
    std::fprintf(stderr, "bench: %s: %s\n", dataset.c_str(), s.message.c_str());
    return false;
  }
  row->objective = s.objective;
  row->certified = s.certified() ? "yes" : "no";
  if (s.certified() &&
      !(s.relative_suboptimality_bound <=
        options.certification_max_relative_bound * (1 + 1e-9))) {
    // The SDP solution is certified, but the rounded poses are not within
    // the tolerance of its lower bound (the relaxation is not exact).
    row->certified = "SDP only (bound > " +
                     Fmt("%g", options.certification_max_relative_bound) + ")";
  }
  row->lower_bound = s.lower_bound;
  row->rel_subopt_bound = s.relative_suboptimality_bound;
  row->proof = s.proof_precision + " (" + std::to_string(s.factorizations) +
               "+" + std::to_string(s.extended_factorizations) + ", " +
               Fmt("%.3f", s.extended_proof_time_s) + " s)";
  row->iterations = s.iterations;
  row->status = s.StatusString() + ", rank " + std::to_string(s.final_rank);
  if (options.local_solver == SolverOptions::LocalSolver::kCeresLbfgs) {
    // How each staircase level's LBFGS run ended (rank: reason, iterations).
    for (const SolverSummary::Level& level : s.levels) {
      row->status += "; " + std::to_string(level.rank) + ": " +
                     ShortTermination(level.termination) + " (" +
                     std::to_string(level.iterations) + " it)";
    }
  }
  row->chordal_time_s = s.initialization_time_s;
  std::fprintf(stderr, "  %-22s %8.3f s  F = %.6e  %s\n", method.c_str(),
               Min(row->times), s.objective, row->status.c_str());
  auto known = PaperOptima().find(dataset);
  if (known != PaperOptima().end()) {
    const double rel = std::abs(s.objective - known->second) / known->second;
    if (rel > 5e-4) {
      std::fprintf(stderr,
                   "WARNING: %s: %s objective %.6e differs from the "
                   "paper's %.4e by %.2e relative (> 5e-4)\n",
                   dataset.c_str(), method.c_str(), s.objective, known->second,
                   rel);
      row->status += ", DIFFERS FROM PAPER";
    }
  }
  return true;
}

bool BenchDataset(const std::string& path, int repeats,
                  const std::set<std::string>& methods, std::vector<Row>* rows,
                  std::vector<Stages>* stages) {
  const std::string dataset = BaseName(path);
  PoseGraph graph;
  std::string error;
  if (!ReadG2oFile(path, G2oReadOptions(), &graph, &error)) {
    std::fprintf(stderr, "bench: %s\n", error.c_str());
    return false;
  }
  const int n = graph.num_poses;
  const int m = static_cast<int>(graph.measurements.size());
  std::fprintf(stderr, "%s: d = %d, n = %d, m = %d\n", dataset.c_str(),
               graph.dimension, n, m);

  // --- SE-Sync (default options: chordal initialization, trust region) and
  // the certification of its solution.
  if (methods.count("sesync")) {
    Row sesync;
    Stages stage;
    Poses sesync_poses;
    SolverOptions sesync_options;
    sesync_options.num_threads = FLAGS_num_threads;
    if (FLAGS_preconditioner == "q") {
      sesync_options.preconditioner =
          SolverOptions::Preconditioner::kRegularizedQ;
    }
    sesync_options.test_certificate_near_convergence =
        FLAGS_near_convergence_tests;
    if (!RunSESync(graph, dataset, "SE-Sync", sesync_options, repeats,
                   /*extend=*/true, &sesync, &stage, &sesync_poses)) {
      return false;
    }
    rows->push_back(sesync);
    stages->push_back(stage);

    if (!FLAGS_poses_dir.empty()) {
      std::filesystem::create_directories(FLAGS_poses_dir);
      const std::string base = FLAGS_poses_dir + "/" + dataset;
      const Poses initial = graph.initial_poses.empty()
                                ? OdometryInitialization(graph)
                                : graph.initial_poses;
      if (!WriteG2oPoses(base + "_sesync.g2o", graph, sesync_poses, &error) ||
          !WriteG2oPoses(base + "_initial.g2o", graph, initial, &error)) {
        std::fprintf(stderr, "bench: %s\n", error.c_str());
      }
    }

    Row row;
    row.dataset = dataset;
    row.n = n;
    row.m = m;
    row.method = "Certify";
    row.init = "sesync";
    row.objective = sesync.objective;
    for (int r = 0; Again(r, repeats, Sum(row.times)); ++r) {
      double t = NAN;
      CertifyInto(graph, sesync_poses, &row, &t);
      if (!std::isnan(t)) row.times.push_back(t);
    }
    std::fprintf(stderr, "  Certify(SE-Sync)    %8.3f s  certified=%s\n",
                 Min(row.times), row.certified.c_str());
    rows->push_back(row);
  }

  // --- SE-Sync with Ceres's LBFGS as the local solver, time-limited.
  if (methods.count("lbfgs")) {
    SolverOptions options;
    options.local_solver = SolverOptions::LocalSolver::kCeresLbfgs;
    options.max_time_s = FLAGS_lbfgs_max_time;
    options.num_threads = FLAGS_num_threads;
    Row row;
    Stages stage;
    Poses poses;
    if (!RunSESync(graph, dataset, "SE-Sync (Ceres LBFGS)", options,
                   std::max(1, std::min(repeats, FLAGS_lbfgs_repeats)),
                   /*extend=*/false, &row, &stage, &poses)) {
      return false;
    }
    rows->push_back(row);
    stages->push_back(stage);
  }
  if (!methods.count("ceres")) return true;

  // --- Certify the file's own initial guess.
  if (!graph.initial_poses.empty()) {
    Row row;
    row.dataset = dataset;
    row.n = n;
    row.m = m;
    row.method = "Certify";
    row.init = "vertices";
    row.objective = EvaluateObjective(graph, graph.initial_poses);
    double t = NAN;
    CertifyInto(graph, graph.initial_poses, &row, &t);
    if (!std::isnan(t)) row.times.push_back(t);
    std::fprintf(stderr,
                 "  Certify(vertices)   %8.3f s  F = %.6e  LB = %.6e  "
                 "certified=%s\n",
                 Min(row.times), row.objective, row.lower_bound,
                 row.certified.c_str());
    rows->push_back(row);
  }

  // --- Ceres from the chordal initialization (its time included).
  Poses chordal;
  double chordal_time = 0;
  {
    std::vector<double> t;
    for (int r = 0; Again(r, repeats, Sum(t)); ++r) {
      const auto start = Clock::now();
      if (!ChordalInitialization(graph, &chordal, &error)) {
        std::fprintf(stderr, "bench: %s: chordal: %s\n", path.c_str(),
                     error.c_str());
        return false;
      }
      t.push_back(SecondsSince(start));
    }
    chordal_time = Min(t);
  }
  using Method = CeresBaselineOptions::Method;
  for (Method method : {Method::kPowellDogleg, Method::kLevenbergMarquardt}) {
    rows->push_back(RunCeres(graph, dataset, method, "chordal", chordal,
                             chordal_time, repeats));
  }

  // --- Ceres from the file's vertices (odometry if there are none).
  const bool has_vertices = !graph.initial_poses.empty();
  double odometry_time = 0;
  const auto start = Clock::now();
  const Poses initial =
      has_vertices ? graph.initial_poses : OdometryInitialization(graph);
  if (!has_vertices) odometry_time = SecondsSince(start);
  const int odometry_repeats =
      std::max(1, std::min(repeats, FLAGS_odometry_repeats));
  for (Method method : {Method::kPowellDogleg, Method::kLevenbergMarquardt}) {
    rows->push_back(RunCeres(graph, dataset, method,
                             has_vertices ? "vertices" : "odometry", initial,
                             odometry_time, odometry_repeats));
  }
  std::fprintf(stderr, "  peak RSS of the process so far: %.0f MiB\n",
               PeakRssMiB());
  return true;
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  using namespace ceres_sesync;
  gflags::SetUsageMessage(
      "bench [--quick] [--repeats N] [--out_dir DIR] [--methods LIST] "
      "[files...]\n"
      "SE-Sync vs Ceres PDL-GN/LM on pose-graph datasets.");
  bench::InitBenchProgram(&argc, &argv);

  std::set<std::string> methods;
  {
    std::stringstream list(FLAGS_methods);
    std::string method;
    while (std::getline(list, method, ',')) {
      if (method.empty()) continue;
      if (method != "sesync" && method != "lbfgs" && method != "ceres") {
        std::fprintf(stderr,
                     "bench: unknown method '%s' in --methods (sesync, lbfgs, "
                     "ceres)\n",
                     method.c_str());
        return 2;
      }
      methods.insert(method);
    }
  }
  if (FLAGS_preconditioner != "auto" && FLAGS_preconditioner != "q") {
    std::fprintf(stderr, "bench: unknown --preconditioner '%s' (auto, q)\n",
                 FLAGS_preconditioner.c_str());
    return 2;
  }
  if (FLAGS_sesync_only) methods = {"sesync"};
  if (!FLAGS_lbfgs) methods.erase("lbfgs");

  std::vector<std::string> files(argv + 1, argv + argc);
  int repeats = std::max(1, FLAGS_repeats);
  const std::string data_dir = CERES_SESYNC_DATA_DIR;
  if (FLAGS_quick) {
    repeats = 1;
    if (files.empty()) {
      for (const char* name : {"tinyGrid3D", "smallGrid3D", "CSAIL", "intel"}) {
        files.push_back(data_dir + "/" + name + ".g2o");
      }
    }
  }
  if (files.empty()) {
    std::error_code ec;
    for (const auto& entry :
         std::filesystem::directory_iterator(data_dir, ec)) {
      if (entry.path().extension() == ".g2o") {
        files.push_back(entry.path().string());
      }
    }
    if (ec || files.empty()) {
      std::fprintf(stderr, "bench: no .g2o files in %s%s%s\n", data_dir.c_str(),
                   ec ? ": " : "", ec ? ec.message().c_str() : "");
      return 2;
    }
    std::sort(files.begin(), files.end());
  }

  std::vector<Row> rows;
  std::vector<Stages> stages;
  int failures = 0;
  for (const std::string& file : files) {
    if (!BenchDataset(file, repeats, methods, &rows, &stages)) ++failures;
  }

  // Speedups relative to SE-Sync of the same dataset.
  std::map<std::string, double> sesync_time;
  for (const Row& r : rows) {
    if (r.method == "SE-Sync") sesync_time[r.dataset] = Min(r.times);
  }
  for (Row& r : rows) {
    auto sesync = sesync_time.find(r.dataset);
    if (r.method != "Certify" && sesync != sesync_time.end()) {
      r.speedup = Min(r.times) / sesync->second;
    }
  }

  // Summary: PDL-GN (chordal) / SE-Sync.
  double log_sum = 0;
  int count = 0, sesync_faster = 0;
  std::string slower;
  for (const Row& r : rows) {
    if (r.method != "PDL-GN" || r.init != "chordal" || std::isnan(r.speedup)) {
      continue;
    }
    log_sum += std::log(r.speedup);
    ++count;
    if (r.speedup > 1) {
      ++sesync_faster;
    } else {
      slower += (slower.empty() ? "" : ", ") + r.dataset;
    }
  }
  const double geomean = count ? std::exp(log_sum / count) : NAN;

  // Summary: SE-Sync (Ceres LBFGS) / SE-Sync (trust region).
  double lbfgs_log_sum = 0;
  int lbfgs_count = 0, lbfgs_rows = 0, lbfgs_certified = 0;
  for (const Row& r : rows) {
    if (r.method != "SE-Sync (Ceres LBFGS)") continue;
    ++lbfgs_rows;
    if (r.certified == "yes") ++lbfgs_certified;
    if (std::isnan(r.speedup)) continue;
    lbfgs_log_sum += std::log(r.speedup);
    ++lbfgs_count;
  }

  std::ostringstream md;
  md << "| dataset | n | m | method | init | time min [s] | time median [s] "
        "| chordal [s] | objective | certified | rel. subopt. bound | proof "
        "(factorizations double+dd, dd time) | iterations | time / SE-Sync | "
        "status |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    md << "| " << r.dataset << " | " << r.n << " | " << r.m << " | " << r.method
       << " | " << r.init << " | " << Fmt("%.4f", Min(r.times)) << " | "
       << Fmt("%.4f", Median(r.times)) << " | " << Fmt("%.4f", r.chordal_time_s)
       << " | " << Fmt("%.6e", r.objective) << " | " << r.certified << " | "
       << Fmt("%.2e", r.rel_subopt_bound) << " | " << r.proof << " | "
       << (r.iterations >= 0 ? std::to_string(r.iterations) : "") << " | "
       << Fmt("%.2f", r.speedup) << " | " << r.status << " |\n";
  }
  md << "\nStage breakdown of SE-Sync (fastest repeat), seconds:\n\n"
        "| dataset | method | d | n | m | data | init | optimize | verify | "
        "round | total | rank | iterations | Hv products |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Stages& st : stages) {
    const SolverSummary& s = st.summary;
    md << "| " << st.dataset << " | " << st.method << " | " << st.d << " | "
       << st.n << " | " << st.m << " | " << Fmt("%.4f", s.data_time_s) << " | "
       << Fmt("%.4f", s.initialization_time_s) << " | "
       << Fmt("%.4f", s.optimization_time_s) << " | "
       << Fmt("%.4f", s.verification_time_s) << " | "
       << Fmt("%.4f", s.rounding_time_s) << " | " << Fmt("%.4f", s.total_time_s)
       << " | " << s.final_rank << " | " << s.iterations << " | "
       << s.hessian_vector_products << " |\n";
  }
  if (count > 0) {
    md << "\nGeometric mean of PDL-GN(chordal) / SE-Sync time over " << count
       << " datasets: " << Fmt("%.2f", geomean) << "; SE-Sync (including its "
       << "certification) is faster on " << sesync_faster << " of " << count
       << (slower.empty() ? "" : " (slower on: " + slower + ")") << ".\n";
  }
  if (lbfgs_rows > 0) {
    md << "\nSE-Sync (Ceres LBFGS): certified on " << lbfgs_certified << " of "
       << lbfgs_rows << " datasets; time limit " << FLAGS_lbfgs_max_time
       << " s, repeats " << std::max(1, std::min(repeats, FLAGS_lbfgs_repeats));
    if (lbfgs_count > 0) {
      md << "; geometric mean of its time / SE-Sync (trust region) time over "
         << lbfgs_count
         << " datasets: " << Fmt("%.2f", std::exp(lbfgs_log_sum / lbfgs_count));
    }
    md << ".\n";
  }
  md << "Repeats: at least " << repeats << ", more until " << FLAGS_min_time
     << " s per method and dataset (SE-Sync, Certify, chordal initialization "
        "and Ceres from it; at most 100); runs from the file's initial guess: "
     << std::max(1, std::min(repeats, FLAGS_odometry_repeats))
     << "; Ceres time limit " << FLAGS_ceres_max_time
     << " s. Peak RSS of the whole run: " << Fmt("%.0f", PeakRssMiB())
     << " MiB. BLAS (CHOLMOD's supernodal kernels, both sides): "
     << BlasLibrary() << ".\n";
  std::fputs(md.str().c_str(), stdout);

  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out_dir, ec);
  {
    std::ofstream out(FLAGS_out_dir + "/bench.md");
    out << md.str();
    if (!out) {
      std::fprintf(stderr, "bench: cannot write %s/bench.md\n",
                   FLAGS_out_dir.c_str());
      return 2;
    }
  }
  {
    std::ofstream out(FLAGS_out_dir + "/bench.csv");
    out << "dataset,n,m,method,init,time_min_s,time_median_s,chordal_time_s,"
           "objective,certified,lower_bound,rel_subopt_bound,proof,iterations,"
           "speedup,status\n";
    for (const Row& r : rows) {
      out << r.dataset << "," << r.n << "," << r.m << "," << CsvField(r.method)
          << "," << r.init << "," << Fmt("%.6g", Min(r.times)) << ","
          << Fmt("%.6g", Median(r.times)) << ","
          << Fmt("%.6g", r.chordal_time_s) << "," << Fmt("%.10g", r.objective)
          << "," << r.certified << "," << Fmt("%.10g", r.lower_bound) << ","
          << Fmt("%.3e", r.rel_subopt_bound) << "," << CsvField(r.proof) << ","
          << (r.iterations >= 0 ? std::to_string(r.iterations) : "") << ","
          << Fmt("%.4g", r.speedup) << "," << CsvField(r.status) << "\n";
    }
  }
  {
    std::ofstream out(FLAGS_out_dir + "/bench_stages.csv");
    out << "dataset,d,n,m,wall_s,data_s,initialization_s,optimization_s,"
           "verification_s,rounding_s,total_s,rank,iterations,"
           "hessian_vector_products,status,method,proof_precision,"
           "factorizations,extended_factorizations,extended_proof_s\n";
    for (const Stages& st : stages) {
      const SolverSummary& s = st.summary;
      out << st.dataset << "," << st.d << "," << st.n << "," << st.m << ","
          << st.wall_s << "," << s.data_time_s << "," << s.initialization_time_s
          << "," << s.optimization_time_s << "," << s.verification_time_s << ","
          << s.rounding_time_s << "," << s.total_time_s << "," << s.final_rank
          << "," << s.iterations << "," << s.hessian_vector_products << ","
          << CsvField(s.StatusString()) << "," << CsvField(st.method) << ","
          << s.proof_precision << "," << s.factorizations << ","
          << s.extended_factorizations << "," << s.extended_proof_time_s
          << "\n";
    }
  }
  return failures ? 1 : 0;
}
