#include "tests/util/tool_runner.h"

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>

namespace ceres_sesync::test_util {

bool ToolBuilt() { return !std::string(CERES_SESYNC_TOOL).empty(); }

int RunTool(const std::string& arguments) {
  const std::string command =
      std::string(CERES_SESYNC_TOOL) + " " + arguments + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool FileExists(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "r");
  if (f) std::fclose(f);
  return f != nullptr;
}

}  // namespace ceres_sesync::test_util
