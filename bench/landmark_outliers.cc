// Outlier benchmark for landmark-SLAM graphs (robust_solver.h with
// landmarks and priors): wrong data associations and false GPS fixes
// (AddLandmarkOutliers, outlier_generator.h) on generated graphs
// (landmark_generator.h), solved by SolveRobust.
//
//   landmark_outliers [--quick] [--cases LIST] [--fractions LIST]
//                     [--kinds both|landmarks|priors] [--seeds N]
//                     [--methods sesync,ceres] [--num_threads N]
//                     [--mu_step X] [--max_removal_trials N]
//                     [--out_dir DIR]
//
// Cases (seed 1, GPS-like position priors every 20th pose, 1 m RMS, and a
// start prior: the solutions are in the world frame):
//  - manhattan2d_gps: 2D walk, 2000 poses in a 40 m box, 400 landmarks
//                     drawn, 5 m sensor range (landmark_nu 25: 0.2 m);
//  - manhattan3d_gps: 3D walk, 2000 poses in a 20 m box, 600 landmarks;
//  - victoria_gps:    VictoriaParkLikeOptions() (~30 landmarks per pose).
// --quick: 300 poses per case.
//
// Methods (--methods): SE-Sync GNC (SolveRobust with default options), and
// Ceres Levenberg-Marquardt with HuberLoss and with CauchyLoss on every term
// (ceres_baseline.h; a^2 = each kind's default TLS threshold), from the
// odometry in the priors' frame with each landmark at its first
// observation; their verdicts are f_k > c_k^2 at their result, and they
// certify nothing.
//
// Per case, fraction F and seed s: F of the output's landmark measurements
// are wrong associations and F of its position priors false fixes
// (LandmarkOutlierOptions{F, F, s}; --kinds: one of the two only). Reported
// against the injected outliers: precision and recall of the rejections per
// kind; "ties": wrong associations accepted on landmarks that one pose alone
// observes truly (that observation and the wrong one fit equally well: not
// identifiable); the largest rotation and translation error of the poses
// against the clean graph's certified optimum (both in the world frame) and the
// clean graph's objective at the result's poses (landmarks at their optimal
// positions for them) relative to that optimum. success: every rejection rate
// and precision >= 99%, no relative pose measurement rejected, clean gap <=
// 1e-6, certified.
//
// Output in --out_dir: landmark_outliers_KINDS.csv and .md.

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/internal/chi_square.h"
#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/outlier_generator.h"
#include "ceres_sesync/robust_solver.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"

DEFINE_bool(quick, false, "300 poses per case.");
DEFINE_string(cases, "manhattan2d_gps,manhattan3d_gps,victoria_gps",
              "Comma-separated cases: manhattan2d_gps, manhattan3d_gps, "
              "victoria_gps.");
DEFINE_string(fractions, "0.1,0.3,0.5",
              "Outlier fractions (of the landmark measurements and of the "
              "position priors alike, see --kinds).");
DEFINE_string(kinds, "both",
              "Which outliers: both (wrong associations and false fixes), "
              "landmarks (wrong associations only) or priors (false fixes "
              "only).");
DEFINE_int32(seeds, 3, "Seeds 1..N per case and fraction.");
DEFINE_int32(num_threads, 1, "SolverOptions::num_threads.");
DEFINE_double(mu_step, ceres_sesync::RobustSolverOptions().mu_step,
              "RobustSolverOptions::mu_step.");
DEFINE_int32(max_removal_trials,
             ceres_sesync::RobustSolverOptions().max_removal_trials,
             "RobustSolverOptions::max_removal_trials.");
DEFINE_string(out_dir, ".", "Directory for the outputs.");
DEFINE_string(methods, "sesync,ceres",
              "sesync (SolveRobust) and/or ceres (Levenberg-Marquardt with "
              "Huber and with Cauchy losses on every term).");
DEFINE_double(ceres_max_time, 60, "Ceres time limit per run, seconds.");

namespace ceres_sesync::bench {
namespace {

// The landmark bench's maps with priors, and its Victoria-Park-like map
// with the same GPS priors and start prior.
std::vector<LandmarkCase> AllCases(bool quick) {
  std::vector<LandmarkCase> cases;
  for (LandmarkCase c : LandmarkCases(quick)) {
    if (c.name == "victoria") {
      c.name = "victoria_gps";
      c.options.gps_interval = 20;
      c.options.start_prior = true;
    }
    if (c.options.gps_interval > 0) cases.push_back(c);
  }
  return cases;
}

struct Rates {
  int added = 0, rejected = 0, rejected_wrong = 0;
  double precision() const {
    return rejected > 0 ? static_cast<double>(rejected_wrong) / rejected : 1;
  }
  double recall() const {
    return added > 0 ? static_cast<double>(rejected_wrong) / added : 1;
  }
};

Rates Count(const std::vector<int>& added, const std::vector<int>& rejected) {
  const std::set<int> wrong(added.begin(), added.end());
  Rates r;
  r.added = static_cast<int>(added.size());
  r.rejected = static_cast<int>(rejected.size());
  for (int k : rejected) r.rejected_wrong += wrong.count(k) > 0;
  return r;
}

int Main() {
  std::vector<LandmarkCase> cases;
  const std::set<std::string> wanted = [] {
    std::set<std::string> names;
    std::string item;
    for (char c : FLAGS_cases + ",") {
      if (c != ',') {
        item += c;
      } else if (!item.empty()) {
        names.insert(item);
        item.clear();
      }
    }
    return names;
  }();
  for (const LandmarkCase& c : AllCases(FLAGS_quick)) {
    if (wanted.count(c.name)) cases.push_back(c);
  }
  if (cases.size() != wanted.size()) {
    std::fprintf(stderr, "unknown case in --cases '%s'\n", FLAGS_cases.c_str());
    return 2;
  }
  const std::vector<double> fractions = ParseDoubles(FLAGS_fractions);
  std::set<std::string> methods;
  {
    std::string item;
    for (char ch : FLAGS_methods + ",") {
      if (ch != ',') {
        item += ch;
      } else if (!item.empty()) {
        if (item != "sesync" && item != "ceres") {
          std::fprintf(stderr, "unknown method '%s'\n", item.c_str());
          return 2;
        }
        methods.insert(item);
        item.clear();
      }
    }
  }
  if (FLAGS_kinds != "both" && FLAGS_kinds != "landmarks" &&
      FLAGS_kinds != "priors") {
    std::fprintf(stderr, "--kinds must be both, landmarks or priors\n");
    return 2;
  }
  const std::string base = FLAGS_out_dir + "/landmark_outliers_" + FLAGS_kinds;
  const std::string csv_path = base + ".csv";
  const std::string md_path = base + ".md";
  std::ofstream csv(csv_path), md(md_path);
  if (!csv || !md) {
    std::fprintf(stderr, "cannot write to %s\n", FLAGS_out_dir.c_str());
    return 2;
  }
  csv << "case,method,d,n,landmarks,landmark_measurements,priors,fraction,seed,"
         "wrong_associations,rejected_landmark,rejected_wrong_landmark,"
         "landmark_precision,landmark_recall,ties,false_fixes,"
         "rejected_priors,rejected_false_priors,prior_precision,"
         "prior_recall,rejected_measurements,max_rotation_error_deg,"
         "max_translation_error,clean_gap,certified,time_s,success,status\n";
  md << "# Wrong landmark associations and false GPS fixes: SolveRobust\n\n"
        "Generated by `bench/landmark_outliers` (see its header for the "
        "cases and metrics); "
     << FLAGS_num_threads << " thread(s), mu_step " << FLAGS_mu_step
     << ", max_removal_trials " << FLAGS_max_removal_trials
     << ", outliers: " << FLAGS_kinds
     << ". Precision / recall of the rejections per kind "
        "(landmark: wrong associations; prior: false fixes); ties: wrong "
        "associations accepted on landmarks one pose alone observes truly "
        "(not identifiable); errors and gap against the clean graph's "
        "certified optimum.\n\n"
        "| case | method | d | n | L | M | P | F | seed | wrong | lm. "
        "precision | "
        "lm. recall | ties | fixes | prior precision | prior recall | "
        "edges rejected | max rot. err [deg] | max trans. err | clean gap | "
        "certified | time [s] | success |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
        "---|---|---|---|---|---|---|\n";
  for (const LandmarkCase& c : cases) {
    PoseGraph clean;
    std::string error;
    if (!GenerateLandmarkGraph(c.options, &clean, nullptr, &error)) {
      std::fprintf(stderr, "%s: %s\n", c.name.c_str(), error.c_str());
      return 1;
    }
    SolverOptions options;
    options.num_threads = FLAGS_num_threads;
    SolverSummary clean_summary;
    Solution optimum;
    Solve(clean, options, &optimum, &clean_summary);
    std::vector<int> seen_by(clean.num_landmarks, 0);
    for (const LandmarkMeasurement& o : clean.landmark_measurements) {
      ++seen_by[o.l];
    }
    std::printf(
        "%s: n %d, %d landmarks, %zu landmark measurements, %zu "
        "priors; clean optimum %s F = %.10g\n",
        c.name.c_str(), clean.num_poses, clean.num_landmarks,
        clean.landmark_measurements.size(), clean.priors.size(),
        clean_summary.certified() ? "certified" : "NOT certified",
        clean_summary.objective);
    for (double fraction : fractions) {
      for (int seed = 1; seed <= FLAGS_seeds; ++seed) {
        LandmarkOutlierOptions outliers;
        outliers.landmark_fraction = FLAGS_kinds != "priors" ? fraction : 0;
        outliers.prior_fraction = FLAGS_kinds != "landmarks" ? fraction : 0;
        outliers.seed = seed;
        PoseGraph corrupted;
        std::vector<int> added_l, added_p;
        if (!AddLandmarkOutliers(clean, outliers, &corrupted, &added_l,
                                 &added_p, &error)) {
          std::fprintf(stderr, "%s: %s\n", c.name.c_str(), error.c_str());
          return 1;
        }
        // One row: a method's result x, its rejections (indices per kind)
        // and certificate.
        auto row = [&](const std::string& method, const Solution& x,
                       const std::vector<int>& rejected_edges,
                       const std::vector<int>& rejected_landmarks,
                       const std::vector<int>& rejected_priors, bool certified,
                       double time_s, const std::string& status) {
          const Rates lm = Count(added_l, rejected_landmarks);
          const Rates pr = Count(added_p, rejected_priors);
          const std::set<int> rejected(rejected_landmarks.begin(),
                                       rejected_landmarks.end());
          int ties = 0;
          for (int q : added_l) {
            ties += !rejected.count(q) &&
                    seen_by[corrupted.landmark_measurements[q].l] == 1;
          }
          double rot = NAN, trans = NAN, gap = NAN;
          if (x.poses.size() == optimum.poses.size()) {
            rot = trans = 0;
            for (size_t i = 0; i < x.poses.size(); ++i) {
              const Eigen::MatrixXd dR =
                  optimum.poses[i].R.transpose() * x.poses[i].R;
              const double cos_angle = std::clamp(
                  (dR.trace() - (clean.dimension - 2)) / 2, -1.0, 1.0);
              rot = std::max(rot, std::acos(cos_angle) * 180 / M_PI);
              trans =
                  std::max(trans, (x.poses[i].t - optimum.poses[i].t).norm());
            }
            gap = (EvaluateObjective(clean, x.poses,
                                     OptimalLandmarkPositions(clean, x.poses)) -
                   clean_summary.objective) /
                  clean_summary.objective;
          }
          const bool success = certified && rejected_edges.empty() &&
                               lm.precision() >= 0.99 && lm.recall() >= 0.99 &&
                               pr.precision() >= 0.99 && pr.recall() >= 0.99 &&
                               gap <= 1e-6;
          char line[1024];
          std::snprintf(
              line, sizeof(line),
              "%s,%s,%d,%d,%d,%zu,%zu,%g,%d,%d,%d,%d,%.6f,%.6f,%d,%d,%d,%d,"
              "%.6f,%.6f,%zu,%.6g,%.6g,%.6g,%d,%.4f,%d,%s\n",
              c.name.c_str(), method.c_str(), clean.dimension, clean.num_poses,
              clean.num_landmarks, corrupted.landmark_measurements.size(),
              corrupted.priors.size(), fraction, seed, lm.added, lm.rejected,
              lm.rejected_wrong, lm.precision(), lm.recall(), ties, pr.added,
              pr.rejected, pr.rejected_wrong, pr.precision(), pr.recall(),
              rejected_edges.size(), rot, trans, gap, certified ? 1 : 0, time_s,
              success ? 1 : 0, status.c_str());
          csv << line << std::flush;
          std::snprintf(
              line, sizeof(line),
              "| %s | %s | %d | %d | %d | %zu | %zu | %g | %d | %d | %.4f | "
              "%.4f | %d | %d | %.4f | %.4f | %zu | %.3g | %.3g | %.2e | %s | "
              "%.2f | %s |\n",
              c.name.c_str(), method.c_str(), clean.dimension, clean.num_poses,
              clean.num_landmarks, corrupted.landmark_measurements.size(),
              corrupted.priors.size(), fraction, seed, lm.added, lm.precision(),
              lm.recall(), ties, pr.added, pr.precision(), pr.recall(),
              rejected_edges.size(), rot, trans, gap, certified ? "yes" : "no",
              time_s, success ? "yes" : "no");
          md << line << std::flush;
          std::printf("%s", line);
        };
        if (methods.count("sesync")) {
          RobustSolverOptions robust;
          robust.solver_options.num_threads = FLAGS_num_threads;
          robust.mu_step = FLAGS_mu_step;
          robust.max_removal_trials = FLAGS_max_removal_trials;
          RobustSolverSummary s;
          Solution x;
          const auto start = Clock::now();
          SolveRobust(corrupted, robust, &x, &s);
          row("SE-Sync GNC", x, s.outlier_edges,
              s.outlier_landmark_measurements, s.outlier_priors, s.certified(),
              SecondsSince(start),
              s.StatusString() + "/" + s.inlier_summary.StatusString());
        }
        for (auto [name, type] :
             {std::pair{"LM Huber", CeresRobustLoss::Type::kHuber},
              {"LM Cauchy", CeresRobustLoss::Type::kCauchy}}) {
          if (!methods.count("ceres")) break;
          // From the odometry (in the priors' frame) and each landmark at
          // its first observation; the loss's a^2 = each kind's TLS
          // threshold; verdicts: f_k > c_k^2 at the result.
          const auto start = Clock::now();
          const Poses poses = OdometryInitialization(corrupted);
          const Solution initial{poses,
                                 InitialLandmarkPositions(corrupted, poses)};
          const RobustSolverOptions defaults;
          const int d = corrupted.dimension;
          CeresBaselineOptions options;
          options.method = CeresBaselineOptions::Method::kLevenbergMarquardt;
          options.num_threads = FLAGS_num_threads;
          options.max_solver_time_s = FLAGS_ceres_max_time;
          options.loss.type = type;
          options.loss.threshold = InlierThreshold(defaults, d);
          options.loss.landmark_threshold =
              internal::ChiSquareQuantile(defaults.inlier_probability, d);
          options.loss.prior_threshold = options.loss.landmark_threshold;
          Solution x;
          CeresBaselineSummary summary;
          std::string why;
          const bool ok =
              SolveWithCeres(corrupted, initial, options, &x, &summary, &why);
          const double time_s = SecondsSince(start);
          std::vector<int> edges, landmarks, priors;
          if (ok) {
            const std::vector<double> f = TermCosts(corrupted, x);
            const std::vector<double> c2 = TermThresholds(defaults, corrupted);
            const size_t m = corrupted.measurements.size();
            const size_t first_prior =
                m + corrupted.landmark_measurements.size();
            for (size_t k = 0; k < f.size(); ++k) {
              if (!(f[k] > c2[k])) continue;
              if (k < m) {
                edges.push_back(static_cast<int>(k));
              } else if (k < first_prior) {
                landmarks.push_back(static_cast<int>(k - m));
              } else {
                priors.push_back(static_cast<int>(k - first_prior));
              }
            }
          }
          row(name, x, edges, landmarks, priors, false, time_s,
              ok ? CeresStatus(summary) : "failed: " + why);
        }
      }
    }
  }
  std::printf("wrote %s and %s\n", csv_path.c_str(), md_path.c_str());
  return 0;
}

}  // namespace
}  // namespace ceres_sesync::bench

int main(int argc, char** argv) {
  ceres_sesync::bench::InitBenchProgram(&argc, &argv);
  return ceres_sesync::bench::Main();
}
