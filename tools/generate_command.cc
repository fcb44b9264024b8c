#include <cstdio>

#include "tools/commands.h"

namespace ceres_sesync::tools {

// Placeholder until the owning issue lands.
int RunGenerate(const Args&) {
  std::fputs("ceres_sesync generate: not implemented yet\n", stderr);
  return kUsageOrInputError;
}

}  // namespace ceres_sesync::tools
