// Runs the `ceres_sesync` command-line program from tests, as a user would,
// and reads what it wrote.

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

struct RunResult {
  int exit_code = -1;
  std::string out;     // stdout.
  std::string err;     // stderr.
  std::string output;  // out + err.
};

// Runs the tool with `arguments` (as RunTool), capturing stdout and stderr
// separately; stdin is /dev/null.
RunResult RunToolWithOutput(const std::string& arguments);

// A path in the test's temporary directory, unique to this process.
std::string TempPath(const std::string& name);
// Writes `text` to `path` (a test failure if that fails).
void WriteText(const std::string& path, const std::string& text);
// The contents of `path` ("" if it cannot be read).
std::string ReadText(const std::string& path);

// The rest of the line after `label` in `text`, trimmed; "" if absent.
std::string ValueAfter(const std::string& text, const std::string& label);

// The number after `"key": ` at or after the first occurrence of `scope`
// (NaN if absent).
double JsonNumber(const std::string& json, const std::string& scope,
                  const std::string& key);

}  // namespace ceres_sesync::test_util

#endif  // CERES_SESYNC_TESTS_UTIL_TOOL_RUNNER_H_
