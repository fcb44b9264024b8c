// Landmark benchmark (issue #15): SE-Sync versus Ceres local search on
// generated landmark-SLAM graphs (landmark_generator.h).
//
//   landmarks [--quick] [--cases LIST] [--repeats N] [--ceres_repeats N]
//             [--min_time S] [--ceres_max_time S] [--num_threads N]
//             [--out_dir DIR]
//
// Cases (each a deterministic function of its options; seed 1):
//  - manhattan2d:     2D walk, 2000 poses in a 40 m box, 400 landmarks drawn,
//                     5 m sensor range, no priors (gauge: pose 0);
//  - manhattan2d_gps: the same walk with GPS-like position priors on every
//                     20th pose (1 m RMS) and a start prior: world frame;
//  - manhattan3d:     3D walk, 2000 poses in a 20 m box, 600 landmarks, 5 m;
//  - manhattan3d_gps: the same with GPS priors every 20th pose and a start
//                     prior;
//  - victoria:        VictoriaParkLikeOptions() (2D, 2000 poses, ~30
//                     landmarks per pose).
// --quick: 300 poses per case, 1 repeat (seconds).
//
// Methods per case:
//  - SE-Sync / chordal: Solve() with default options (its chordal
//    initialization); time = the whole Solve (data matrices, initialization,
//    staircase, certificate, rounding);
//  - SE-Sync / odometry: Solve() from the odometry poses (only their rotations
//    are used: translations and landmarks are eliminated);
//  - PDL-GN, LM / odometry: SolveWithCeres from OdometryInitialization with
//    InitialLandmarkPositions (ceres_baseline.h), time including building
//    that start;
//  - PDL-GN, LM / chordal: SolveWithCeres from ChordalInitialization (poses
//    and optimal landmark positions), time including the chordal solve.
// Every result is certified afterwards with Certify() (default
// CertifyOptions: certified iff the proven relative bound is <= 1e-3); the
// Ceres rows report that certificate, the SE-Sync rows the solver's own.
// gap = (F - F_SE-Sync) / F_SE-Sync relative to the SE-Sync (chordal)
// objective. Times: minimum and median over --repeats runs (Ceres:
// --ceres_repeats, default 1: its runs take seconds and dominate the
// bench), extended until they add up to --min_time seconds (at most 100
// runs).
//
// Output in --out_dir: landmarks.csv (one row per case and method) and
// landmarks.md (the tables, also printed to stdout). Progress on stderr.

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
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(quick, false, "300 poses per case and one repeat: seconds.");
DEFINE_string(cases,
              "manhattan2d,manhattan2d_gps,manhattan3d,manhattan3d_gps,"
              "victoria",
              "Comma-separated cases: manhattan2d, manhattan2d_gps, "
              "manhattan3d, manhattan3d_gps, victoria.");
DEFINE_int32(repeats, 3,
             "Timed repeats of the SE-Sync runs (min and median kept).");
DEFINE_int32(ceres_repeats, 1,
             "Timed repeats of the Ceres runs (seconds each at 2000 poses: "
             "they dominate the bench's time).");
DEFINE_double(min_time, 1.0,
              "Repeat each method beyond --repeats until its runs add up to "
              "this many seconds (at most 100 runs).");
DEFINE_double(ceres_max_time, 60, "Wall-clock limit of each Ceres solve [s].");
DEFINE_int32(num_threads, 1,
             "Threads for every method alike: SolverOptions::num_threads, "
             "CertifyOptions::num_threads and Ceres's num_threads.");
DEFINE_string(out_dir, ".", "Directory for landmarks.csv and landmarks.md.");

namespace ceres_sesync {
namespace {

using bench::Clock;
using bench::Fmt;
using bench::Median;
using bench::Min;
using bench::SecondsSince;
using bench::Sum;

using Case = bench::LandmarkCase;
using bench::LandmarkCases;

struct Row {
  std::string case_name, method, init, status, certified, proof;
  int n = 0, num_landmarks = 0, m = 0, num_landmark_measurements = 0,
      num_priors = 0, iterations = 0;
  std::vector<double> times;
  double init_time_s = NAN, objective = NAN, gap = NAN, lower_bound = NAN,
         rel_bound = NAN, certify_time_s = NAN;
};

Row NewRow(const std::string& name, const PoseGraph& graph,
           const std::string& method, const std::string& init) {
  Row row;
  row.case_name = name;
  row.method = method;
  row.init = init;
  row.n = graph.num_poses;
  row.num_landmarks = graph.num_landmarks;
  row.m = static_cast<int>(graph.measurements.size());
  row.num_landmark_measurements =
      static_cast<int>(graph.landmark_measurements.size());
  row.num_priors = static_cast<int>(graph.priors.size());
  return row;
}

// Whether to run repeat `r` (0-based) of `repeats` given the seconds spent
// so far.
bool Again(int r, int repeats, double spent) {
  if (r < repeats) return true;
  return r < 100 && spent < FLAGS_min_time;
}

// Fills the certification columns of `row` from Certify(graph, solution).
void CertifyInto(const PoseGraph& graph, const Solution& solution, Row* row) {
  CertifyOptions options;
  options.num_threads = FLAGS_num_threads;
  Certificate certificate;
  std::string error;
  const auto start = Clock::now();
  if (!Certify(graph, solution, options, &certificate, &error)) {
    row->certified = "error";
    row->status += " (certify error: " + error + ")";
    LOG(WARNING) << row->case_name << " " << row->method << "/" << row->init
                 << ": Certify failed: " << error;
    return;
  }
  row->certify_time_s = SecondsSince(start);
  row->certified = certificate.certified ? "yes" : "no";
  row->lower_bound = certificate.lower_bound;
  row->rel_bound = certificate.relative_suboptimality_bound;
  row->proof = certificate.proof_precision;
  if (certificate.certified && !(certificate.relative_suboptimality_bound <=
                                 options.max_relative_suboptimality)) {
    // Certify's contract: certified implies bound <= tolerance. Flag it.
    row->certified = "yes (bound > tolerance!)";
    LOG(WARNING) << row->case_name << " " << row->method << "/" << row->init
                 << ": certified with relative bound "
                 << certificate.relative_suboptimality_bound;
  }
}

Row RunSESync(const std::string& name, const PoseGraph& graph,
              const std::string& init, const Poses* initial,
              double init_time_s) {
  Row row = NewRow(name, graph, "SE-Sync", init);
  SolverOptions options;
  options.num_threads = FLAGS_num_threads;
  Solution solution;
  SolverSummary summary;
  for (int r = 0; Again(r, FLAGS_repeats, Sum(row.times)); ++r) {
    const auto start = Clock::now();
    if (initial) {
      Solve(graph, *initial, options, &solution, &summary);
    } else {
      Solve(graph, options, &solution, &summary);
    }
    row.times.push_back(init_time_s + SecondsSince(start));
    if (summary.status == SolverSummary::Status::kInvalidInput) break;
  }
  if (initial) row.init_time_s = init_time_s;
  row.status = summary.StatusString();
  if (summary.status == SolverSummary::Status::kInvalidInput) {
    row.status += ": " + summary.message;
    return row;
  }
  row.objective = summary.objective;
  // The solver's reported objective must be that of its returned solution.
  const double f = EvaluateObjective(graph, solution);
  if (!(std::abs(f - row.objective) <= 1e-9 * std::abs(f))) {
    LOG(WARNING) << name << " SE-Sync/" << init << ": summary objective "
                 << row.objective << " but the solution evaluates to " << f;
    row.status += " (objective mismatch)";
  }
  row.iterations = summary.iterations;
  row.certified = summary.certified() ? "yes" : "no";
  row.lower_bound = summary.lower_bound;
  row.rel_bound = summary.relative_suboptimality_bound;
  row.proof =
      summary.proof_precision + ", rank " + std::to_string(summary.final_rank);
  std::fprintf(stderr, "  SE-Sync from %-8s %8.3f s  F = %.9e  %s\n",
               init.c_str(), Min(row.times), row.objective, row.status.c_str());
  return row;
}

Row RunCeres(const std::string& name, const PoseGraph& graph,
             CeresBaselineOptions::Method method, const std::string& init,
             const Solution& initial, double init_time_s) {
  const bool pdl = method == CeresBaselineOptions::Method::kPowellDogleg;
  Row row = NewRow(name, graph, pdl ? "PDL-GN" : "LM", init);
  row.init_time_s = init_time_s;
  CeresBaselineOptions options;
  options.method = method;
  options.max_solver_time_s = FLAGS_ceres_max_time;
  options.num_threads = FLAGS_num_threads;
  Solution result;
  CeresBaselineSummary summary;
  for (int r = 0; Again(r, FLAGS_ceres_repeats, Sum(row.times)); ++r) {
    std::string error;
    const auto start = Clock::now();
    if (!SolveWithCeres(graph, initial, options, &result, &summary, &error)) {
      row.status = "error: " + error;
      LOG(WARNING) << name << " " << row.method << "/" << init << ": " << error;
      return row;
    }
    row.times.push_back(init_time_s + SecondsSince(start));
    // A run at the time limit is not repeated: its time is the limit.
    if (bench::CeresStatus(summary) == "timeout") break;
  }
  row.objective = EvaluateObjective(graph, result);
  row.iterations = summary.iterations;
  row.status = bench::CeresStatus(summary);
  CertifyInto(graph, result, &row);
  std::fprintf(stderr,
               "  %-6s from %-8s  %8.3f s  F = %.9e  %s  certified=%s\n",
               row.method.c_str(), init.c_str(), Min(row.times), row.objective,
               row.status.c_str(), row.certified.c_str());
  return row;
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = NAN, five = NAN, fifteen = NAN;
  in >> one >> five >> fifteen;
  return Fmt("%.2f", one) + " / " + Fmt("%.2f", five) + " / " +
         Fmt("%.2f", fifteen);
}

std::string Describe(const Case& c) {
  const LandmarkGraphOptions& o = c.options;
  std::ostringstream s;
  s << o.dimension << "D, " << o.num_poses << " poses, box " << o.world_size
    << " m, " << o.num_landmarks << " landmarks drawn, sensor range "
    << o.sensor_range << " m, detection " << o.detection_probability;
  if (o.max_observations_per_pose > 0) {
    s << ", at most " << o.max_observations_per_pose << " per pose";
  }
  s << ", kappa " << o.kappa << ", tau " << o.tau << ", nu " << o.landmark_nu;
  if (o.gps_interval > 0) {
    s << ", GPS every " << o.gps_interval << " poses (tau " << o.gps_tau << ")";
  }
  if (o.start_prior) s << ", start prior";
  s << ", seed " << o.seed;
  return s.str();
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  using namespace ceres_sesync;
  gflags::SetUsageMessage(
      "landmarks [--quick] [--cases LIST] [--repeats N] [--out_dir DIR] ...\n"
      "SE-Sync vs Ceres PDL-GN/LM on generated landmark-SLAM graphs.");
  bench::InitBenchProgram(&argc, &argv);
  if (argc > 1) {
    std::fprintf(stderr, "landmarks: unexpected argument '%s'\n", argv[1]);
    return 2;
  }
  if (FLAGS_quick) FLAGS_repeats = FLAGS_ceres_repeats = 1;
  if (FLAGS_quick) FLAGS_min_time = 0;
  std::vector<Case> cases;
  {
    std::set<std::string> wanted;
    std::stringstream in(FLAGS_cases);
    std::string token;
    while (std::getline(in, token, ',')) {
      if (!token.empty()) wanted.insert(token);
    }
    for (const Case& c : LandmarkCases(FLAGS_quick)) {
      if (wanted.erase(c.name)) cases.push_back(c);
    }
    if (!wanted.empty()) {
      std::fprintf(stderr, "landmarks: unknown case '%s' in --cases\n",
                   wanted.begin()->c_str());
      return 2;
    }
  }
  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out_dir, ec);
  const std::string load_at_start = LoadAverage();

  std::vector<Row> rows;
  std::vector<std::string> case_lines;
  for (const Case& c : cases) {
    PoseGraph graph;
    Solution truth;
    std::string error;
    if (!GenerateLandmarkGraph(c.options, &graph, &truth, &error)) {
      std::fprintf(stderr, "landmarks: %s: %s\n", c.name.c_str(),
                   error.c_str());
      return 1;
    }
    const double f_truth = EvaluateObjective(graph, truth);
    const double f_expected = ExpectedGroundTruthObjective(graph);
    std::fprintf(stderr,
                 "%s: n = %d, landmarks = %d, landmark measurements = %zu, "
                 "priors = %zu; F(truth) = %.6e (expected %.6e)\n",
                 c.name.c_str(), graph.num_poses, graph.num_landmarks,
                 graph.landmark_measurements.size(), graph.priors.size(),
                 f_truth, f_expected);
    case_lines.push_back(
        "- `" + c.name + "`: " + Describe(c) + "; " +
        std::to_string(graph.num_landmarks) + " landmarks observed, " +
        Fmt("%.1f", static_cast<double>(graph.landmark_measurements.size()) /
                        graph.num_poses) +
        " landmark measurements per pose, " +
        std::to_string(graph.priors.size()) + " priors; F(truth) " +
        Fmt("%.6g", f_truth) + " (expected over the noise " +
        Fmt("%.6g", f_expected) + ")");

    const size_t first = rows.size();
    rows.push_back(RunSESync(c.name, graph, "chordal", nullptr, 0));
    const double f_sesync = rows[first].objective;

    // Odometry start (Ceres), timed with its landmark positions.
    auto start = Clock::now();
    Solution odometry;
    odometry.poses = OdometryInitialization(graph);
    odometry.landmarks = InitialLandmarkPositions(graph, odometry.poses);
    const double odometry_time_s = SecondsSince(start);
    rows.push_back(
        RunSESync(c.name, graph, "odometry", &odometry.poses, odometry_time_s));

    start = Clock::now();
    Solution chordal;
    if (!ChordalInitialization(graph, &chordal, &error)) {
      std::fprintf(stderr, "landmarks: %s: chordal initialization: %s\n",
                   c.name.c_str(), error.c_str());
      return 1;
    }
    const double chordal_time_s = SecondsSince(start);
    for (const auto method :
         {CeresBaselineOptions::Method::kPowellDogleg,
          CeresBaselineOptions::Method::kLevenbergMarquardt}) {
      rows.push_back(RunCeres(c.name, graph, method, "odometry", odometry,
                              odometry_time_s));
      rows.push_back(
          RunCeres(c.name, graph, method, "chordal", chordal, chordal_time_s));
    }
    for (size_t k = first; k < rows.size(); ++k) {
      rows[k].gap = (rows[k].objective - f_sesync) / f_sesync;
    }
  }

  // ---- output ----
  const std::string csv_path = FLAGS_out_dir + "/landmarks.csv";
  std::ofstream csv(csv_path);
  csv << "case,n,landmarks,m,landmark_measurements,priors,method,init,"
         "time_min_s,time_median_s,init_time_s,objective,gap_to_sesync,"
         "certified,lower_bound,rel_subopt_bound,proof,certify_time_s,"
         "iterations,status\n";
  for (const Row& r : rows) {
    csv << r.case_name << "," << r.n << "," << r.num_landmarks << "," << r.m
        << "," << r.num_landmark_measurements << "," << r.num_priors << ","
        << r.method << "," << r.init << "," << Fmt("%.6f", Min(r.times)) << ","
        << Fmt("%.6f", Median(r.times)) << "," << Fmt("%.6f", r.init_time_s)
        << "," << Fmt("%.12e", r.objective) << "," << Fmt("%.3e", r.gap) << ","
        << bench::CsvField(r.certified) << "," << Fmt("%.12e", r.lower_bound)
        << "," << Fmt("%.3e", r.rel_bound) << "," << bench::CsvField(r.proof)
        << "," << Fmt("%.6f", r.certify_time_s) << "," << r.iterations << ","
        << bench::CsvField(r.status) << "\n";
  }

  std::ostringstream md;
  md << "# Landmark benchmark: SE-Sync vs Ceres (`bench/landmarks`)\n\n"
     << "Command: `landmarks" << (FLAGS_quick ? " --quick" : "")
     << " --repeats " << FLAGS_repeats << " --ceres_repeats "
     << FLAGS_ceres_repeats << " --min_time " << FLAGS_min_time
     << " --ceres_max_time " << FLAGS_ceres_max_time << " --num_threads "
     << FLAGS_num_threads << "`. Load average (1/5/15 min) at start "
     << load_at_start << ", at end " << LoadAverage()
     << " (timings under load are not comparable across runs; ratios in one "
        "run are).\n\n"
     << "Cases (landmark_generator.h):\n";
  for (const std::string& line : case_lines) md << line << "\n";
  md << "\nTimes: minimum (median) over the repeats, in seconds, including "
        "the initialization (`init [s]`: odometry composition with first-"
        "sighting landmark positions, or the chordal solve with optimal "
        "landmark positions). `gap` = (F - F_SE-Sync) / F_SE-Sync. "
        "`certified` / `bound`: the SE-Sync rows are the solver's own "
        "certificate, the Ceres rows Certify() of the result (default "
        "tolerance 1e-3 on the proven relative suboptimality bound). `time / "
        "SE-Sync` is over SE-Sync from chordal.\n\n"
     << "| case | poses | landmarks | measurements (odometry + landmark + "
        "priors) | method | init | time [s] | init [s] | time / SE-Sync | F "
        "| gap | certified | proven bound | iterations | status |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  std::map<std::string, double> sesync_time;
  for (const Row& r : rows) {
    if (r.method == "SE-Sync" && r.init == "chordal") {
      sesync_time[r.case_name] = Min(r.times);
    }
  }
  for (const Row& r : rows) {
    const double t = Min(r.times);
    md << "| " << r.case_name << " | " << r.n << " | " << r.num_landmarks
       << " | " << r.m << " + " << r.num_landmark_measurements << " + "
       << r.num_priors << " | " << r.method << " | " << r.init << " | "
       << Fmt("%.3f", t) << " (" << Fmt("%.3f", Median(r.times)) << ") | "
       << Fmt("%.3f", r.init_time_s) << " | "
       << Fmt("%.2f", t / sesync_time[r.case_name]) << " | "
       << Fmt("%.9g", r.objective) << " | " << Fmt("%.1e", r.gap) << " | "
       << r.certified << " | " << Fmt("%.1e", r.rel_bound) << " | "
       << r.iterations << " | " << r.status << " |\n";
  }
  const std::string md_path = FLAGS_out_dir + "/landmarks.md";
  std::ofstream(md_path) << md.str();
  std::fputs(md.str().c_str(), stdout);
  if (!csv || !std::ifstream(md_path)) {
    std::fprintf(stderr, "landmarks: could not write to %s\n",
                 FLAGS_out_dir.c_str());
    return 1;
  }
  return 0;
}
