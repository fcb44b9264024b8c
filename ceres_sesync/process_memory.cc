#include "ceres_sesync/process_memory.h"

#include <climits>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ceres_sesync {

bool KeepFreedMemory() {
#if defined(__GLIBC__)
  // mallopt returns 1 on success. 32 MiB is glibc's bound for the mmap
  // threshold on 64-bit targets (HEAP_MAX_SIZE / 2); setting either value
  // also turns off glibc's own adjustment of both. Blocks above it would
  // still be mapped one by one (an n x 5 matrix at 10^6 poses is 40 MB), so
  // M_MMAP_MAX = 0 turns block mapping off: every block comes from a heap
  // (glibc still maps when a heap cannot grow).
  const bool threshold_set = mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1;
  const bool mapping_off = mallopt(M_MMAP_MAX, 0) == 1;
  const bool trim_set = mallopt(M_TRIM_THRESHOLD, INT_MAX) == 1;
  return threshold_set && mapping_off && trim_set;
#else
  return false;
#endif
}

}  // namespace ceres_sesync
