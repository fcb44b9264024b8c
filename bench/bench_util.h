// Helpers shared by the benchmark programs (bench.cc, cube_sweep.cc,
// scaling.cc): timing, order statistics, formatting, peak memory, and the
// short form of a Ceres termination.

#ifndef CERES_SESYNC_BENCH_BENCH_UTIL_H_
#define CERES_SESYNC_BENCH_BENCH_UTIL_H_

#include <chrono>
#include <string>
#include <vector>

#include "ceres_sesync/ceres_baseline.h"

namespace ceres_sesync::bench {

using Clock = std::chrono::steady_clock;

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

// How a Ceres solve ended: converged, timeout, max_iterations,
// no_convergence, or Ceres's termination type.
std::string CeresStatus(const CeresBaselineSummary& summary);

}  // namespace ceres_sesync::bench

#endif  // CERES_SESYNC_BENCH_BENCH_UTIL_H_
