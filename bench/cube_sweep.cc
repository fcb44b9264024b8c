// Cube experiments of SE-Sync (Rosen et al., IJRR 2019, Section 6.1,
// Figure 3), SE-Sync versus Ceres local search.
//
//   cube_sweep [--quick] [--realizations N] [--out_dir DIR]
//              [--scaling_sides 5,8,...] [--scaling_time_limit S]
//              [--loop_closure_radius R] [--sweeps kappa,tau,pLC,s]
//              [--rms_angles 0.05,0.1,...] [--sesync_only]
//
// Sweeps one parameter at a time around the paper's defaults (kappa = 16.67,
// i.e. ~10 deg RMS rotation error; tau = 75, i.e. 0.2 m RMS translation
// error; pLC = 0.1; side s = 10, n = 1000):
//  - kappa, given as the RMS angular error (eq. 63) 0.05 .. 0.5 rad;
//  - tau, given as the RMS translational error sqrt(3 / tau) 0.05 .. 0.5 m;
//  - pLC in 0.05 .. 1;
//  - s in 5 .. 20 (n up to 8000);
// with N realizations (seeds 1..N) per setting, each solved by SE-Sync
// (default options, chordal initialization), Ceres PDL-GN and LM from the
// chordal initialization, and PDL-GN from odometry (--sesync_only: SE-Sync
// alone, for exactness studies). --loop_closure_radius sets the cube's
// loop-closure neighbourhood (CubeOptions::loop_closure_radius; 1 = lattice
// neighbours, sqrt(3) = the 3 x 3 x 3 block). Every run is timed from
// the generated graph (initializations included). For each realization,
// SE-Sync's certified lower bound LB also bounds every other method's
// suboptimality: gap = (F - LB) / LB.
//
// Then a scaling run: time versus n = s^3 for SE-Sync and PDL-GN (chordal),
// one realization per s; a method is dropped for larger s once one of its
// runs exceeds --scaling_time_limit.
//
// Output in --out_dir: cube_sweep_runs.csv (every run), cube_sweep.csv
// (medians per setting and method), cube_scaling.csv, cube_sweep.md (the
// median table, also printed to stdout). bench/plot_cube_sweep.py draws them.

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
#include <tuple>
#include <vector>

#include "bench/bench_util.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/chordal_initialization.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/langevin.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_bool(quick, false,
            "One realization, small cubes and few settings (seconds).");
DEFINE_int32(realizations, 5, "Realizations per parameter setting.");
DEFINE_string(out_dir, ".", "Directory for the CSV and Markdown outputs.");
DEFINE_string(scaling_sides, "5,8,10,12,15,20,25",
              "Cube sides of the scaling run (empty: skip it).");
DEFINE_double(scaling_time_limit, 180,
              "Scaling run: stop running a method at larger sides once one "
              "of its runs took longer than this many seconds.");
DEFINE_double(ceres_max_time, 120, "Wall-clock limit of each Ceres solve.");
DEFINE_bool(skip_sweeps, false, "Only the scaling run.");
DEFINE_string(sweeps, "kappa,tau,pLC,s",
              "Sweeps to run (comma-separated subset of kappa,tau,pLC,s).");
DEFINE_string(rms_angles, "",
              "RMS rotation errors of the kappa sweep, radians, comma-"
              "separated (empty: 0.05,0.1,0.15,0.2,0.25,0.3,0.35,0.4,0.5).");
DEFINE_double(loop_closure_radius, 1.0,
              "Loop-closure candidates: non-consecutive poses at most this "
              "many lattice units apart (1: lattice neighbours; 1.732: the "
              "3 x 3 x 3 block). See CubeOptions::loop_closure_radius.");
DEFINE_bool(sesync_only, false,
            "Run only SE-Sync (no Ceres baselines): exactness studies.");

namespace ceres_sesync {
namespace {

using bench::Clock;
using bench::Fmt;
using bench::Median;
using bench::ParseDoubles;
using bench::ParseInts;
using bench::SecondsSince;

// kappa whose Langevin RMS angle (eq. 63) is `rms` radians (bisection on
// log kappa; the RMS angle decreases monotonically in kappa).
double KappaForRmsAngle(double rms) {
  double lo = std::log(1e-3), hi = std::log(1e9);
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    if (LangevinAngularStandardDeviation(std::exp(mid)) > rms) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return std::exp(0.5 * (lo + hi));
}

struct Run {
  std::string sweep;  // kappa / tau / pLC / s / scaling.
  double x = 0;       // The swept quantity as plotted (see XLabel).
  CubeOptions cube;
  int n = 0, m = 0;
  int realization = 0;
  std::string method;
  double objective = NAN;
  double time_s = NAN;
  // SE-Sync only: the staircase certified the SDP solution, and the rounded
  // poses are also within 1e-6 relative of its lower bound (MLE certified).
  bool sdp_certified = false;
  bool certified = false;
  double rel_bound = NAN;  // SE-Sync: its own relative bound.
  double gap_to_lb = NAN;  // (F - LB_SE-Sync) / LB_SE-Sync.
  int iterations = 0;
  std::string status;
};

const char* XLabel(const std::string& sweep) {
  if (sweep == "kappa") return "rms_angle_rad";
  if (sweep == "tau") return "rms_translation_m";
  if (sweep == "pLC") return "pLC";
  return "side";
}

const std::vector<std::string>& AllMethods() {
  static const std::vector<std::string> methods = {
      "SE-Sync", "PDL-GN/chordal", "LM/chordal", "PDL-GN/odometry"};
  return methods;
}

std::vector<std::string> Methods() {
  if (FLAGS_sesync_only) return {"SE-Sync"};
  return AllMethods();
}

// Runs `methods` on one generated cube; appends to `runs`.
void RunCube(const std::string& sweep, double x, const CubeOptions& cube,
             int realization, const std::vector<std::string>& methods,
             std::vector<Run>* runs) {
  PoseGraph graph;
  std::string error;
  if (!GenerateCube(cube, &graph, nullptr, &error)) {
    LOG(FATAL) << "GenerateCube: " << error;
  }
  Run base;
  base.sweep = sweep;
  base.x = x;
  base.cube = cube;
  base.n = graph.num_poses;
  base.m = static_cast<int>(graph.measurements.size());
  base.realization = realization;
  double lower_bound = NAN;
  const size_t first = runs->size();
  for (const std::string& method : methods) {
    Run run = base;
    run.method = method;
    const auto start = Clock::now();
    if (method == "SE-Sync") {
      SolverSummary summary;
      Solve(graph, SolverOptions(), &summary);
      run.time_s = SecondsSince(start);
      run.objective = summary.objective;
      run.sdp_certified = summary.certified();
      run.certified =
          summary.certified() && summary.relative_suboptimality_bound <= 1e-6;
      run.rel_bound = summary.relative_suboptimality_bound;
      run.iterations = summary.iterations;
      run.status = summary.StatusString();
      if (std::isfinite(summary.lower_bound)) {
        lower_bound = summary.lower_bound;
      }
    } else {
      Poses initial;
      if (method.find("chordal") != std::string::npos) {
        if (!ChordalInitialization(graph, &initial, &error)) {
          LOG(FATAL) << "chordal: " << error;
        }
      } else {
        initial = OdometryInitialization(graph);
      }
      CeresBaselineOptions options;
      options.method = method.rfind("LM", 0) == 0
                           ? CeresBaselineOptions::Method::kLevenbergMarquardt
                           : CeresBaselineOptions::Method::kPowellDogleg;
      options.max_solver_time_s = FLAGS_ceres_max_time;
      Poses result;
      CeresBaselineSummary summary;
      if (!SolveWithCeres(graph, initial, options, &result, &summary, &error)) {
        run.status = "error: " + error;
      } else {
        run.time_s = SecondsSince(start);
        run.objective = summary.final_objective;
        run.iterations = summary.iterations;
        run.status = ceres::TerminationTypeToString(
            summary.solver_summary.termination_type);
      }
    }
    runs->push_back(run);
  }
  for (size_t k = first; k < runs->size(); ++k) {
    Run& r = (*runs)[k];
    if (std::isfinite(lower_bound) && lower_bound > 0) {
      r.gap_to_lb = (r.objective - lower_bound) / lower_bound;
    }
  }
  std::fprintf(stderr, "%-7s x=%-8.4g n=%-6d m=%-6d #%d:", sweep.c_str(), x,
               base.n, base.m, realization);
  for (size_t k = first; k < runs->size(); ++k) {
    std::fprintf(stderr, "  %s %.3fs F=%.5g", (*runs)[k].method.c_str(),
                 (*runs)[k].time_s, (*runs)[k].objective);
  }
  std::fputc('\n', stderr);
}

void WriteRuns(const std::string& path, const std::vector<Run>& runs) {
  std::ofstream out(path);
  out << "sweep,x,kappa,tau,pLC,radius,side,n,m,realization,method,objective,"
         "time_s,sdp_certified,certified,rel_subopt_bound,gap_to_sesync_lb,"
         "iterations,"
         "status\n";
  for (const Run& r : runs) {
    out << r.sweep << "," << r.x << "," << r.cube.kappa << "," << r.cube.tau
        << "," << r.cube.loop_closure_probability << ","
        << r.cube.loop_closure_radius << "," << r.cube.side << "," << r.n << ","
        << r.m << "," << r.realization << "," << r.method << ","
        << Fmt("%.10g", r.objective) << "," << Fmt("%.6g", r.time_s) << ","
        << (r.method == "SE-Sync" ? (r.sdp_certified ? "1" : "0") : "") << ","
        << (r.method == "SE-Sync" ? (r.certified ? "1" : "0") : "") << ","
        << Fmt("%.3e", r.rel_bound) << "," << Fmt("%.3e", r.gap_to_lb) << ","
        << r.iterations << "," << r.status << "\n";
  }
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  using namespace ceres_sesync;
  gflags::SetUsageMessage(
      "cube_sweep [--quick] [--realizations N] [--out_dir DIR]\n"
      "Figure 3 of the SE-Sync paper: cube experiments, SE-Sync vs Ceres.");
  bench::InitBenchProgram(&argc, &argv);

  CubeOptions defaults;  // kappa 16.67, tau 75, pLC 0.1, s 10.
  defaults.loop_closure_radius = FLAGS_loop_closure_radius;
  {
    // Validate the radius (and the rest of the defaults) once, up front.
    std::string error;
    CubeOptions probe = defaults;
    probe.side = 2;
    if (!GenerateCube(probe, nullptr, nullptr, &error)) {
      LOG(FATAL) << "invalid cube options: " << error;
    }
  }
  std::set<std::string> sweeps;
  for (const char* name : {"kappa", "tau", "pLC", "s"}) {
    if (("," + FLAGS_sweeps + ",").find(std::string(",") + name + ",") !=
        std::string::npos) {
      sweeps.insert(name);
    }
  }
  int realizations = std::max(1, FLAGS_realizations);
  std::vector<double> rms_angles = {0.05, 0.1,  0.15, 0.2, 0.25,
                                    0.3,  0.35, 0.4,  0.5};
  std::vector<double> rms_translations = {0.05, 0.1, 0.2, 0.3, 0.4, 0.5};
  std::vector<double> loop_closures = {0.05, 0.1, 0.2, 0.4, 0.6, 0.8, 1.0};
  std::vector<int> sides = {5, 8, 10, 12, 15, 20};
  std::vector<int> scaling_sides = ParseInts(FLAGS_scaling_sides);
  if (!FLAGS_rms_angles.empty()) rms_angles = ParseDoubles(FLAGS_rms_angles);
  int sweep_side = defaults.side;
  if (FLAGS_quick) {
    realizations = 1;
    if (FLAGS_rms_angles.empty()) rms_angles = {0.1, 0.3, 0.5};
    rms_translations = {0.1, 0.3};
    loop_closures = {0.1, 0.5};
    sides = {3, 4, 5};
    sweep_side = 4;
    if (gflags::GetCommandLineFlagInfoOrDie("scaling_sides").is_default) {
      scaling_sides = {3, 4, 5, 6};
    }
  }

  std::vector<Run> runs;
  if (!FLAGS_skip_sweeps) {
    for (int k = 1; k <= realizations; ++k) {
      CubeOptions base = defaults;
      base.side = sweep_side;
      base.seed = k;
      for (double rms :
           sweeps.count("kappa") ? rms_angles : std::vector<double>()) {
        CubeOptions c = base;
        c.kappa = KappaForRmsAngle(rms);
        RunCube("kappa", rms, c, k, Methods(), &runs);
      }
      for (double rms :
           sweeps.count("tau") ? rms_translations : std::vector<double>()) {
        CubeOptions c = base;
        c.tau = c.dimension / (rms * rms);
        RunCube("tau", rms, c, k, Methods(), &runs);
      }
      for (double p :
           sweeps.count("pLC") ? loop_closures : std::vector<double>()) {
        CubeOptions c = base;
        c.loop_closure_probability = p;
        RunCube("pLC", p, c, k, Methods(), &runs);
      }
      for (int s : sweeps.count("s") ? sides : std::vector<int>()) {
        CubeOptions c = base;
        c.side = s;
        RunCube("s", s, c, k, Methods(), &runs);
      }
    }
  }

  // Scaling: SE-Sync and PDL-GN (chordal), one realization per side.
  std::vector<Run> scaling;
  std::map<std::string, bool> dropped;
  for (int s : scaling_sides) {
    std::vector<std::string> methods;
    for (const char* m : {"SE-Sync", "PDL-GN/chordal"}) {
      if (!dropped[m] && (!FLAGS_sesync_only || std::string(m) == "SE-Sync")) {
        methods.push_back(m);
      }
    }
    if (methods.empty()) break;
    CubeOptions c = defaults;
    c.side = s;
    c.seed = 1;
    const size_t first = scaling.size();
    RunCube("scaling", s, c, 1, methods, &scaling);
    for (size_t k = first; k < scaling.size(); ++k) {
      if (!(scaling[k].time_s <= FLAGS_scaling_time_limit)) {
        dropped[scaling[k].method] = true;
      }
    }
  }

  std::error_code ec;
  std::filesystem::create_directories(FLAGS_out_dir, ec);
  WriteRuns(FLAGS_out_dir + "/cube_sweep_runs.csv", runs);
  WriteRuns(FLAGS_out_dir + "/cube_scaling.csv", scaling);

  // Medians per (sweep, x, method).
  struct Key {
    std::string sweep;
    double x;
    std::string method;
    bool operator<(const Key& o) const {
      return std::tie(sweep, x, method) < std::tie(o.sweep, o.x, o.method);
    }
  };
  struct Acc {
    int n = 0, m_sum = 0, count = 0, certified = 0;
    std::vector<double> f, t, bound, gap;
  };
  std::map<Key, Acc> acc;
  std::vector<Key> order;
  for (const Run& r : runs) {
    Key key{r.sweep, r.x, r.method};
    if (!acc.count(key)) order.push_back(key);
    Acc& a = acc[key];
    a.n = r.n;
    a.m_sum += r.m;
    ++a.count;
    a.certified += r.certified ? 1 : 0;
    a.f.push_back(r.objective);
    a.t.push_back(r.time_s);
    if (!std::isnan(r.rel_bound)) a.bound.push_back(r.rel_bound);
    if (!std::isnan(r.gap_to_lb)) a.gap.push_back(r.gap_to_lb);
  }
  std::ofstream csv(FLAGS_out_dir + "/cube_sweep.csv");
  csv << "sweep,x_name,x,n,mean_m,method,realizations,median_objective,"
         "median_time_s,median_rel_subopt_bound,certified_fraction,"
         "median_gap_to_sesync_lb,max_gap_to_sesync_lb\n";
  std::ostringstream md;
  md << "| sweep | x | n | method | median F | median time [s] | SE-Sync "
        "rel. bound | certified | median gap to LB | max gap to LB |\n"
        "|---|---|---|---|---|---|---|---|---|---|\n";
  // Sweeps in the order run, then by x, then methods in Methods() order.
  std::map<std::string, int> sweep_rank, method_rank;
  for (const Key& key : order) sweep_rank.emplace(key.sweep, sweep_rank.size());
  for (const std::string& m : AllMethods())
    method_rank.emplace(m, method_rank.size());
  std::sort(order.begin(), order.end(), [&](const Key& a, const Key& b) {
    return std::make_tuple(sweep_rank[a.sweep], a.x, method_rank[a.method]) <
           std::make_tuple(sweep_rank[b.sweep], b.x, method_rank[b.method]);
  });
  for (const Key& key : order) {
    const Acc& a = acc[key];
    const bool sesync = key.method == "SE-Sync";
    const double max_gap =
        a.gap.empty() ? NAN : *std::max_element(a.gap.begin(), a.gap.end());
    csv << key.sweep << "," << XLabel(key.sweep) << "," << key.x << "," << a.n
        << "," << static_cast<double>(a.m_sum) / a.count << "," << key.method
        << "," << a.count << "," << Fmt("%.10g", Median(a.f)) << ","
        << Fmt("%.6g", Median(a.t)) << ","
        << (sesync ? Fmt("%.3e", Median(a.bound)) : "") << ","
        << (sesync ? Fmt("%.3f", double(a.certified) / a.count) : "") << ","
        << Fmt("%.3e", Median(a.gap)) << "," << Fmt("%.3e", max_gap) << "\n";
    md << "| " << key.sweep << " | " << key.x << " | " << a.n << " | "
       << key.method << " | " << Fmt("%.6g", Median(a.f)) << " | "
       << Fmt("%.4f", Median(a.t)) << " | "
       << (sesync ? Fmt("%.1e", Median(a.bound)) : "") << " | "
       << (sesync ? std::to_string(a.certified) + "/" + std::to_string(a.count)
                  : "")
       << " | " << Fmt("%.1e", Median(a.gap)) << " | " << Fmt("%.1e", max_gap)
       << " |\n";
  }
  md << "\nScaling (one realization, kappa 16.67, tau 75, pLC 0.1, "
        "loop-closure radius "
     << defaults.loop_closure_radius
     << "):\n\n"
        "| s | n | m | method | time [s] | F | certified (MLE) | rel. bound |\n"
        "|---|---|---|---|---|---|---|---|\n";
  for (const Run& r : scaling) {
    md << "| " << r.cube.side << " | " << r.n << " | " << r.m << " | "
       << r.method << " | " << Fmt("%.4f", r.time_s) << " | "
       << Fmt("%.6g", r.objective) << " | "
       << (r.method == "SE-Sync" ? (r.certified ? "yes" : "no") : "") << " | "
       << (r.method == "SE-Sync" ? Fmt("%.1e", r.rel_bound) : "") << " |\n";
  }
  md << "\nRealizations per setting: " << realizations << "; sweeps at side "
     << sweep_side << " (n = " << sweep_side * sweep_side * sweep_side
     << ") unless swept; loop-closure radius " << defaults.loop_closure_radius
     << " lattice units. Certified = SE-Sync certified the SDP solution AND "
        "its "
        "rounded poses are within 1e-6 relative of the lower bound. Gap to LB "
        "= (F - LB) / LB with LB the lower bound "
        "SE-Sync certified on the same realization.\n";
  std::fputs(md.str().c_str(), stdout);
  std::ofstream(FLAGS_out_dir + "/cube_sweep.md") << md.str();
  return 0;
}
