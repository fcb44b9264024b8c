// KeepFreedMemory: a 48 MiB block (above every mmap threshold glibc accepts)
// comes from the heap, and freeing it leaves the heap at its size (no trim);
// without the call (a separate process: each test runs in its own) the same
// block is mapped on its own, so the second test fails if the setting is lost.
// ctest runs each test in a process of its own; run directly, the binary
// runs them in this order (the setting is process-wide).

#include "ceres_sesync/process_memory.h"

#include <cstdlib>
#include <cstring>

#include "gtest/gtest.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define CERES_SESYNC_SANITIZED_ALLOCATOR 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define CERES_SESYNC_SANITIZED_ALLOCATOR 1
#endif

namespace ceres_sesync {
namespace {

#if defined(__GLIBC__) && !defined(CERES_SESYNC_SANITIZED_ALLOCATOR)
// Above glibc's default mmap threshold (128 KiB) and above the largest one it
// accepts (32 MiB): only M_MMAP_MAX = 0 keeps such a block in the heap.
constexpr size_t kBlock = size_t{48} << 20;

// Allocates and touches kBlock bytes, frees them, and reports the mapped
// bytes while it was allocated and the heap size before and after the free.
struct BlockTrace {
  size_t mapped_before, mapped_during, heap_during, heap_after;
};
BlockTrace TraceOneBlock() {
  BlockTrace trace;
  trace.mapped_before = mallinfo2().hblkhd;
  void* block = std::malloc(kBlock);
  EXPECT_NE(block, nullptr);
  std::memset(block, 1, kBlock);
  const struct mallinfo2 during = mallinfo2();
  trace.mapped_during = during.hblkhd;
  trace.heap_during = during.arena;
  std::free(block);
  trace.heap_after = mallinfo2().arena;
  return trace;
}
#endif

TEST(ProcessMemory, WithoutItGlibcMapsTheBlock) {
#if !defined(__GLIBC__) || defined(CERES_SESYNC_SANITIZED_ALLOCATOR)
  GTEST_SKIP() << "glibc's malloc only";
#else
  const BlockTrace trace = TraceOneBlock();
  EXPECT_GE(trace.mapped_during, trace.mapped_before + kBlock);
#endif
}

TEST(ProcessMemory, FreedMemoryStaysWithTheProcess) {
#if !defined(__GLIBC__) || defined(CERES_SESYNC_SANITIZED_ALLOCATOR)
  GTEST_SKIP() << "glibc's malloc only";
#else
  ASSERT_TRUE(KeepFreedMemory());
  const BlockTrace trace = TraceOneBlock();
  EXPECT_EQ(trace.mapped_during, trace.mapped_before)
      << "the block was mapped on its own";
  EXPECT_GE(trace.heap_during, kBlock);
  EXPECT_EQ(trace.heap_after, trace.heap_during) << "the heap was trimmed";
#endif
}

}  // namespace
}  // namespace ceres_sesync
