#include "tests/util/tool_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "gtest/gtest.h"

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

std::string TempPath(const std::string& name) {
  return testing::TempDir() + "cli_test_" + std::to_string(getpid()) + "_" +
         name;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

RunResult RunToolWithOutput(const std::string& args) {
  RunResult result;
  const std::string err_path = TempPath("stderr.txt");
  const std::string command =
      std::string(CERES_SESYNC_TOOL) + " " + args + " </dev/null 2>" + err_path;
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) {
    result.out.append(buffer, n);
  }
  const int status = pclose(pipe);
  if (status != -1 && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  result.err = ReadText(err_path);
  std::remove(err_path.c_str());
  result.output = result.out + result.err;
  return result;
}

std::string ValueAfter(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  if (at == std::string::npos) return "";
  size_t begin = at + label.size();
  const size_t end = text.find('\n', begin);
  while (begin < end && text[begin] == ' ') ++begin;
  return text.substr(begin, end - begin);
}

double JsonNumber(const std::string& json, const std::string& scope,
                  const std::string& key) {
  const size_t from = json.find(scope);
  if (from == std::string::npos) return std::nan("");
  const size_t at = json.find("\"" + key + "\": ", from);
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

}  // namespace ceres_sesync::test_util
