// A std::allocator replacement for the large numeric buffers that are filled
// right after they are allocated (the double-double factor's blocks): on
// Linux, blocks of at least kHugePageMinBytes are mapped on their own,
// aligned to 2 MiB and advised MADV_HUGEPAGE, so that the kernel can back
// them with transparent huge pages. Debian's default THP mode is "madvise":
// without the advice every 4 KiB page of a fresh buffer costs a page fault on
// first touch. Measured on the 10^5-pose city (2 threads, a paravirtualized
// machine where a fault costs ~10 us): page faults were 18% of the solve's
// CPU time, half of them filling the double-double factor's ~500 MB of
// blocks.
//
// The advice is a hint: with THP off ("never") or no huge page free the
// kernel falls back to 4 KiB pages, and the results are the same either way.
// Under AddressSanitizer the standard allocator is used, so that the
// sanitizer still sees every access.

#ifndef CERES_SESYNC_INTERNAL_HUGE_PAGE_ALLOCATOR_H_
#define CERES_SESYNC_INTERNAL_HUGE_PAGE_ALLOCATOR_H_

#include <cstddef>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CERES_SESYNC_ASAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define CERES_SESYNC_ASAN 1
#endif
#if defined(__linux__) && !defined(CERES_SESYNC_ASAN)
#define CERES_SESYNC_HUGE_PAGES 1
#endif

namespace ceres_sesync::internal {

// Smallest block mapped with the advice (smaller ones gain little and would
// round up to 2 MiB).
inline constexpr std::size_t kHugePageMinBytes = std::size_t{4} << 20;

#ifdef CERES_SESYNC_HUGE_PAGES
// Maps `bytes` (>= kHugePageMinBytes) 2 MiB-aligned with MADV_HUGEPAGE, zero
// filled (fresh anonymous pages); throws std::bad_alloc when it cannot.
// UnmapHugePages releases such a block.
void* MapHugePages(std::size_t bytes);
void UnmapHugePages(void* p, std::size_t bytes);
#endif

template <typename T>
struct HugePageAllocator {
  using value_type = T;

  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) {}  // NOLINT

  T* allocate(std::size_t n) {
#ifdef CERES_SESYNC_HUGE_PAGES
    if (n * sizeof(T) >= kHugePageMinBytes) {
      return static_cast<T*>(MapHugePages(n * sizeof(T)));
    }
#endif
    return std::allocator<T>().allocate(n);
  }

  void deallocate(T* p, std::size_t n) {
#ifdef CERES_SESYNC_HUGE_PAGES
    if (n * sizeof(T) >= kHugePageMinBytes) {
      UnmapHugePages(p, n * sizeof(T));
      return;
    }
#endif
    std::allocator<T>().deallocate(p, n);
  }

  // Value-less construction default-initializes: resize(n) and vector(n)
  // leave arithmetic elements unwritten (callers fill them; a fresh mapped
  // block is then first touched where it is filled). assign(n, value) and
  // the other constructors write as usual.
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const {
    return true;
  }
  template <typename U>
  bool operator!=(const HugePageAllocator<U>&) const {
    return false;
  }
};

template <typename T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_HUGE_PAGE_ALLOCATOR_H_
