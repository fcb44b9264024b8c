// Benchmark (issue #3): products with Q in the paper's implicit,
// translation-eliminated form versus the translation-explicit form.
//
//   formulation_compare [--repeats N] [--num_threads N] [--out FILE]
//                       [--quick] [--variants LIST] [files...]
//
// Without files: every .g2o in CERES_SESYNC_DATA_DIR, sorted by name
// (--quick: tinyGrid3D, smallGrid3D, CSAIL, intel, one repeat).
//
// For each dataset, the rank r = d + 2 Burer-Monteiro problem is solved from
// the same chordal initialization (ChordalRotationsFromLaplacian, padded with
// zero rows, as in Solve()) with the library's Riemannian trust region and
// the same stopping rule as Solve() (preconditioned gradient norm <= 1e-6
// sqrt(F), up to 3 passes, the default tCG settings), in
//
//  implicit  the library's form: F(Y) = tr(Q Y^T Y) on St(d, r)^n with
//            Q = D - Vbar^T Lbar^{-1} Vbar (SESyncCost), preconditioned by
//            (Q + eps I)^{-1} through the sparse K_eps (kRegularizedQ).
//  explicit  X = [Tbar | R] (r x ((n-1) + dn), t_0 = 0) on
//            R^{r x (n-1)} x St(d, r)^n with F(X) = tr(Mbar X^T X),
//            Mbar = [Lbar -Vbar; -Vbar^T D] (the certificate matrix K_c at
//            Lambda = 0, c = 0). Euclidean gradient 2 X Mbar; only the
//            rotation blocks are projected (Lambda = SymBlockDiag(R^T (X
//            Mbar)_R)); Hv = Proj(2 V Mbar - [0 | V_R Lambda]); translations
//            retract additively, rotations by RetractStiefelProduct. The
//            translations start at their optimum for the chordal rotations
//            (Tbar = Y Vbar^T Lbar^{-1}, one solve, timed), so both forms
//            start at the same F. Preconditioner: the full solve
//            V (Mbar + eps E)^{-1} (SparseCholeskyFactor::SolveRows) followed
//            by the projection, with the library's eps = lambda_max(D) / 1e6
//            (Gershgorin) and
//              explicit  E = diag(0, I_dn): exactly the library's K_eps, whose
//                        rotation block of the inverse is (Q + eps I)^{-1};
//              explicit_all  E = I: Mbar + eps I, the translations shifted
//                        too.
//  explicit_schur  the explicit cost with the preconditioner that keeps the
//            translations optimal for the projected rotations:
//              P = [Lbar^{-1} 0; 0 0] + L Pi (Q + eps I)^{-1} Pi L^T,
//            L = [Lbar^{-1} Vbar; I] (the optimal translations of a rotation
//            step), Pi the tangent projection of the rotation blocks. Applied
//            as a = V_T Lbar^{-1}, y = Pi(V_R + a Vbar), w = Pi([0 | y]
//            K_eps^{-1})_R (SolveRowsTail), P V = [(V_T + w Vbar^T) Lbar^{-1} |
//            w]: two Lbar solves more than the implicit preconditioner. From
//            a translation-optimal start (zero translation residual) its tCG
//            iterates are the implicit form's (with the translations that are
//            optimal for them), so it isolates the per-product costs.
//            "explicit" (Pi applied after the full solve) loses this: the
//            translation part of K_eps^{-1} V is optimal for the unprojected
//            rotation part, the translation residual becomes nonzero, and tCG
//            needs many more products.
//
// Reported per form: final F, RTR iterations, Hessian-vector products,
// optimize time (min over --repeats; translation initialization included for
// the explicit forms, preconditioner factorization excluded and reported
// separately), and the cost of one Hv product and one preconditioner
// application (median of 21 at the final point). --variants selects a subset
// of implicit,explicit,explicit_all,explicit_schur. The Markdown table goes to
// stdout and to
// --out when given.

// Build note: the internal headers include CHOLMOD's cholmod.h;
// bench/CMakeLists.txt links SuiteSparse::CHOLMOD (and so gets its include
// directory) for every bench program. Without it this program would compile
// to a stub that says so.

#if !__has_include(<cholmod.h>)

#include <cstdio>

int main() {
  std::fprintf(stderr,
               "formulation_compare was built without CHOLMOD's include "
               "directory: rebuild it with CPATH=/usr/include/suitesparse "
               "(see the top of bench/formulation_compare.cc)\n");
  return 2;
}

#else  // __has_include(<cholmod.h>)

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/certificate_matrix.h"
#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/parallel.h"
#include "ceres_sesync/internal/sesync_cost.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"
#include "ceres_sesync/pose_graph.h"
#include "ceres_sesync/riemannian_trust_region.h"
#include "ceres_sesync/sesync_solver.h"
#include "ceres_sesync/stiefel_manifold.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_int32(repeats, 3, "Timed repeats per form (the minimum is reported).");
DEFINE_int32(num_threads, 1,
             "Threads for the O(m r) kernels of both forms (1: serial, the "
             "fairest on a shared machine).");
DEFINE_double(max_time, 60,
              "Wall-clock limit of one optimization (all passes) in seconds; "
              "a form that reaches it is reported as not converged and not "
              "repeated.");
DEFINE_string(out, "", "If set, also write the Markdown report here.");
DEFINE_bool(quick, false,
            "Only tinyGrid3D, smallGrid3D, CSAIL and intel, one repeat.");
DEFINE_string(variants, "implicit,explicit,explicit_all,explicit_schur",
              "Comma-separated forms to run: implicit, explicit (K_eps "
              "preconditioner), explicit_all (Mbar + eps I preconditioner), "
              "explicit_schur (translation-consistent preconditioner).");

namespace ceres_sesync {
namespace {

using internal::SparseMatrix;
using Clock = std::chrono::steady_clock;
using Triplet = Eigen::Triplet<double>;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// out = Y A for Y (r x k) and the compressed-column A (k x N): the same
// column-of-Y kernel as the library's products with Q (SESyncProblem's
// MultiplyBySparse, which is not exported), so that the two forms differ
// only in the work they do, not in how well it is coded.
template <int R>
void MultiplyBySparseKernel(const Eigen::MatrixXd& Y, const SparseMatrix& A,
                            int begin, int end, Eigen::MatrixXd* out) {
  using Vector = Eigen::Matrix<double, R, 1>;
  using ConstMap = Eigen::Map<const Vector>;
  const int r = static_cast<int>(Y.rows());
  const int* start = A.outerIndexPtr();
  const int* row = A.innerIndexPtr();
  const double* value = A.valuePtr();
  const double* y = Y.data();
  Vector sum(r);
  for (int j = begin; j < end; ++j) {
    sum.setZero();
    for (int k = start[j]; k < start[j + 1]; ++k) {
      sum +=
          value[k] * ConstMap(y + static_cast<std::ptrdiff_t>(row[k]) * r, r);
    }
    Eigen::Map<Vector>(out->data() + static_cast<std::ptrdiff_t>(j) * r, r) =
        sum;
  }
}

void MultiplyBySparse(const Eigen::MatrixXd& Y, const SparseMatrix& A,
                      int num_threads, Eigen::MatrixXd* out) {
  out->resize(Y.rows(), A.cols());
  const int cols = static_cast<int>(A.cols());
  const int parts =
      internal::ThreadsFor(num_threads, 2.0 * Y.rows() * (A.nonZeros() + cols));
  internal::ParallelParts(parts, [&](int part, int num_parts) {
    const int begin = internal::PartBegin(cols, part, num_parts);
    const int end = internal::PartBegin(cols, part + 1, num_parts);
    switch (Y.rows()) {
      case 4:
        return MultiplyBySparseKernel<4>(Y, A, begin, end, out);
      case 5:
        return MultiplyBySparseKernel<5>(Y, A, begin, end, out);
      default:
        return MultiplyBySparseKernel<Eigen::Dynamic>(Y, A, begin, end, out);
    }
  });
}

// The sparse matrices of the translation-explicit form.
struct ExplicitData {
  int d = 0, n = 0, t0 = 0;  // t0 = n - 1 translation unknowns first.
  SparseMatrix M;            // Mbar, both triangles.
  SparseMatrix Vbar;         // (n-1) x dn.
  SparseMatrix VbarT;        // Vbar^T (dn x (n-1)).
  bool schur = false;        // Preconditioner of explicit_schur.
  internal::SparseCholeskyFactor preconditioner;  // Mbar + eps E.
  internal::SparseCholeskyFactor lbar;            // Lbar.
};

// eps = lambda_max(D) / max_condition by Gershgorin, as SESyncPreconditioner.
double RegularizationShift(const SparseMatrix& D, double max_condition) {
  Eigen::VectorXd row_sums = Eigen::VectorXd::Zero(D.rows());
  for (int k = 0; k < D.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(D, k); it; ++it) {
      row_sums(it.row()) += std::abs(it.value());
    }
  }
  return row_sums.maxCoeff() / max_condition;
}

// Assembles Mbar from the problem's Lbar (lower triangle stored), Vbar and D
// (both triangles), and factorizes Mbar + eps E (E = I or diag(0, I_dn)).
bool BuildExplicitData(const internal::SESyncProblem& problem, double eps,
                       bool shift_translations, ExplicitData* data) {
  const int d = problem.dimension(), n = problem.num_rotations(), t0 = n - 1;
  const int size = t0 + d * n;
  data->d = d;
  data->n = n;
  data->t0 = t0;
  const SparseMatrix& L = problem.Lbar();
  const SparseMatrix& V = problem.Vbar();
  const SparseMatrix& D = problem.D();
  std::vector<Triplet> full, lower;
  full.reserve(2 * L.nonZeros() + 2 * V.nonZeros() + D.nonZeros());
  lower.reserve(L.nonZeros() + V.nonZeros() + D.nonZeros() + size);
  for (int k = 0; k < L.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
      if (it.row() < it.col()) continue;  // Lower triangle only (defensive).
      full.emplace_back(it.row(), it.col(), it.value());
      if (it.row() != it.col())
        full.emplace_back(it.col(), it.row(), it.value());
      lower.emplace_back(it.row(), it.col(), it.value());
    }
  }
  for (int k = 0; k < V.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(V, k); it; ++it) {
      full.emplace_back(it.row(), t0 + it.col(), -it.value());
      full.emplace_back(t0 + it.col(), it.row(), -it.value());
      lower.emplace_back(t0 + it.col(), it.row(), -it.value());
    }
  }
  for (int k = 0; k < D.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(D, k); it; ++it) {
      full.emplace_back(t0 + it.row(), t0 + it.col(), it.value());
      if (it.row() >= it.col()) {
        lower.emplace_back(t0 + it.row(), t0 + it.col(), it.value());
      }
    }
  }
  for (int k = 0; k < size && shift_translations; ++k) {
    lower.emplace_back(k, k, eps);
  }
  data->M.resize(size, size);
  data->M.setFromTriplets(full.begin(), full.end());
  data->M.makeCompressed();
  data->Vbar = V;
  data->Vbar.makeCompressed();
  data->VbarT = V.transpose();
  data->VbarT.makeCompressed();

  if (shift_translations) {
    SparseMatrix K(size, size);
    K.setFromTriplets(lower.begin(), lower.end());
    K.makeCompressed();
    internal::CholmodFactor factor;
    internal::ConfigureCholmod(internal::CholmodLayout::kAutomatic, &factor);
    factor.compute(K);
    if (factor.info() != Eigen::Success) return false;
    data->preconditioner = factor.ExtractFactor();
  } else {
    // K_eps = Mbar + eps diag(0, I) is the library's certificate matrix at
    // Lambda = 0, c = eps: use its assembly, ordering and factorization, so
    // that both forms apply the very same factor (SolveRows here,
    // SolveRowsTail in the implicit form).
    internal::CertificateMatrix certificate(problem);
    if (!certificate.Factorize(Eigen::MatrixXd::Zero(d, d * n), eps)) {
      return false;
    }
    data->preconditioner = certificate.ExtractFactor();
  }

  internal::CholmodFactor lbar_factor;
  internal::ConfigureCholmod(internal::CholmodLayout::kSimplicial,
                             &lbar_factor);
  lbar_factor.compute(L);
  if (lbar_factor.info() != Eigen::Success) return false;
  data->lbar = lbar_factor.ExtractFactor();
  return true;
}

// F(X) = tr(Mbar X^T X) on R^{r x (n-1)} x St(d, r)^n.
class ExplicitCost : public RiemannianCostFunction {
 public:
  ExplicitCost(const ExplicitData* data, int num_threads)
      : data_(data), num_threads_(num_threads) {}

  double Evaluate(const Eigen::MatrixXd& X) override {
    X_ = X;
    R_ = X.rightCols(rotation_size());
    MultiplyBySparse(X_, data_->M, num_threads_, &XM_);
    xm_rotations_ = XM_.rightCols(rotation_size());
    lambda_ = SymBlockDiagProduct(xm_rotations_, R_, data_->d);
    return X_.cwiseProduct(XM_).sum();
  }

  void Gradient(Eigen::MatrixXd* gradient) override {
    // 2 X Mbar, with the rotation blocks projected: 2 ((X Mbar)_R - R Lambda).
    internal::BlockDiagonalMultiply(R_, lambda_, data_->d, &rotations_);
    *gradient = 2 * XM_;
    gradient->rightCols(rotation_size()) -= 2 * rotations_;
  }

  void HessianVector(const Eigen::MatrixXd& V, Eigen::MatrixXd* hv) override {
    ++hessian_vector_products_;
    MultiplyBySparse(V, data_->M, num_threads_, &vm_);
    rotations_ = V.rightCols(rotation_size());
    internal::BlockDiagonalMultiply(rotations_, lambda_, data_->d, &v_lambda_);
    vm_.rightCols(rotation_size()) -= v_lambda_;
    vm_ *= 2;
    ProjectToTangent(vm_, hv);
  }

  void Precondition(const Eigen::MatrixXd& V, Eigen::MatrixXd* pv) override {
    if (!data_->schur) {
      data_->preconditioner.SolveRows(V, &vm_, num_threads_);
      ProjectToTangent(vm_, pv);
      return;
    }
    const int t0 = data_->t0, dn = rotation_size(), d = data_->d;
    translations_ = V.leftCols(t0);
    data_->lbar.SolveRows(translations_, &a_, num_threads_);
    MultiplyBySparse(a_, data_->Vbar, num_threads_, &rotations_);
    rotations_ += V.rightCols(dn);
    ProjectToStiefelProductTangent(R_, rotations_, d, &rotations_);
    data_->preconditioner.SolveRowsTail(rotations_, t0, &projected_,
                                        num_threads_);
    ProjectToStiefelProductTangent(R_, projected_, d, &projected_);
    MultiplyBySparse(projected_, data_->VbarT, num_threads_, &a_);
    a_ += translations_;
    pv->resize(V.rows(), V.cols());
    data_->lbar.SolveRows(a_, &translations_, num_threads_);
    pv->leftCols(t0) = translations_;
    pv->rightCols(dn) = projected_;
  }

  void Retract(const Eigen::MatrixXd& X, const Eigen::MatrixXd& V,
               Eigen::MatrixXd* result) override {
    const int t0 = data_->t0, dn = rotation_size();
    Eigen::MatrixXd rotations;
    RetractStiefelProduct(X.rightCols(dn), V.rightCols(dn), data_->d,
                          &rotations);
    result->resize(X.rows(), X.cols());
    result->leftCols(t0) = X.leftCols(t0) + V.leftCols(t0);
    result->rightCols(dn) = rotations;
  }

  void ProjectToTangent(const Eigen::MatrixXd& V,
                        Eigen::MatrixXd* result) override {
    // Translations are unconstrained; rotations project as on St(d, r)^n.
    projected_ = V.rightCols(rotation_size());
    ProjectToStiefelProductTangent(R_, projected_, data_->d, &projected_);
    if (result != &V) *result = V;
    result->rightCols(rotation_size()) = projected_;
  }

  int hessian_vector_products() const { return hessian_vector_products_; }

 private:
  int rotation_size() const { return data_->d * data_->n; }

  const ExplicitData* data_;
  int num_threads_;
  Eigen::MatrixXd X_, R_, XM_, xm_rotations_, lambda_;
  Eigen::MatrixXd vm_, rotations_, v_lambda_, projected_;  // Workspace.
  Eigen::MatrixXd translations_, a_;
  int hessian_vector_products_ = 0;
};

// The stopping rule of Solve(): preconditioned gradient norm <= rel sqrt(F)
// (floored), repeated from the current point (up to 3 passes) while F drops
// below half of the value the tolerance was computed from.
struct RunResult {
  double f = 0;
  int iterations = 0;
  int hessian_vector_products = 0;
  int passes = 0;
  double time_s = 0;
  std::string termination;
  bool timed_out = false;
};

RunResult Optimize(const SolverOptions& options, double scale,
                   RiemannianCostFunction* cost, Eigen::MatrixXd* x) {
  RunResult result;
  RiemannianTrustRegionOptions rtr;
  rtr.max_iterations = options.max_iterations;
  rtr.max_inner_iterations = options.max_inner_iterations;
  rtr.gradient_tolerance = 0;
  rtr.relative_decrease_tolerance = options.relative_decrease_tolerance;
  const auto start = Clock::now();
  double f = cost->Evaluate(*x);
  for (int pass = 0; pass < 3; ++pass) {
    if (FLAGS_max_time > 0) {
      rtr.max_time_s = std::max(1e-3, FLAGS_max_time - SecondsSince(start));
    }
    rtr.preconditioned_gradient_tolerance =
        options.relative_preconditioned_gradient_tolerance *
        std::sqrt(std::max(f, 1e-14 * scale));
    RiemannianTrustRegionSummary summary;
    MinimizeRiemannianTrustRegion(rtr, cost, x, &summary);
    ++result.passes;
    result.iterations += summary.iterations;
    result.hessian_vector_products += summary.hessian_vector_products;
    result.termination = summary.TerminationString();
    result.timed_out = summary.termination ==
                       RiemannianTrustRegionSummary::Termination::kMaxTime;
    const double previous = f;
    f = summary.final_cost;
    if (summary.termination != RiemannianTrustRegionSummary::Termination::
                                   kPreconditionedGradientTolerance ||
        f >= 0.5 * previous) {
      break;
    }
  }
  result.f = f;
  return result;
}

// Median wall time of one call of `f` over 21 calls.
template <typename F>
double TimePerCall(F&& f) {
  std::vector<double> times;
  for (int k = 0; k < 21; ++k) {
    const auto start = Clock::now();
    f();
    times.push_back(SecondsSince(start));
  }
  return Median(times);
}

struct FormResult {
  std::string form;
  bool ran = false;
  RunResult run;              // Of the last repeat (all repeats agree).
  std::vector<double> times;  // Optimize time of each repeat.
  double setup_s = 0;         // Preconditioner (and Mbar) setup.
  double hv_s = 0, precondition_s = 0;
  double implicit_f_of_rotations = 0;  // Implicit F at the final rotations.
};

struct DatasetResult {
  std::string name;
  int d = 0, n = 0, m = 0;
  std::vector<FormResult> forms;
};

double Min(const std::vector<double>& v) {
  return *std::min_element(v.begin(), v.end());
}

bool RunDataset(const std::string& path, int repeats,
                const std::set<std::string>& variants, DatasetResult* out) {
  PoseGraph graph;
  std::string error;
  if (!ReadG2oFile(path, G2oReadOptions(), &graph, &error)) {
    std::fprintf(stderr, "formulation_compare: %s\n", error.c_str());
    return false;
  }
  out->name = std::filesystem::path(path).stem().string();
  out->d = graph.dimension;
  out->n = graph.num_poses;
  out->m = static_cast<int>(graph.measurements.size());
  const int d = graph.dimension, n = graph.num_poses, r = d + 2;
  std::fprintf(stderr, "%s: d = %d, n = %d, m = %d\n", out->name.c_str(), d, n,
               out->m);

  const SolverOptions options;  // Library defaults (tolerances, eps).
  internal::SESyncProblem problem(graph, FLAGS_num_threads);
  if (!problem.ok()) return false;
  double scale = 0;
  for (int k = 0; k < problem.D().rows(); ++k) {
    scale = std::max(scale, problem.D().coeff(k, k));
  }
  Eigen::MatrixXd chordal;
  if (!internal::ChordalRotationsFromLaplacian(problem.RotationLaplacian(), d,
                                               &chordal)) {
    return false;
  }
  Eigen::MatrixXd Y0 = Eigen::MatrixXd::Zero(r, d * n);
  Y0.topRows(d) = chordal;

  // (a) Implicit form: exactly the library's cost and preconditioner.
  auto start = Clock::now();
  internal::SESyncPreconditioner preconditioner(
      problem, internal::PreconditionerType::kRegularizedQ,
      options.regularized_cholesky_max_condition);
  const double implicit_setup_s = SecondsSince(start);
  internal::SESyncCost implicit_cost(&problem, &preconditioner);
  if (variants.count("implicit")) {
    FormResult form;
    form.form = "implicit";
    form.ran = true;
    form.setup_s = implicit_setup_s;
    Eigen::MatrixXd Y;
    for (int k = 0; k < repeats; ++k) {
      Y = Y0;
      start = Clock::now();
      form.run = Optimize(options, scale, &implicit_cost, &Y);
      form.times.push_back(SecondsSince(start));
      if (form.run.timed_out) break;
    }
    form.implicit_f_of_rotations = implicit_cost.Evaluate(Y);
    Eigen::MatrixXd V, out_matrix;
    implicit_cost.Gradient(&V);
    form.hv_s =
        TimePerCall([&] { implicit_cost.HessianVector(V, &out_matrix); });
    form.precondition_s =
        TimePerCall([&] { implicit_cost.Precondition(V, &out_matrix); });
    out->forms.push_back(form);
  }

  // (b) Explicit forms.
  const double eps = RegularizationShift(
      problem.D(), options.regularized_cholesky_max_condition);
  for (const std::string name :
       {"explicit", "explicit_all", "explicit_schur"}) {
    if (!variants.count(name)) continue;
    const bool shift_translations = name == "explicit_all";
    FormResult form;
    form.form = name;
    start = Clock::now();
    ExplicitData data;
    if (!BuildExplicitData(problem, eps, shift_translations, &data)) {
      std::fprintf(stderr, "%s: %s: factorization failed\n", out->name.c_str(),
                   name.c_str());
      out->forms.push_back(form);
      continue;
    }
    data.schur = name == "explicit_schur";
    form.setup_s = SecondsSince(start);
    form.ran = true;
    ExplicitCost cost(&data, FLAGS_num_threads);
    const int t0 = data.t0;
    Eigen::MatrixXd X, P, T;
    for (int k = 0; k < repeats; ++k) {
      start = Clock::now();
      // Optimal translations for the chordal rotations: Tbar Lbar = Y Vbar^T.
      X.resize(r, t0 + d * n);
      MultiplyBySparse(Y0, data.VbarT, FLAGS_num_threads, &P);
      data.lbar.SolveRows(P, &T, FLAGS_num_threads);
      X.leftCols(t0) = T;
      X.rightCols(d * n) = Y0;
      form.run = Optimize(options, scale, &cost, &X);
      form.times.push_back(SecondsSince(start));
      if (form.run.timed_out) break;
    }
    cost.Evaluate(X);
    Eigen::MatrixXd V, out_matrix;
    cost.Gradient(&V);
    form.hv_s = TimePerCall([&] { cost.HessianVector(V, &out_matrix); });
    form.precondition_s =
        TimePerCall([&] { cost.Precondition(V, &out_matrix); });
    form.implicit_f_of_rotations = implicit_cost.Evaluate(X.rightCols(d * n));
    out->forms.push_back(form);
  }
  for (const FormResult& form : out->forms) {
    if (!form.ran) continue;
    std::fprintf(stderr,
                 "  %-12s F %.12e (implicit F of its rotations %.12e) iters %d "
                 "Hv %d passes %d time %.4f s (setup %.4f s, Hv %.3g ms, "
                 "precond %.3g ms) %s\n",
                 form.form.c_str(), form.run.f, form.implicit_f_of_rotations,
                 form.run.iterations, form.run.hessian_vector_products,
                 form.run.passes, Min(form.times), form.setup_s,
                 1e3 * form.hv_s, 1e3 * form.precondition_s,
                 form.run.termination.c_str());
  }
  return true;
}

const FormResult* Find(const DatasetResult& dataset, const std::string& form) {
  for (const FormResult& f : dataset.forms) {
    if (f.form == form && f.ran) return &f;
  }
  return nullptr;
}

std::string Report(const std::vector<DatasetResult>& datasets, int repeats) {
  std::ostringstream md;
  char buf[1024];
  md << "# Implicit (translation-eliminated) vs translation-explicit form\n\n"
     << "Generated by `formulation_compare` (bench/formulation_compare.cc), "
     << "rank r = d + 2 from the chordal initialization, library stopping "
     << "rule (preconditioned gradient norm <= 1e-6 sqrt(F), up to 3 "
     << "passes), default tCG settings, " << FLAGS_num_threads
     << " thread(s). Time = optimize time, min of " << repeats
     << " run(s) (explicit: includes the initial translation solve); setup "
     << "(preconditioner factorization, and Mbar assembly for the explicit "
     << "form) is excluded and listed separately. ratio = explicit time / "
     << "implicit time (> 1: implicit faster). rel. dF = |F_explicit - "
     << "F_implicit| / F_implicit at the solutions; rel. dF(R) compares the "
     << "implicit F of the explicit run's rotation block with F_implicit. "
     << "Runs are limited to " << FLAGS_max_time
     << " s (--max_time); '>=' marks a run stopped by the limit (not "
     << "converged; then not repeated).\n\n";
  for (const std::string variant :
       {"explicit", "explicit_all", "explicit_schur"}) {
    bool any = false;
    for (const DatasetResult& ds : datasets)
      any |= Find(ds, variant) != nullptr;
    if (!any) continue;
    md << "## implicit vs " << variant
       << (variant == "explicit"
               ? " (preconditioner Pi K_eps^{-1}, K_eps = Mbar + eps "
                 "diag(0, I): the library's matrix and factor)"
           : variant == "explicit_all"
               ? " (preconditioner Pi (Mbar + eps I)^{-1})"
               : " (translation-consistent preconditioner: the implicit "
                 "form's tCG iterates while the translations are optimal)")
       << "\n\n"
       << "| dataset | n | m | implicit time [s] | implicit Hv | implicit "
          "iters | explicit time [s] | explicit Hv | explicit iters | ratio "
          "| rel. dF | rel. dF(R) | F implicit |\n"
       << "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const DatasetResult& ds : datasets) {
      const FormResult* a = Find(ds, "implicit");
      const FormResult* b = Find(ds, variant);
      if (a == nullptr || b == nullptr) continue;
      const double dF = std::abs(b->run.f - a->run.f) / a->run.f;
      const double dFR =
          std::abs(b->implicit_f_of_rotations - a->run.f) / a->run.f;
      // A run stopped by --max_time: its time is a lower bound.
      const char* a_limit = a->run.timed_out ? ">= " : "";
      const char* b_limit = b->run.timed_out ? ">= " : "";
      std::snprintf(
          buf, sizeof(buf),
          "| %s | %d | %d | %s%.4f | %d | %d | %s%.4f | %d | %d | %s%.2f | "
          "%.1e | %.1e | %.10e |\n",
          ds.name.c_str(), ds.n, ds.m, a_limit, Min(a->times),
          a->run.hessian_vector_products, a->run.iterations, b_limit,
          Min(b->times), b->run.hessian_vector_products, b->run.iterations,
          a->run.timed_out ? "~" : b_limit, Min(b->times) / Min(a->times), dF,
          dFR, a->run.f);
      md << buf;
    }
    md << "\n";
  }
  md << "## Cost per operation and setup\n\n"
     << "Median of 21 calls at the final point; setup = preconditioner "
     << "factorization (implicit: CertificateMatrix assembly + factorization "
     << "of K_eps; explicit: Mbar assembly, factorization of the shifted "
     << "Mbar and of Lbar). Termination of the last pass.\n\n"
     << "| dataset | form | Hv [ms] | precondition [ms] | setup [s] | "
        "passes | termination |\n|---|---|---|---|---|---|---|\n";
  for (const DatasetResult& ds : datasets) {
    for (const FormResult& f : ds.forms) {
      if (!f.ran) {
        md << "| " << ds.name << " | " << f.form
           << " | | | | | factorization failed |\n";
        continue;
      }
      std::snprintf(
          buf, sizeof(buf), "| %s | %s | %.3f | %.3f | %.4f | %d | %s |\n",
          ds.name.c_str(), f.form.c_str(), 1e3 * f.hv_s, 1e3 * f.precondition_s,
          f.setup_s, f.run.passes, f.run.termination.c_str());
      md << buf;
    }
  }
  return md.str();
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  using namespace ceres_sesync;
  std::set<std::string> variants;
  {
    std::stringstream list(FLAGS_variants);
    std::string v;
    while (std::getline(list, v, ',')) {
      if (v != "implicit" && v != "explicit" && v != "explicit_all" &&
          v != "explicit_schur") {
        std::fprintf(stderr, "formulation_compare: unknown variant '%s'\n",
                     v.c_str());
        return 2;
      }
      variants.insert(v);
    }
  }
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
      std::fprintf(stderr, "formulation_compare: no .g2o files in %s\n",
                   data_dir.c_str());
      return 2;
    }
    std::sort(files.begin(), files.end());
  }
  std::vector<DatasetResult> datasets;
  int failures = 0;
  for (const std::string& file : files) {
    DatasetResult result;
    if (RunDataset(file, repeats, variants, &result)) {
      datasets.push_back(result);
    } else {
      ++failures;
    }
  }
  const std::string report = Report(datasets, repeats);
  std::fputs(report.c_str(), stdout);
  if (!FLAGS_out.empty()) {
    std::ofstream out(FLAGS_out);
    out << report;
    if (!out) {
      std::fprintf(stderr, "formulation_compare: cannot write %s\n",
                   FLAGS_out.c_str());
      return 1;
    }
  }
  return failures == 0 ? 0 : 1;
}

#endif  // __has_include(<cholmod.h>)
