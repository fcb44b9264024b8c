// HugePageAllocator: vectors keep their contents through growth, copies and
// shrinking at every size; large blocks are 2 MiB aligned and the kernel
// records the huge-page advice on their mapping (where THP is available and
// the build is not sanitized); small ones come from the standard allocator.

#include "ceres_sesync/internal/huge_page_allocator.h"

#include <cstdint>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>

#include "gtest/gtest.h"

namespace ceres_sesync::internal {
namespace {

TEST(HugePageAllocator, VectorsKeepTheirContentsAtEverySize) {
  // From below the threshold (standard allocator) through it (growth moves
  // the contents into a mapped block) and back (shrink_to_fit).
  HugePageVector<int> v;
  const int large = static_cast<int>(3 * kHugePageMinBytes / sizeof(int));
  for (int i = 0; i < large; ++i) v.push_back(i);
  for (int i = 0; i < large; ++i) ASSERT_EQ(v[i], i) << i;
  HugePageVector<int> copy = v;
  EXPECT_EQ(copy, v);
  v.resize(100);
  v.shrink_to_fit();
  for (int i = 0; i < 100; ++i) ASSERT_EQ(v[i], i);
  HugePageVector<double> zeros;
  zeros.assign(kHugePageMinBytes / sizeof(double) + 7, 0.0);
  EXPECT_EQ(std::accumulate(zeros.begin(), zeros.end(), 0.0), 0.0);
  zeros.assign(zeros.size(), 1.5);
  EXPECT_EQ(std::accumulate(zeros.begin(), zeros.end(), 0.0),
            1.5 * static_cast<double>(zeros.size()));
}

#ifdef CERES_SESYNC_HUGE_PAGES
constexpr std::uintptr_t kTwoMiB = std::uintptr_t{2} << 20;

// The VmFlags line of the mapping containing `address` in /proc/self/smaps.
std::string VmFlagsOf(const void* address) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream header(line);
    if (header >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}
#endif

TEST(HugePageAllocator, LargeBlocksAreAlignedAndAdvised) {
#ifndef CERES_SESYNC_HUGE_PAGES
  GTEST_SKIP() << "huge-page blocks are Linux-only and off under "
                  "AddressSanitizer";
#else
  HugePageVector<double> large(kHugePageMinBytes / sizeof(double));
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(large.data()) % kTwoMiB, 0u);
  std::ifstream thp("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(thp, mode);
  if (mode.empty() || mode.find("[never]") != std::string::npos) {
    GTEST_SKIP() << "transparent huge pages are off on this machine ("
                 << (mode.empty() ? "no THP" : mode) << ")";
  }
  // "hg": the mapping carries MADV_HUGEPAGE.
  const std::string flags = VmFlagsOf(large.data());
  ASSERT_FALSE(flags.empty()) << "no mapping found in /proc/self/smaps";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;
  HugePageVector<double> small(1000);
  EXPECT_EQ(VmFlagsOf(small.data()).find(" hg"), std::string::npos);
#endif
}

}  // namespace
}  // namespace ceres_sesync::internal
