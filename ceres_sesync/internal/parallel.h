// Minimal data-parallel loops for the heavy O(m r) kernels. Every kernel is
// split so that each output element is computed by exactly one thread with
// the same arithmetic as the serial code: results do not depend on the
// thread count.
//
// Threads are started per call and joined (blocking, no spinning). OpenMP
// was tried first and rejected: its busy-waiting barriers made the solver up
// to 4x slower whenever the cores were shared (e.g. ctest -j2, or a build
// running alongside), while starting a thread costs ~20-50 us, which the
// work threshold below keeps under a few percent.

#ifndef CERES_SESYNC_INTERNAL_PARALLEL_H_
#define CERES_SESYNC_INTERNAL_PARALLEL_H_

#include <algorithm>
#include <thread>
#include <vector>

namespace ceres_sesync::internal {

// num_threads <= 0 means all cores.
inline int ResolveNumThreads(int num_threads) {
  if (num_threads > 0) return num_threads;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

// Threads worth using for `work` floating-point operations: below ~1e7
// (about 1.5 ms) a second thread did not pay on the 2-core machine, where
// starting and joining one costs ~50 us and its caches start cold (with 1e6:
// MultiplyQ of city10000 1.0 -> 1.3 ms, the exact preconditioner of
// ais2klinik 1.1 -> 1.2-1.6 ms with two threads).
inline int ThreadsFor(int num_threads, double work) {
  return work < 1e7 ? 1 : std::max(1, num_threads);
}

// Threads worth using for a blockwise pass over `entries` doubles of each
// operand (the tangent projection, block-diagonal products), which is bound
// by memory traffic rather than flops. Measured on the 2-core machine, r = 4,
// d = 2, one -> two threads: 2.6e5 entries 0.14 -> 0.14 ms (projection) and
// 0.09 -> 0.12 ms (block product), 5.2e5 0.33 -> 0.26 and 0.20 -> 0.19 ms,
// 8e5 (the 10^5-pose city) 0.51-0.58 -> 0.33-0.35 and 0.34 -> 0.24 ms.
inline int ThreadsForPass(int num_threads, double entries) {
  return entries < (1 << 19) ? 1 : std::max(1, num_threads);
}

// Calls f(part, num_parts) for part = 0 .. num_parts - 1, part 0 on the
// calling thread and the others on threads of their own.
template <typename F>
void ParallelParts(int num_parts, F&& f) {
  std::vector<std::thread> threads;
  threads.reserve(std::max(0, num_parts - 1));
  for (int part = 1; part < num_parts; ++part) {
    threads.emplace_back([&f, part, num_parts] { f(part, num_parts); });
  }
  f(0, std::max(1, num_parts));
  for (std::thread& thread : threads) thread.join();
}

// First item of part `part` when `size` items are split into `parts`.
inline int PartBegin(int size, int part, int parts) {
  return static_cast<int>(static_cast<long long>(size) * part / parts);
}

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_PARALLEL_H_
