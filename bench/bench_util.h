// Helpers shared by the benchmark programs (bench.cc, cube_sweep.cc,
// scaling.cc, outliers.cc, ...): timing, order statistics, formatting, peak
// memory, runs in a child process, and the short form of a Ceres
// termination.

#ifndef CERES_SESYNC_BENCH_BENCH_UTIL_H_
#define CERES_SESYNC_BENCH_BENCH_UTIL_H_

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

#include "ceres_sesync/ceres_baseline.h"
#include "ceres_sesync/landmark_generator.h"

namespace ceres_sesync::bench {

using Clock = std::chrono::steady_clock;

// A bench program's start: parses its flags (removing them from argv),
// starts glog on stderr, and shows only warnings and errors of the library
// unless --minloglevel asks for less.
void InitBenchProgram(int* argc, char*** argv);

// Wall-clock seconds since `start`.
double SecondsSince(Clock::time_point start);

// Sum, minimum and median (mean of the middle two for an even count) of
// `v`; Min and Median return NaN for an empty vector.
double Sum(const std::vector<double>& v);
double Min(const std::vector<double>& v);
double Median(std::vector<double> v);

// `v` formatted with the printf `format`, or "" for NaN.
std::string Fmt(const char* format, double v);

// `s` as one CSV field (quoted if it holds a comma or a quote).
std::string CsvField(const std::string& s);

// Comma-separated lists ("1,2,3"; empty items are skipped). Throw
// std::invalid_argument / std::out_of_range on a malformed number.
std::vector<int> ParseInts(const std::string& s);
std::vector<double> ParseDoubles(const std::string& s);

// Peak resident set size of this process so far (VmHWM of
// /proc/self/status), in MiB; NaN if unavailable.
double PeakRssMiB();

// Runs `child` in a forked process (SIGALRM after timeout_s seconds, at
// least 1; address space limited to max_memory_gb GiB if > 0), which writes
// `size` bytes to the buffer it is given; they are copied into `out` through
// a pipe. Returns true if the child sent them and exited with 0; otherwise
// false with the reason in *failure ("killed at --child_timeout", "killed by
// signal N (name)", "child exited with N (memory limit?)", or the failed
// system call).
bool RunInChildProcess(double timeout_s, double max_memory_gb,
                       const std::function<void(void* buffer)>& child,
                       void* out, size_t size, std::string* failure);
// The same for a trivially copyable result returned by fn().
template <typename Result, typename Fn>
bool RunInChildProcess(double timeout_s, double max_memory_gb, Fn&& fn,
                       Result* result, std::string* failure) {
  static_assert(std::is_trivially_copyable_v<Result>);
  return RunInChildProcess(
      timeout_s, max_memory_gb,
      [&fn](void* buffer) { *static_cast<Result*>(buffer) = fn(); }, result,
      sizeof(Result), failure);
}

// The shared library whose dgemm_ this process calls (CHOLMOD's supernodal
// factorizations, Ceres's and SE-Sync's alike, run in it: Debian's ATLAS and
// OpenBLAS differ ~2x there), resolved through symbolic links; "unknown" if
// it cannot be told.
std::string BlasLibrary();

// How a Ceres solve ended: converged, timeout, max_iterations,
// no_convergence, or Ceres's termination type.
std::string CeresStatus(const CeresBaselineSummary& summary);

// The generated landmark maps of the landmark benches (bench/landmarks.cc
// documents them): manhattan2d, manhattan2d_gps, manhattan3d,
// manhattan3d_gps, victoria; 300 poses each when `quick`, else 2000.
struct LandmarkCase {
  std::string name;
  LandmarkGraphOptions options;
};
std::vector<LandmarkCase> LandmarkCases(bool quick);

}  // namespace ceres_sesync::bench

#endif  // CERES_SESYNC_BENCH_BENCH_UTIL_H_
