#include "ceres_sesync/internal/huge_page_allocator.h"

#ifdef CERES_SESYNC_HUGE_PAGES
#include <sys/mman.h>

#include <cstdint>

namespace ceres_sesync::internal {
namespace {

constexpr std::size_t kHugePage = std::size_t{2} << 20;

std::size_t RoundUp(std::size_t bytes) {
  return (bytes + kHugePage - 1) / kHugePage * kHugePage;
}

}  // namespace

void* MapHugePages(std::size_t bytes) {
  const std::size_t size = RoundUp(bytes);
  // Over-map by one huge page and trim to a 2 MiB-aligned block, so that
  // every page of it can be a huge one.
  void* raw = mmap(nullptr, size + kHugePage, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto begin = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned =
      (begin + kHugePage - 1) / kHugePage * kHugePage;
  if (aligned > begin) munmap(raw, aligned - begin);
  const std::uintptr_t end = begin + size + kHugePage;
  if (end > aligned + size) {
    munmap(reinterpret_cast<void*>(aligned + size), end - (aligned + size));
  }
  void* p = reinterpret_cast<void*>(aligned);
  madvise(p, size, MADV_HUGEPAGE);  // A hint: failure changes nothing.
  return p;
}

void UnmapHugePages(void* p, std::size_t bytes) { munmap(p, RoundUp(bytes)); }

}  // namespace ceres_sesync::internal
#endif  // CERES_SESYNC_HUGE_PAGES
