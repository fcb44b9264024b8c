// Benchmark: the double-double sparse Cholesky factorization
// (internal/extended_cholesky.h) on certificate matrices, against CHOLMOD's
// double factorization of the same matrix.
//
//   extended_cholesky_bench [--repeats N] [--simplicial] [--portable]
//                           [--cholmod] GRAPH.g2o...
//
// Times are CPU seconds (the machine may be shared). Per graph: K = [Lbar,
// -Vbar; -Vbar^T, D + I] (the certificate matrix K_c of
// internal/certificate_matrix.h with Lambda = 0, c = 1: positive definite), in
// the block ordering the certificate uses (the problem's vertex ordering, each
// vertex expanded into its unknowns), and in double-double (the doubles
// exactly). Times (seconds, minimum over
// --repeats runs: the machine is shared) of Factorize() for
//  - supernodal: the default (SIMD kernels when the CPU has AVX2+FMA);
//  - portable (--portable): the same without SIMD (bitwise the same factor);
//  - simplicial (--simplicial): the up-looking reference (one run; slow);
//  - cholmod (--cholmod): CHOLMOD's supernodal LL^T in double, same
//    ordering;
// with nnz(L), the multiply-adds (flops()), ns per multiply-add, and the
// largest difference between the factors of the schemes run (relative to
// the largest |L_ij| of the row).
//
// Generate graphs with the CLI, e.g.
//   ceres_sesync generate city --poses 50000 --output /tmp/city50k.g2o
//   ceres_sesync generate cube --side 20 --output /tmp/cube20.g2o

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/double_double.h"
#include "ceres_sesync/internal/extended_cholesky.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/pose_graph.h"
#include "gflags/gflags.h"
#include "glog/logging.h"

DEFINE_int32(repeats, 3, "Runs per measurement (the minimum is reported).");
DEFINE_bool(simplicial, false, "Also time the simplicial reference (once).");
DEFINE_bool(portable, false, "Also time the supernodal scheme without SIMD.");
DEFINE_bool(cholmod, true, "Also time CHOLMOD's double factorization.");
DEFINE_int32(threads, 1,
             "Also time the double factorization on this many threads "
             "(wall time).");
DEFINE_int32(dense, 0,
             "Also time a dense N x N SPD matrix (the dense kernels alone).");

namespace ceres_sesync {
namespace {

using internal::DoubleDouble;
using internal::DoubleDoubleCholesky;
using internal::SparseMatrix;

// Times are CPU seconds of this process (the machine is shared: wall time
// counts other sessions' work too).
double CpuNow() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}
double Seconds(double begin) { return CpuNow() - begin; }

// The certificate matrix with Lambda = 0 and c = 1 (lower triangle), as
// CertificateMatrix assembles it.
SparseMatrix CertificateLikeMatrix(const internal::SESyncProblem& problem) {
  const int n = problem.num_rotations(), d = problem.dimension(),
            t0 = problem.num_translations() - 1;  // Pose graphs only.
  std::vector<Eigen::Triplet<double>> triplets;
  const SparseMatrix& L = problem.Lbar();
  const SparseMatrix& V = problem.Vbar();
  const SparseMatrix& D = problem.D();
  for (int k = 0; k < L.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
      if (it.row() >= it.col()) {
        triplets.emplace_back(it.row(), it.col(), it.value());
      }
    }
  }
  for (int k = 0; k < V.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(V, k); it; ++it) {
      triplets.emplace_back(t0 + it.col(), it.row(), -it.value());
    }
  }
  for (int k = 0; k < D.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(D, k); it; ++it) {
      if (it.row() >= it.col()) {
        triplets.emplace_back(t0 + it.row(), t0 + it.col(), it.value());
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int b = 0; b < d; ++b) {
      for (int a = b; a < d; ++a) {
        triplets.emplace_back(t0 + d * i + a, t0 + d * i + b,
                              a == b ? 1.0 : 0.0);
      }
    }
  }
  SparseMatrix K(t0 + d * n, t0 + d * n);
  K.setFromTriplets(triplets.begin(), triplets.end());
  K.makeCompressed();
  return K;
}

// CertificateMatrix's ordering: the vertex ordering, each vertex expanded
// into its translation (none for vertex 0) and d rotation unknowns.
std::vector<int> BlockOrdering(const internal::SESyncProblem& problem) {
  const int d = problem.dimension();
  const int t0 = problem.num_translations() - 1;  // Pose graphs only.
  std::vector<int> ordering;
  for (int v : problem.vertex_ordering()) {
    if (v > 0) ordering.push_back(v - 1);
    for (int a = 0; a < d; ++a) ordering.push_back(t0 + d * v + a);
  }
  return ordering;
}

struct Timing {
  double analyze = 0, factorize = 1e300;
};

// Values: DoubleDouble or double (the same scheme in double).
template <typename Value>
Timing TimeFactorization(DoubleDoubleCholesky* chol, int size,
                         const std::vector<int>& start,
                         const std::vector<int>& row,
                         const std::vector<Value>& values, int repeats) {
  Timing t;
  double begin = CpuNow();
  chol->Analyze(size, start, row);
  t.analyze = Seconds(begin);
  for (int r = 0; r < repeats; ++r) {
    begin = CpuNow();
    CHECK(chol->Factorize(values)) << "not positive definite";
    t.factorize = std::min(t.factorize, Seconds(begin));
  }
  return t;
}

// Wall-clock seconds (minimum over `repeats`) of a factorization on
// `threads` threads.
template <typename Value>
double WallFactorization(int threads, int size, const std::vector<int>& start,
                         const std::vector<int>& row,
                         const std::vector<Value>& values, int repeats) {
  DoubleDoubleCholesky::Options options;
  options.num_threads = threads;
  DoubleDoubleCholesky chol(options);
  chol.Analyze(size, start, row);
  double best = 1e300;
  for (int r = 0; r < repeats; ++r) {
    timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    CHECK(chol.Factorize(values)) << "not positive definite";
    clock_gettime(CLOCK_MONOTONIC, &b);
    best = std::min(best, b.tv_sec - a.tv_sec + 1e-9 * (b.tv_nsec - a.tv_nsec));
  }
  return best;
}

// max over entries of |a - b| / (largest |L_ij| of the row in a).
double FactorDifference(const DoubleDoubleCholesky& a,
                        const DoubleDoubleCholesky& b) {
  const int n = a.size();
  std::vector<double> row_max(n, 0.0);
  for (int c = 0; c < n; ++c) {
    for (int p = a.factor_start()[c]; p < a.factor_start()[c + 1]; ++p) {
      double& m = row_max[a.factor_row()[p]];
      m = std::max(m, std::abs(a.factor_value()[p].hi));
    }
  }
  double worst = 0;
  for (int c = 0; c < n; ++c) {
    for (int p = a.factor_start()[c]; p < a.factor_start()[c + 1]; ++p) {
      CHECK_EQ(a.factor_row()[p], b.factor_row()[p]);
      const DoubleDouble diff = a.factor_value()[p] - b.factor_value()[p];
      worst = std::max(worst,
                       std::abs(diff.ToDouble()) / row_max[a.factor_row()[p]]);
    }
  }
  return worst;
}

// A dense SPD matrix (a shifted Gram matrix of random vectors): one
// supernode, so this times the dense kernels alone.
void RunDense(int n) {
  std::vector<double> g(static_cast<size_t>(n) * n);
  uint64_t state = 1;
  for (double& x : g) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    x = static_cast<double>(state >> 11) * 0x1p-53 - 0.5;
  }
  std::vector<int> start(n + 1, 0), row;
  std::vector<DoubleDouble> values;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= j; ++i) {
      double a = i == j ? n : 0;
      for (int k = 0; k < n; k += 16) a += g[i + k * n] * g[j + k * n];
      row.push_back(i);
      values.emplace_back(a);
    }
    start[j + 1] = static_cast<int>(row.size());
  }
  DoubleDoubleCholesky chol;
  const Timing t =
      TimeFactorization(&chol, n, start, row, values, FLAGS_repeats);
  std::printf(
      "dense %d: multiply-adds %.3g, factorize %.3f s (%.2f ns per "
      "multiply-add), SIMD %s\n",
      n, chol.flops(), t.factorize, 1e9 * t.factorize / chol.flops(),
      chol.vectorized() ? "yes" : "no");
}

void Run(const std::string& path) {
  PoseGraph graph;
  std::string error;
  if (!ReadG2oFile(path, G2oReadOptions(), &graph, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    std::exit(2);
  }
  internal::SESyncProblem problem(graph);
  CHECK(problem.ok());
  const SparseMatrix K = CertificateLikeMatrix(problem);
  const std::vector<int> ordering = BlockOrdering(problem);
  const int size = static_cast<int>(K.rows());
  // The permuted upper triangle, as CertificateMatrix builds it.
  std::vector<int> position(size);
  for (int k = 0; k < size; ++k) position[ordering[k]] = k;
  std::vector<int> start(size + 1, 0), row(K.nonZeros());
  std::vector<DoubleDouble> values(K.nonZeros());
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  for (int c = 0; c < size; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      ++start[std::max(position[inner[q]], position[c]) + 1];
    }
  }
  for (int k = 0; k < size; ++k) start[k + 1] += start[k];
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int c = 0; c < size; ++c) {
    for (int q = outer[c]; q < outer[c + 1]; ++q) {
      const int pr = position[inner[q]], pc = position[c];
      const int slot = next[std::max(pr, pc)]++;
      row[slot] = std::min(pr, pc);
      values[slot] = DoubleDouble(K.valuePtr()[q]);
    }
  }

  DoubleDoubleCholesky supernodal;
  const Timing t_super =
      TimeFactorization(&supernodal, size, start, row, values, FLAGS_repeats);
  const double flops = supernodal.flops();
  std::printf("%s: n %d, nnz(K) %lld, nnz(L) %lld, multiply-adds %.3g\n",
              path.c_str(), size, static_cast<long long>(K.nonZeros()),
              supernodal.factor_nonzeros(), flops);
  std::printf(
      "  supernodes %d, stored entries %lld (%.2f x nnz(L)), SIMD kernels: "
      "%s\n",
      supernodal.num_supernodes(), supernodal.supernodal_entries(),
      supernodal.supernodal_entries() /
          static_cast<double>(supernodal.factor_nonzeros()),
      supernodal.vectorized() ? "yes" : "no");
  {
    // The work (multiply-adds) by supernode width.
    const int edges[] = {1, 2, 4, 8, 16, 32, 64, 1 << 30};
    double work[8] = {0};
    const std::vector<int>& super = supernodal.supernode_start();
    for (int s = 0; s < supernodal.num_supernodes(); ++s) {
      const int width = super[s + 1] - super[s];
      int b = 0;
      while (width >= edges[b + 1]) ++b;
      for (int j = super[s]; j < super[s + 1]; ++j) {
        const double count =
            supernodal.factor_start()[j + 1] - supernodal.factor_start()[j];
        work[b] += 0.5 * count * count;
      }
    }
    std::printf("  work by supernode width:");
    for (int b = 0; b < 7; ++b) {
      std::printf(" %d+: %.0f%%", edges[b], 100 * work[b] / flops);
    }
    std::printf("\n");
  }
  auto report = [&](const char* name, const Timing& t) {
    std::printf(
        "  %-22s analyze %8.3f s  factorize %8.3f s  (%.2f ns per "
        "multiply-add)\n",
        name, t.analyze, t.factorize, 1e9 * t.factorize / flops);
  };
  report("double-double supernodal", t_super);
  {
    std::vector<double> double_values(values.size());
    for (size_t q = 0; q < values.size(); ++q) {
      double_values[q] = values[q].hi;
    }
    DoubleDoubleCholesky in_double;
    const Timing t = TimeFactorization(&in_double, size, start, row,
                                       double_values, FLAGS_repeats);
    report("double supernodal", t);
    std::printf("    double-double / double: %.2fx, max difference %.3g\n",
                t_super.factorize / t.factorize,
                FactorDifference(supernodal, in_double));
    if (FLAGS_threads > 1) {
      const double one =
          WallFactorization(1, size, start, row, double_values, FLAGS_repeats);
      const double many = WallFactorization(FLAGS_threads, size, start, row,
                                            double_values, FLAGS_repeats);
      std::printf("    wall time: 1 thread %.3f s, %d threads %.3f s (%.2fx)\n",
                  one, FLAGS_threads, many, one / many);
    }
  }
  if (FLAGS_portable) {
    DoubleDoubleCholesky::Options options;
    options.vectorize = false;
    DoubleDoubleCholesky portable(options);
    report(
        "  portable (no SIMD)",
        TimeFactorization(&portable, size, start, row, values, FLAGS_repeats));
    std::printf("    difference from SIMD: %.3g\n",
                FactorDifference(supernodal, portable));
  }
  if (FLAGS_simplicial) {
    DoubleDoubleCholesky::Options options;
    options.supernodal = false;
    DoubleDoubleCholesky simplicial(options);
    const Timing t =
        TimeFactorization(&simplicial, size, start, row, values, 1);
    report("double-double simplicial", t);
    std::printf(
        "    speed-up %.2fx, max difference %.3g (relative to the "
        "row's largest entry)\n",
        t.factorize / t_super.factorize,
        FactorDifference(simplicial, supernodal));
  }
  if (FLAGS_cholmod) {
    internal::CholmodFactor factor;
    internal::ConfigureCholmod(internal::CholmodLayout::kSupernodal, &factor);
    Timing t;
    double begin = CpuNow();
    factor.AnalyzePatternWithOrdering(K, ordering);
    t.analyze = Seconds(begin);
    for (int r = 0; r < FLAGS_repeats; ++r) {
      begin = CpuNow();
      factor.factorize(K);
      t.factorize = std::min(t.factorize, Seconds(begin));
      CHECK(factor.info() == Eigen::Success);
    }
    report("CHOLMOD double", t);
    std::printf("    double-double / double: %.2fx\n",
                t_super.factorize / t.factorize);
  }
  std::fflush(stdout);
}

}  // namespace
}  // namespace ceres_sesync

int main(int argc, char** argv) {
  gflags::SetUsageMessage(
      "extended_cholesky_bench [--repeats N] [--simplicial] [--portable] "
      "[--nocholmod] GRAPH.g2o...");
  gflags::ParseCommandLineFlags(&argc, &argv, true);
  google::InitGoogleLogging(argv[0]);
  if (FLAGS_dense > 0) ceres_sesync::RunDense(FLAGS_dense);
  if (argc < 2 && FLAGS_dense == 0) {
    gflags::ShowUsageWithFlags(argv[0]);
    return 2;
  }
  for (int i = 1; i < argc; ++i) ceres_sesync::Run(argv[i]);
  return 0;
}
