#include <cstdio>

#include "tools/commands.h"

namespace ceres_sesync::tools {

// Placeholder until the owning issue lands.
int RunInfo(const Args&) {
  std::fputs("ceres_sesync info: not implemented yet\n", stderr);
  return kUsageOrInputError;
}

}  // namespace ceres_sesync::tools
