// A process-wide allocator setting for programs that solve many problems, or
// large ones, in one process.
//
// glibc's malloc hands freed memory back to the kernel eagerly: the free top
// of its heaps beyond M_TRIM_THRESHOLD, and every block above
// M_MMAP_THRESHOLD, which it maps on its own and unmaps on free (both start
// at 128 KiB; glibc raises them as large blocks are freed). A solve
// allocates and frees its matrices, factors and work vectors, so the next
// factorization, and the next solve, first-touch fresh pages again: one page
// fault per 4 KiB, and the kernel zeroes each page. Where faults are
// expensive that costs a large share of the time. Measured on the
// paravirtualized 2-core machine of bench/ (a fault there costs ~12 us;
// bench/results/process_memory/): repeated solves of kitti_00 (4541 poses),
// 2462 faults per solve and certify, about 40% of their time, and none
// with this setting. One solve of a 10^6-pose city: 20.3M faults and 865 s
// with the thresholds below alone (its n x 5 matrices, 40 MB each, were
// still mapped and unmapped at every product), 2.8M and 629 s with block
// mapping off as well.
//
// KeepFreedMemory() sets M_MMAP_THRESHOLD to 32 MiB (glibc's largest),
// M_MMAP_MAX to 0 (no block is mapped on its own, whatever its size) and
// M_TRIM_THRESHOLD to 2 GiB - 1: every block comes from the heaps, and freed
// memory stays with the process for the next allocation. The price is
// that the process keeps its peak heap size until it exits. Large numeric
// buffers that the library maps itself (huge_page_allocator.h) are not
// affected.
//
// It changes every allocation of the process, which is why the library never
// calls it: programs opt in. The ceres_sesync tool and the benchmark
// programs call it first thing in main(), so that SE-Sync and the Ceres
// baselines run under the same allocator settings.
#ifndef CERES_SESYNC_PROCESS_MEMORY_H_
#define CERES_SESYNC_PROCESS_MEMORY_H_

namespace ceres_sesync {

// Returns false (and changes nothing, or part of it) where the C library is
// not glibc or refuses a setting (e.g. under a sanitizer's allocator).
bool KeepFreedMemory();

}  // namespace ceres_sesync

#endif  // CERES_SESYNC_PROCESS_MEMORY_H_
