// Scaling benchmark (issue #16): SE-Sync versus Ceres local search as the
// number of poses n grows, on generated maps: the city walk in 2D and 3D
// (city_generator.h, default CityOptions) and the 3D cube (cube_generator.h).
//
//   scaling [--quick] [--families city2d,city3d,cube] [--city2d_sizes LIST]
//           [--city3d_sizes LIST] [--cube_sides LIST] [--cube_kappa K]
//           [--cube_tau T] [--methods sesync,pdl,lm] [--ceres_max_time S]
//           [--sesync_max_time S] [--max_time S] [--child_timeout S]
//           [--max_memory_gb G] [--repeats N] [--num_threads N] [--seed N]
//           [--out_dir DIR]
//
// Every run (graph, method, repeat) is a child process (fork) that generates
// the graph itself (deterministic for the seed; not timed as part of the
// method) and then runs one method:
//  - sesync: Solve() with default SolverOptions (chordal initialization);
//    the stage times (data matrices, initialization, optimization,
//    verification, rounding incl. refinement) come from SolverSummary;
//  - pdl, lm: ChordalInitialization, then Ceres PDL-GN or LM from it
//    (SolveWithCeres, --ceres_max_time); the time includes the chordal
//    initialization, as in bench.cc.
// One process per run gives each its own peak RSS (VmHWM at the end of the
// child, which includes the graph; "graph" = VmHWM right after generating
// it), and a crash, a --child_timeout kill or an allocation failure at the
// --max_memory_gb address-space limit loses only that run.
//
// Ceres results are compared with SE-Sync's proven lower bound LB on the same
// graph: gap = (F - LB) / LB. Time ratios are method / SE-Sync. Log-log
// slopes of time versus n are least-squares fits over all sizes, over the
// sizes n >= 10^4 (the range of the goal), and between consecutive
// sizes. Once a run of a method takes longer than --max_time (or fails), the
// method is skipped at the larger sizes of that family.
//
// Output in --out_dir: scaling.csv (one row per graph and method: the fastest
// repeat), scaling.md (tables and slopes, also printed to stdout).
// bench/plot_scaling.py draws scaling.png from scaling.csv.

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
#include <thread>
#include <vector>

#include "bench/bench_util.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(quick, false,
            "Small sizes only (2D city 1000 and 3000, 3D city 1000, cube "
            "sides 5 and 8): a smoke run of a few seconds.");
DEFINE_string(families, "city2d,city3d,cube",
              "Comma-separated graph families: city2d, city3d, cube.");
DEFINE_string(city2d_sizes, "1000,3000,10000,30000,100000,300000,1000000",
              "Numbers of poses of the 2D city runs.");
DEFINE_string(city3d_sizes, "1000,3000,10000,30000,100000",
              "Numbers of poses of the 3D city runs (the fill of the 3D "
              "factorizations grows fast: 10^5 already takes minutes).");
DEFINE_string(cube_sides, "10,15,22,30,46",
              "Sides s of the 3D cube runs (n = s^3; 46 is the issue's "
              "97,336-pose cube).");
DEFINE_double(cube_kappa, 100,
              "kappa of the cube runs (the issue's 97k cube: 100; the paper's "
              "default 16.67 makes large cubes very slow).");
DEFINE_double(cube_tau, 400, "tau of the cube runs (the issue's: 400).");
DEFINE_string(methods, "sesync,pdl,lm",
              "Comma-separated methods: sesync (SE-Sync), pdl (Ceres PDL-GN "
              "from chordal), lm (Ceres LM from chordal).");
DEFINE_double(ceres_max_time, 600,
              "Wall-clock limit of each Ceres solve, in seconds.");
DEFINE_double(sesync_max_time, 0,
              "SolverOptions::max_time_s of the SE-Sync runs (0: none).");
DEFINE_double(max_time, 1800,
              "Skip a method at the larger sizes of a family once one of its "
              "runs took longer than this many seconds.");
DEFINE_double(child_timeout, 7200,
              "Kill a run (child process) after this many seconds.");
DEFINE_double(max_memory_gb, 20,
              "Address-space limit (RLIMIT_AS) of each run's process, in GiB "
              "(0: none): a run that needs more fails (reported) instead of "
              "driving a shared machine into the OOM killer.");
DEFINE_int32(repeats, 1,
             "Runs per graph and method (the fastest is reported).");
DEFINE_int32(num_threads, 1,
             "Threads for SE-Sync (SolverOptions::num_threads) and Ceres.");
DEFINE_uint64(seed, 1, "Seed of every generated graph.");
DEFINE_string(out_dir, ".", "Directory for scaling.csv and scaling.md.");

namespace ceres_sesync {
namespace {

using bench::BlasLibrary;
using bench::Clock;
using bench::CsvField;
using bench::Fmt;
using bench::Median;
using bench::SecondsSince;

// What a child reports through its pipe (plain data, fixed size).
struct RunResult {
  int n = 0, m = 0, d = 0;
  double generate_s = NAN, graph_rss_mib = NAN, peak_rss_mib = NAN;
  double time_s = NAN;
  double data_s = NAN, initialization_s = NAN, optimization_s = NAN,
         verification_s = NAN, rounding_s = NAN;
  double chordal_s = NAN;
  double objective = NAN, lower_bound = NAN, rel_bound = NAN,
         rounding_gap = NAN;
  int iterations = -1, hessian_vector_products = -1, factorizations = -1,
      rank = -1;
  bool certified = false;
  char status[200] = {};
};

void SetStatus(RunResult* r, const std::string& status) {
  std::snprintf(r->status, sizeof(r->status), "%s", status.c_str());
}

// One row of the output: a graph, a method, the fastest repeat.
struct Row {
  std::string family;
  int size = 0;  // n for the cities, the side for the cube.
  std::string method;
  std::vector<double> times;
  RunResult result;
  bool ok = false;
  double ratio = NAN;  // time / SE-Sync time.
  double gap = NAN;    // (F - LB_SE-Sync) / LB_SE-Sync.
};

const char* MethodName(const std::string& method) {
  if (method == "sesync") return "SE-Sync";
  if (method == "pdl") return "PDL-GN";
  return "LM";
}

bool MakeGraph(const std::string& family, int size, PoseGraph* graph,
               std::string* error) {
  if (family == "cube") {
    CubeOptions options;
    options.side = size;
    options.kappa = FLAGS_cube_kappa;
    options.tau = FLAGS_cube_tau;
    options.seed = FLAGS_seed;
    return GenerateCube(options, graph, nullptr, error);
  }
  CityOptions options;
  options.dimension = family == "city3d" ? 3 : 2;
  options.num_poses = size;
  options.seed = FLAGS_seed;
  return GenerateCity(options, graph, nullptr, error);
}

// Runs `method` on the graph (in the child process).
RunResult RunMethod(const std::string& family, int size,
                    const std::string& method) {
  RunResult r;
  PoseGraph graph;
  std::string error;
  auto start = Clock::now();
  if (!MakeGraph(family, size, &graph, &error)) {
    SetStatus(&r, "generate: " + error);
    return r;
  }
  r.generate_s = SecondsSince(start);
  r.graph_rss_mib = bench::PeakRssMiB();
  r.n = graph.num_poses;
  r.m = static_cast<int>(graph.measurements.size());
  r.d = graph.dimension;
  if (method == "sesync") {
    SolverOptions options;
    options.num_threads = FLAGS_num_threads;
    options.max_time_s = FLAGS_sesync_max_time;
    SolverSummary s;
    start = Clock::now();
    Solve(graph, options, &s);
    r.time_s = SecondsSince(start);
    r.data_s = s.data_time_s;
    r.initialization_s = s.initialization_time_s;
    r.optimization_s = s.optimization_time_s;
    r.verification_s = s.verification_time_s;
    r.rounding_s = s.rounding_time_s;
    r.objective = s.objective;
    r.lower_bound = s.lower_bound;
    r.rel_bound = s.relative_suboptimality_bound;
    r.rounding_gap = s.rounding_gap;
    r.iterations = s.iterations;
    r.hessian_vector_products = s.hessian_vector_products;
    r.factorizations = s.factorizations;
    r.rank = s.final_rank;
    r.certified = s.certified();
    SetStatus(&r, s.StatusString());
  } else {
    start = Clock::now();
    Poses chordal;
    if (!ChordalInitialization(graph, &chordal, &error)) {
      SetStatus(&r, "chordal: " + error);
      return r;
    }
    r.chordal_s = SecondsSince(start);
    CeresBaselineOptions options;
    options.method = method == "pdl"
                         ? CeresBaselineOptions::Method::kPowellDogleg
                         : CeresBaselineOptions::Method::kLevenbergMarquardt;
    options.max_solver_time_s = FLAGS_ceres_max_time;
    options.num_threads = FLAGS_num_threads;
    Poses result;
    CeresBaselineSummary summary;
    if (!SolveWithCeres(graph, chordal, options, &result, &summary, &error)) {
      SetStatus(&r, "ceres: " + error);
      return r;
    }
    r.time_s = SecondsSince(start);
    r.objective = summary.final_objective;
    r.iterations = summary.iterations;
    SetStatus(&r, bench::CeresStatus(summary));
  }
  r.peak_rss_mib = bench::PeakRssMiB();
  return r;
}

// Runs `method` in a child process; false (with a status in `result`) if the
// child failed, was killed or reported nothing.
bool RunInChild(const std::string& family, int size, const std::string& method,
                RunResult* result) {
  *result = RunResult();
  std::string failure;
  if (bench::RunInChildProcess(
          FLAGS_child_timeout, FLAGS_max_memory_gb,
          [&] { return RunMethod(family, size, method); }, result, &failure)) {
    return !std::isnan(result->time_s);
  }
  *result = RunResult();
  SetStatus(result, failure);
  return false;
}

// Least-squares slope of log(y) against log(x) over the points with x >=
// min_x (NaN with fewer than two).
double LogLogSlope(const std::vector<std::pair<double, double>>& points,
                   double min_x = 0) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int k = 0;
  for (const auto& [x, y] : points) {
    if (x < min_x || !(x > 0 && y > 0)) continue;
    const double lx = std::log(x), ly = std::log(y);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++k;
  }
  if (k < 2) return NAN;
  const double denominator = k * sxx - sx * sx;
  return denominator > 0 ? (k * sxy - sx * sy) / denominator : NAN;
}

std::string LoadAverage() {
  std::ifstream in("/proc/loadavg");
  double one = NAN, five = NAN, fifteen = NAN;
  in >> one >> five >> fifteen;
  return Fmt("%.2f", one) + " / " + Fmt("%.2f", five) + " / " +
         Fmt("%.2f", fifteen);
}

std::set<std::string> ParseSet(const std::string& list,
                               const std::set<std::string>& allowed,
                               const char* flag) {
  std::set<std::string> out;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) continue;
    if (!allowed.count(item)) {
      std::fprintf(stderr, "scaling: unknown item '%s' in --%s\n", item.c_str(),
                   flag);
      std::exit(2);
    }
    out.insert(item);
  }
  return out;
}

std::string FamilyDescription(const std::string& family) {
  if (family == "cube") {
    return "3D cube (cube_generator.h), kappa " + Fmt("%g", FLAGS_cube_kappa) +
           ", tau " + Fmt("%g", FLAGS_cube_tau) + ", pLC 0.1, radius 1";
  }
  const CityOptions o;
  return std::string(family == "city3d" ? "3D" : "2D") +
         " city (city_generator.h, default CityOptions: kappa " +
         Fmt("%g", o.kappa) + ", tau " + Fmt("%g", o.tau) + ", pLC " +
         Fmt("%g", o.loop_closure_probability) +
         " (<= " + std::to_string(o.max_loop_closures_per_visit) +
         " per visit), turn " + Fmt("%g", o.turn_probability) +
         ", lattice scale " + Fmt("%g", o.lattice_scale) +
         (family == "city3d" ? ", " + std::to_string(o.levels) + " levels"
                             : std::string()) +
         ")";
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  using namespace ceres_sesync;
  gflags::SetUsageMessage(
      "scaling [--quick] [--families city2d,city3d,cube] [--methods "
      "sesync,pdl,lm] [--out_dir DIR] ...\n"
      "SE-Sync vs Ceres PDL-GN/LM as n grows (one child process per run).");
  bench::InitBenchProgram(&argc, &argv);
  if (argc > 1) {
    std::fprintf(stderr, "scaling: unexpected argument '%s'\n", argv[1]);
    return 2;
  }
  const std::set<std::string> families =
      ParseSet(FLAGS_families, {"city2d", "city3d", "cube"}, "families");
  const std::set<std::string> methods =
      ParseSet(FLAGS_methods, {"sesync", "pdl", "lm"}, "methods");
  std::map<std::string, std::vector<int>> sizes;
  try {
    sizes["city2d"] = bench::ParseInts(FLAGS_city2d_sizes);
    sizes["city3d"] = bench::ParseInts(FLAGS_city3d_sizes);
    sizes["cube"] = bench::ParseInts(FLAGS_cube_sides);
  } catch (const std::exception&) {
    std::fprintf(stderr, "scaling: malformed size list\n");
    return 2;
  }
  if (FLAGS_quick) {
    auto keep = [](const char* flag) {
      return !gflags::GetCommandLineFlagInfoOrDie(flag).is_default;
    };
    if (!keep("city2d_sizes")) sizes["city2d"] = {1000, 3000};
    if (!keep("city3d_sizes")) sizes["city3d"] = {1000};
    if (!keep("cube_sides")) sizes["cube"] = {5, 8};
  }
  for (auto& [family, list] : sizes) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  const std::vector<std::string> family_order = {"city2d", "city3d", "cube"};
  const std::vector<std::string> method_order = {"sesync", "pdl", "lm"};
  const int repeats = std::max(1, FLAGS_repeats);
  const std::string load_at_start = LoadAverage();
  const auto start = Clock::now();

  std::vector<Row> rows;
  int failures = 0;
  for (const std::string& family : family_order) {
    if (!families.count(family)) continue;
    std::set<std::string> dropped;
    for (int size : sizes[family]) {
      for (const std::string& method : method_order) {
        if (!methods.count(method)) continue;
        Row row;
        row.family = family;
        row.size = size;
        row.method = method;
        if (dropped.count(method)) {
          SetStatus(&row.result,
                    "skipped (slower than --max_time at a "
                    "smaller size, or failed)");
          std::fprintf(stderr, "%-6s size %-8d %-7s %s\n", family.c_str(), size,
                       MethodName(method), row.result.status);
          rows.push_back(row);
          continue;
        }
        for (int k = 0; k < repeats; ++k) {
          RunResult r;
          const bool ok = RunInChild(family, size, method, &r);
          if (!ok) {
            row.ok = false;
            row.result = r;
            ++failures;
            break;
          }
          row.times.push_back(r.time_s);
          if (!row.ok || r.time_s < row.result.time_s) row.result = r;
          row.ok = true;
        }
        const RunResult& r = row.result;
        std::fprintf(stderr,
                     "%-6s size %-8d n %-8d m %-8d %-7s %9.3f s  F %.8e  "
                     "RSS %6.0f MiB  %s\n",
                     family.c_str(), size, r.n, r.m, MethodName(method),
                     r.time_s, r.objective, r.peak_rss_mib, r.status);
        if (!row.ok || !(r.time_s <= FLAGS_max_time)) dropped.insert(method);
        rows.push_back(row);
      }
    }
  }

  // Ratios and gaps against SE-Sync on the same graph.
  std::map<std::pair<std::string, int>, const Row*> sesync;
  for (const Row& row : rows) {
    if (row.method == "sesync" && row.ok) sesync[{row.family, row.size}] = &row;
  }
  for (Row& row : rows) {
    auto it = sesync.find({row.family, row.size});
    if (!row.ok || it == sesync.end()) continue;
    const RunResult& s = it->second->result;
    row.ratio = row.result.time_s / s.time_s;
    if (s.lower_bound > 0) {
      row.gap = (row.result.objective - s.lower_bound) / s.lower_bound;
    }
  }

  // Markdown.
  std::ostringstream md;
  md << "# Scaling: SE-Sync vs Ceres PDL-GN and LM from the chordal "
        "initialization\n\n"
     << "Each run in its own process; " << FLAGS_num_threads << " thread(s); "
     << std::thread::hardware_concurrency() << " hardware threads; BLAS "
     << BlasLibrary() << "; load average (1 / 5 / 15 min) at start "
     << load_at_start << ", at end " << LoadAverage()
     << " (timings taken under load are not comparable); Ceres limit "
     << FLAGS_ceres_max_time << " s; address-space limit per run "
     << (FLAGS_max_memory_gb > 0 ? Fmt("%g GiB", FLAGS_max_memory_gb)
                                 : std::string("none"))
     << "; fastest of " << repeats << " run(s); wall time of the whole bench "
     << Fmt("%.0f", SecondsSince(start))
     << " s. SE-Sync [s] is the wall time of Solve() (stages: data matrices, "
        "chordal initialization, staircase optimization, verification, "
        "rounding incl. refinement); Ceres times include the chordal "
        "initialization. gap = (F - LB) / LB with LB SE-Sync's proven lower "
        "bound. RSS = peak resident set of the run's process, graph "
        "included.\n";
  for (const std::string& family : family_order) {
    if (!families.count(family)) continue;
    md << "\n## " << family << ": " << FamilyDescription(family) << "\n\n"
       << "| n | m | generate [s] | SE-Sync [s] | data | init | optimize | "
          "verify | round | iters | Hv | ms / Hv | fact. | rank | status | "
          "rel. bound | RSS [MiB] | PDL-GN [s] | PDL-GN / SE-Sync | PDL-GN "
          "gap | PDL-GN status | LM [s] | LM / SE-Sync | LM gap | LM status | "
          "RSS PDL-GN [MiB] |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
          "---|---|---|---|---|---|---|---|---|---|\n";
    for (int size : sizes[family]) {
      const Row* by_method[3] = {nullptr, nullptr, nullptr};
      for (const Row& row : rows) {
        if (row.family != family || row.size != size) continue;
        for (int k = 0; k < 3; ++k) {
          if (row.method == method_order[k]) by_method[k] = &row;
        }
      }
      const Row* s = by_method[0];
      const Row* any = nullptr;  // The row that names the graph.
      for (const Row* row : by_method) {
        if (row && (row->ok || !any)) any = row;
        if (any && any->ok) break;
      }
      if (!any) continue;
      const RunResult& g = any->result;
      md << "| " << (g.n ? std::to_string(g.n) : "size " + std::to_string(size))
         << " | " << (g.m ? std::to_string(g.m) : "") << " | "
         << Fmt("%.2f", g.generate_s) << " | ";
      if (s && s->ok) {
        const RunResult& r = s->result;
        md << Fmt("%.3f", r.time_s) << " | " << Fmt("%.3f", r.data_s) << " | "
           << Fmt("%.3f", r.initialization_s) << " | "
           << Fmt("%.3f", r.optimization_s) << " | "
           << Fmt("%.3f", r.verification_s) << " | "
           << Fmt("%.3f", r.rounding_s) << " | " << r.iterations << " | "
           << r.hessian_vector_products << " | "
           << (r.hessian_vector_products > 0
                   ? Fmt("%.2f",
                         1e3 * r.optimization_s / r.hessian_vector_products)
                   : "")
           << " | " << r.factorizations << " | " << r.rank << " | " << r.status
           << " | " << Fmt("%.1e", r.rel_bound) << " | "
           << Fmt("%.0f", r.peak_rss_mib) << " | ";
      } else {
        md << " | | | | | | | | | | | " << (s ? s->result.status : "")
           << " | | | ";
      }
      for (int k = 1; k < 3; ++k) {
        const Row* c = by_method[k];
        if (c && c->ok) {
          md << Fmt("%.3f", c->result.time_s) << " | " << Fmt("%.2f", c->ratio)
             << " | " << Fmt("%.1e", c->gap) << " | " << c->result.status
             << ", " << c->result.iterations << " it | ";
        } else {
          md << " | | | " << (c ? c->result.status : "") << " | ";
        }
      }
      md << (by_method[1] && by_method[1]->ok
                 ? Fmt("%.0f", by_method[1]->result.peak_rss_mib)
                 : "")
         << " |\n";
    }
  }

  md << "\n## Log-log slopes\n\nd log(time) / d log(n) (least squares), and "
        "of SE-Sync's peak RSS; segments are between consecutive sizes.\n\n"
        "| family | method | quantity | sizes | slope (all) | slope (n >= "
        "1e4) | segments |\n|---|---|---|---|---|---|---|\n";
  for (const std::string& family : family_order) {
    if (!families.count(family)) continue;
    for (const std::string& method : method_order) {
      for (const char* quantity : {"time", "peak RSS"}) {
        const bool rss = std::string(quantity) == "peak RSS";
        if (rss && method != "sesync") continue;
        std::vector<std::pair<double, double>> points;
        for (const Row& row : rows) {
          if (row.family != family || row.method != method || !row.ok) continue;
          points.push_back({double(row.result.n),
                            rss ? row.result.peak_rss_mib : row.result.time_s});
        }
        if (points.size() < 2) continue;
        std::string segments;
        for (size_t k = 1; k < points.size(); ++k) {
          segments += (k > 1 ? ", " : "") +
                      Fmt("%.2f", LogLogSlope({points[k - 1], points[k]}));
        }
        md << "| " << family << " | " << MethodName(method) << " | " << quantity
           << " | " << Fmt("%.0f", points.front().first) << " .. "
           << Fmt("%.0f", points.back().first) << " | "
           << Fmt("%.2f", LogLogSlope(points)) << " | "
           << Fmt("%.2f", LogLogSlope(points, 1e4)) << " | " << segments
           << " |\n";
      }
    }
  }
  std::fputs(md.str().c_str(), stdout);

  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out_dir, ec);
  {
    std::ofstream out(FLAGS_out_dir + "/scaling.md");
    out << md.str();
    if (!out) {
      std::fprintf(stderr, "scaling: cannot write %s/scaling.md\n",
                   FLAGS_out_dir.c_str());
      return 2;
    }
  }
  std::ofstream csv(FLAGS_out_dir + "/scaling.csv");
  csv << "family,size,d,n,m,method,runs,time_s,time_median_s,generate_s,"
         "data_s,initialization_s,optimization_s,verification_s,rounding_s,"
         "chordal_s,iterations,hessian_vector_products,factorizations,rank,"
         "objective,lower_bound,rel_subopt_bound,rounding_gap,certified,"
         "status,graph_rss_mib,peak_rss_mib,time_ratio_to_sesync,"
         "gap_to_sesync_lb\n";
  for (const Row& row : rows) {
    const RunResult& r = row.result;
    auto integer = [](int v) { return v >= 0 ? std::to_string(v) : ""; };
    csv << row.family << "," << row.size << "," << (r.d ? integer(r.d) : "")
        << "," << (r.n ? integer(r.n) : "") << "," << (r.m ? integer(r.m) : "")
        << "," << MethodName(row.method) << "," << row.times.size() << ","
        << Fmt("%.6g", r.time_s) << "," << Fmt("%.6g", Median(row.times)) << ","
        << Fmt("%.6g", r.generate_s) << "," << Fmt("%.6g", r.data_s) << ","
        << Fmt("%.6g", r.initialization_s) << ","
        << Fmt("%.6g", r.optimization_s) << "," << Fmt("%.6g", r.verification_s)
        << "," << Fmt("%.6g", r.rounding_s) << "," << Fmt("%.6g", r.chordal_s)
        << "," << integer(r.iterations) << ","
        << integer(r.hessian_vector_products) << ","
        << integer(r.factorizations) << "," << integer(r.rank) << ","
        << Fmt("%.12g", r.objective) << "," << Fmt("%.12g", r.lower_bound)
        << "," << Fmt("%.3e", r.rel_bound) << "," << Fmt("%.3e", r.rounding_gap)
        << ","
        << (row.method == "sesync" && row.ok ? (r.certified ? "yes" : "no")
                                             : "")
        << "," << CsvField(r.status) << "," << Fmt("%.1f", r.graph_rss_mib)
        << "," << Fmt("%.1f", r.peak_rss_mib) << "," << Fmt("%.4g", row.ratio)
        << "," << Fmt("%.3e", row.gap) << "\n";
  }
  if (!csv) {
    std::fprintf(stderr, "scaling: cannot write %s/scaling.csv\n",
                 FLAGS_out_dir.c_str());
    return 2;
  }
  return failures ? 1 : 0;
}
