// The optimization stage alone, per preconditioner (issue #16): for each
// graph, the rank-(d + 2) Burer-Monteiro problem from the chordal
// initialization, solved with the library's RTR and Solve()'s stopping rule
// (the preconditioned gradient norm <= 1e-6 sqrt(F), up to 3 passes: the
// loop of Staircase::Optimize), once per preconditioner variant.
//
//   preconditioner_study [--variants exact,block_jacobi,adaptive,...]
//                        [--num_threads N] [--repeats N] [--verify]
//                        [--city 10000,100000] [--city3d N,..] [--cube S,..]
//                        [--datasets] [--out FILE] [files...]
//
// Variants (internal::PreconditionerType): exact = kRegularizedQ, its factor
// in double (the default of Solve); exact_single = the same factor stored in
// single precision; block_jacobi; sparse_cholesky (of D + eps I); none;
// adaptive = kAdaptive (block-Jacobi first, the exact factor when the rule
// of sesync_cost.h says so).
//
// Per run: setup (the preconditioner's construction: factorization and
// copy) and optimization, in CPU seconds of the process (getrusage: user +
// system, all threads, so CHOLMOD's OpenMP threads count) and wall seconds;
// RTR iterations, Hessian-vector products, truncated-CG iterations per outer
// iteration, the preconditioner switches; the final F, ||grad F|| and the
// gradient norm in the metric of the exact preconditioner (the stopping
// test's norm in the default solver), so that every variant is held to the
// default's precision; the process's peak RSS so far. Timing runs are
// repeated --repeats times (minimum reported; counts are deterministic).
// --verify also runs the certificate verification (VerifyCertificate with
// Solve()'s default targets) at each final point.

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "ceres_sesync/city_generator.h"
#include "ceres_sesync/cube_generator.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/verification.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_string(variants, "exact,block_jacobi",
              "Comma-separated preconditioners: exact, exact_single, "
              "block_jacobi, sparse_cholesky, none, adaptive.");
DEFINE_int32(num_threads, 1, "Threads for the O(m r) kernels.");
DEFINE_int32(repeats, 1, "Timed repeats per variant (minimum reported).");
DEFINE_bool(verify, false, "Verify the certificate at every final point.");
DEFINE_string(city, "", "Sizes of generated 2D cities (city_generator.h).");
DEFINE_string(city3d, "", "Sizes of generated 3D cities.");
DEFINE_string(cube, "",
              "Sides of generated 3D cubes (kappa 100, tau 400, pLC 0.1).");
DEFINE_bool(datasets, false,
            "Also every *.g2o in CERES_SESYNC_DATA_DIR (sorted).");
DEFINE_int32(switch_iterations, 0,
             "kAdaptive's switch threshold (0: the library's default).");
DEFINE_string(out, "", "If set, also write the Markdown table here.");

namespace ceres_sesync {
namespace {

using internal::PreconditionerType;

double CpuSeconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + 1e-6 * u.ru_utime.tv_usec + u.ru_stime.tv_sec +
         1e-6 * u.ru_stime.tv_usec;
}

struct Variant {
  std::string name;
  PreconditionerType type;
  internal::FactorPrecision precision;
};

bool ParseVariant(const std::string& name, Variant* v) {
  using FP = internal::FactorPrecision;
  const struct {
    const char* name;
    PreconditionerType type;
    FP precision;
  } table[] = {
      {"exact", PreconditionerType::kRegularizedQ, FP::kDouble},
      {"exact_single", PreconditionerType::kRegularizedQ, FP::kSingle},
      {"block_jacobi", PreconditionerType::kBlockJacobi, FP::kDouble},
      {"sparse_cholesky", PreconditionerType::kSparseCholesky, FP::kDouble},
      {"none", PreconditionerType::kNone, FP::kDouble},
      {"adaptive", PreconditionerType::kAdaptive, FP::kDouble},
      {"adaptive_single", PreconditionerType::kAdaptive, FP::kSingle},
  };
  for (const auto& t : table) {
    if (name == t.name) {
      *v = {t.name, t.type, t.precision};
      return true;
    }
  }
  return false;
}

struct Graph {
  std::string name;
  PoseGraph graph;
};

struct Run {
  double setup_cpu = 0, setup_wall = 0, opt_cpu = 0, opt_wall = 0;
  int iterations = 0, hv = 0, switches = 0;
  std::string inner;  // tCG iterations per outer iteration.
  std::string termination;
  double f = 0, grad = 0, exact_pgrad = 0, tolerance = 0;
  double peak_rss = 0;
  double hv_ms = 0, apply_ms = 0;  // One product / application at the end.
  double factor_mib = 0;
  int64_t factor_entries = 0;
  std::string certified;
};

std::string Join(const std::vector<int>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) {
    s += (i ? " " : "") + std::to_string(v[i]);
  }
  return s;
}

// Staircase::Optimize's RTR loop (3 passes, the same options).
Run Optimize(const internal::SESyncProblem& problem,
             internal::SESyncPreconditioner* preconditioner,
             const internal::SESyncPreconditioner* exact_metric,
             internal::CertificateMatrix* certificate,
             const Eigen::MatrixXd& Y0, const SolverOptions& options,
             double scale) {
  const int d = problem.dimension(), n = problem.num_rotations();
  Run run;
  internal::SESyncCost cost(&problem, preconditioner);
  Eigen::MatrixXd Y = Y0;
  double f = cost.Evaluate(Y);
  std::vector<int> inner;
  RiemannianTrustRegionOptions rtr;
  rtr.max_iterations = options.max_iterations;
  rtr.max_inner_iterations = options.max_inner_iterations;
  rtr.gradient_tolerance = 0;
  rtr.relative_decrease_tolerance = options.relative_decrease_tolerance;
  rtr.callback = [&](int, double, double, double, int k) {
    inner.push_back(k);
    return true;
  };
  for (int pass = 0; pass < 3; ++pass) {
    rtr.preconditioned_gradient_tolerance =
        options.relative_preconditioned_gradient_tolerance *
        std::sqrt(std::max(f, 1e-14 * scale));
    RiemannianTrustRegionSummary s;
    MinimizeRiemannianTrustRegion(rtr, &cost, &Y, &s);
    run.iterations += s.iterations;
    run.hv += s.hessian_vector_products;
    run.termination = s.TerminationString();
    run.tolerance = rtr.preconditioned_gradient_tolerance;
    const double previous = f;
    f = s.final_cost;
    if (s.termination != RiemannianTrustRegionSummary::Termination::
                             kPreconditionedGradientTolerance ||
        f >= 0.5 * previous) {
      break;
    }
  }
  run.f = cost.Evaluate(Y);
  Eigen::MatrixXd g;
  cost.Gradient(&g);
  run.grad = g.norm();
  // The cost of one Hessian-vector product and one application of the
  // (final) preconditioner at the final point: minimum CPU time of 5.
  Eigen::MatrixXd out;
  run.hv_ms = run.apply_ms = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 5; ++k) {
    double c = CpuSeconds();
    cost.HessianVector(g, &out);
    run.hv_ms = std::min(run.hv_ms, 1e3 * (CpuSeconds() - c));
    c = CpuSeconds();
    cost.Precondition(g, &out);
    run.apply_ms = std::min(run.apply_ms, 1e3 * (CpuSeconds() - c));
  }
  run.factor_mib = preconditioner->factor().memory_bytes() / 1048576.0;
  run.factor_entries = preconditioner->factor().stored_entries();
  if (exact_metric != nullptr) {
    Eigen::MatrixXd pg;
    exact_metric->Apply(g, &pg);
    run.exact_pgrad = std::sqrt(std::max(0.0, g.cwiseProduct(pg).sum()));
  }
  if (FLAGS_verify && certificate != nullptr) {
    const double sdp = internal::BlockDiagonalTrace(cost.Lambda(), d);
    internal::VerificationOptions vo;
    const double eta_floor = options.min_relative_eta * scale;
    auto shift = [&](double b) {
      return std::max(eta_floor, b * sdp / (d * n));
    };
    vo.eta_target = shift(options.certification_target_relative_bound);
    vo.eta_max = shift(options.certification_max_relative_bound);
    vo.eta_goal = shift(options.certification_goal_relative_bound);
    const internal::VerificationResult v =
        internal::VerifyCertificate(problem, cost.Lambda(), vo, certificate);
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), "%s (eta %.2e)",
                  v.certified ? "yes" : "no", v.eta);
    run.certified = buffer;
  }
  run.inner = Join(inner);
  run.switches = preconditioner->switches();
  return run;
}

double ShiftScale(const internal::SparseMatrix& D) {
  double m = 0;
  for (int k = 0; k < D.rows(); ++k) m = std::max(m, D.coeff(k, k));
  return m;
}

void Study(const Graph& g, const std::vector<Variant>& variants,
           std::ostream& md) {
  const PoseGraph& graph = g.graph;
  std::string error;
  if (!ValidatePoseGraph(graph, &error)) {
    std::fprintf(stderr, "%s: %s\n", g.name.c_str(), error.c_str());
    return;
  }
  const int d = graph.dimension, n = graph.num_poses;
  SolverOptions options;
  internal::SESyncProblem problem(graph, FLAGS_num_threads);
  CHECK(problem.ok());
  const double scale = ShiftScale(problem.D());
  Eigen::MatrixXd R;
  CHECK(internal::ChordalRotationsFromLaplacian(problem.RotationLaplacian(), d,
                                                &R));
  Eigen::MatrixXd Y0 = Eigen::MatrixXd::Zero(d + 2, d * n);
  Y0.topRows(d) = R;
  internal::CertificateMatrix certificate(problem);
  // The reference metric: the exact preconditioner in double (the default
  // solver's stopping test).
  internal::SESyncPreconditioner reference(
      problem, PreconditionerType::kRegularizedQ,
      options.regularized_cholesky_max_condition, &certificate);
  for (const Variant& v : variants) {
    Run best;
    for (int repeat = 0; repeat < FLAGS_repeats; ++repeat) {
      double c0 = CpuSeconds();
      auto w0 = bench::Clock::now();
      internal::PreconditionerSettings settings;
      settings.precision = v.precision;
      if (FLAGS_switch_iterations > 0) {
        settings.switch_iterations = FLAGS_switch_iterations;
      }
      internal::SESyncPreconditioner preconditioner(
          problem, v.type, options.regularized_cholesky_max_condition,
          &certificate, settings);
      const double setup_cpu = CpuSeconds() - c0;
      const double setup_wall = bench::SecondsSince(w0);
      c0 = CpuSeconds();
      w0 = bench::Clock::now();
      Run run =
          Optimize(problem, &preconditioner, &reference,
                   repeat == 0 ? &certificate : nullptr, Y0, options, scale);
      if (repeat > 0) run.certified = best.certified;
      run.opt_cpu = CpuSeconds() - c0;
      run.opt_wall = bench::SecondsSince(w0);
      run.setup_cpu = setup_cpu;
      run.setup_wall = setup_wall;
      if (repeat == 0 ||
          run.setup_cpu + run.opt_cpu < best.setup_cpu + best.opt_cpu) {
        best = run;
      }
    }
    best.peak_rss = bench::PeakRssMiB();
    md << "| " << g.name << " | " << n << " | " << v.name << " | "
       << bench::Fmt("%.2f", best.setup_cpu) << " | "
       << bench::Fmt("%.2f", best.opt_cpu) << " | "
       << bench::Fmt("%.2f", best.setup_cpu + best.opt_cpu) << " | "
       << bench::Fmt("%.2f", best.setup_wall + best.opt_wall) << " | "
       << best.iterations << " | " << best.hv << " | " << best.inner << " | "
       << best.switches << " | " << bench::Fmt("%.2f", best.hv_ms) << " | "
       << bench::Fmt("%.2f", best.apply_ms) << " | "
       << bench::Fmt("%.1f", best.factor_entries / 1e6) << " | "
       << bench::Fmt("%.0f", best.factor_mib) << " | "
       << bench::Fmt("%.10e", best.f) << " | " << bench::Fmt("%.2e", best.grad)
       << " | " << bench::Fmt("%.2e", best.exact_pgrad) << " | "
       << bench::Fmt("%.2e", best.tolerance) << " | " << best.termination
       << " | " << best.certified << " | " << bench::Fmt("%.0f", best.peak_rss)
       << " |\n";
  }
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  using namespace ceres_sesync;
  std::vector<Variant> variants;
  {
    std::stringstream ss(FLAGS_variants);
    std::string name;
    while (std::getline(ss, name, ',')) {
      Variant v;
      if (!ParseVariant(name, &v)) {
        std::fprintf(stderr, "unknown variant '%s'\n", name.c_str());
        return 2;
      }
      variants.push_back(v);
    }
  }
  std::vector<std::string> files(argv + 1, argv + argc);
  if (FLAGS_datasets) {
    std::vector<std::string> found;
    for (const auto& e :
         std::filesystem::directory_iterator(CERES_SESYNC_DATA_DIR)) {
      if (e.path().extension() == ".g2o") found.push_back(e.path().string());
    }
    std::sort(found.begin(), found.end());
    files.insert(files.end(), found.begin(), found.end());
  }
  std::ostringstream header;
  header << "| graph | n | preconditioner | setup CPU s | optimize CPU s | "
            "total CPU s | total wall s | iterations | Hv | tCG per "
            "iteration | switches | Hv ms | apply ms | factor M entries | "
            "factor MiB | F | grad norm | exact pgrad norm | tolerance | "
            "termination | certified | peak RSS MiB |\n|";
  for (int k = 0; k < 22; ++k) header << "---|";
  header << "\n";
  std::cout << header.str();
  std::ofstream out;
  if (!FLAGS_out.empty()) {
    out.open(FLAGS_out);
    out << header.str();
  }
  auto study = [&](Graph g) {
    std::ostringstream row;
    Study(g, variants, row);
    std::cout << row.str() << std::flush;
    if (out.is_open()) out << row.str() << std::flush;
  };
  for (const std::string& file : files) {
    Graph g;
    g.name = std::filesystem::path(file).stem().string();
    std::string error;
    if (!ReadG2oFile(file, {}, &g.graph, &error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 2;
    }
    study(std::move(g));
  }
  for (int dim : {2, 3}) {
    for (int size : bench::ParseInts(dim == 2 ? FLAGS_city : FLAGS_city3d)) {
      CityOptions o;
      o.seed = 1;  // As bench/scaling.
      o.num_poses = size;
      o.dimension = dim;
      Graph g;
      g.name = "city" + std::to_string(dim) + "d_" + std::to_string(size);
      Poses truth;
      std::string error;
      CHECK(GenerateCity(o, &g.graph, &truth, &error)) << error;
      study(std::move(g));
    }
  }
  for (int side : bench::ParseInts(FLAGS_cube)) {
    CubeOptions o;
    o.seed = 1;
    o.side = side;
    o.kappa = 100;
    o.tau = 400;
    Graph g;
    g.name = "cube_" + std::to_string(side);
    Poses truth;
    std::string error;
    CHECK(GenerateCube(o, &g.graph, &truth, &error)) << error;
    study(std::move(g));
  }
  return 0;
}
