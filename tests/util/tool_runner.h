// Runs the `ceres_sesync` command-line program from tests.

#ifndef CERES_SESYNC_TESTS_UTIL_TOOL_RUNNER_H_
#define CERES_SESYNC_TESTS_UTIL_TOOL_RUNNER_H_

#include <string>

namespace ceres_sesync::test_util {

// Whether the tool was built (CERES_SESYNC_TOOL names it).
bool ToolBuilt();

// Runs the tool with `arguments` (a shell word list), its output discarded.
// Returns its exit code, or -1 if it did not exit normally.
int RunTool(const std::string& arguments);

// Whether `path` can be opened for reading.
bool FileExists(const std::string& path);

}  // namespace ceres_sesync::test_util

#endif  // CERES_SESYNC_TESTS_UTIL_TOOL_RUNNER_H_
