// Helpers for tests that run the `ceres_sesync` program as a user would:
// running it with captured output and exit code, temporary files, and a
// strict JSON validator for its --json files.

#ifndef CERES_SESYNC_TESTS_UTIL_CLI_TEST_UTIL_H_
#define CERES_SESYNC_TESTS_UTIL_CLI_TEST_UTIL_H_

#include <string>

namespace ceres_sesync::test_util {

// True if `text` is one valid JSON document (RFC 8259, strict).
bool IsValidJson(const std::string& text);

// A path in the test's temporary directory, unique to this process.
std::string TempPath(const std::string& name);
// Writes `text` to `path` (a test failure if that fails).
void WriteText(const std::string& path, const std::string& text);
// The contents of `path` ("" if it cannot be read).
std::string ReadText(const std::string& path);

struct RunResult {
  int exit_code = -1;
  std::string out;     // stdout.
  std::string err;     // stderr.
  std::string output;  // out + err.
};

// Runs the program CERES_SESYNC_TOOL with `args` (a shell command line:
// paths here contain no shell metacharacters); stdin is /dev/null.
RunResult RunTool(const std::string& args);

// The rest of the line after `label` in `text`, trimmed; "" if absent.
std::string ValueAfter(const std::string& text, const std::string& label);

// The number after `"key": ` at or after the first occurrence of `scope`
// (NaN if absent).
double JsonNumber(const std::string& json, const std::string& scope,
                  const std::string& key);

}  // namespace ceres_sesync::test_util

#endif  // CERES_SESYNC_TESTS_UTIL_CLI_TEST_UTIL_H_
