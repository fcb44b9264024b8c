#include "tests/util/cli_test_util.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "gtest/gtest.h"

namespace ceres_sesync::test_util {
namespace {

// ---- a minimal strict JSON validator (RFC 8259) ---------------------------

class JsonValidator {
 public:
  explicit JsonValidator(const std::string& text) : s_(text) {}

  bool Valid() {
    SkipSpace();
    if (!Value()) return false;
    SkipSpace();
    return k_ == s_.size();
  }

 private:
  void SkipSpace() {
    while (k_ < s_.size() && (s_[k_] == ' ' || s_[k_] == '\n' ||
                              s_[k_] == '\r' || s_[k_] == '\t')) {
      ++k_;
    }
  }
  bool Literal(const char* word) {
    const std::string w(word);
    if (s_.compare(k_, w.size(), w) != 0) return false;
    k_ += w.size();
    return true;
  }
  bool Digits() {
    const size_t start = k_;
    while (k_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[k_]))) {
      ++k_;
    }
    return k_ > start;
  }
  bool Number() {
    if (s_[k_] == '-') ++k_;
    if (k_ < s_.size() && s_[k_] == '0') {
      ++k_;
    } else if (!Digits()) {
      return false;
    }
    if (k_ < s_.size() && s_[k_] == '.') {
      ++k_;
      if (!Digits()) return false;
    }
    if (k_ < s_.size() && (s_[k_] == 'e' || s_[k_] == 'E')) {
      ++k_;
      if (k_ < s_.size() && (s_[k_] == '+' || s_[k_] == '-')) ++k_;
      if (!Digits()) return false;
    }
    return true;
  }
  bool String() {
    if (s_[k_] != '"') return false;
    for (++k_; k_ < s_.size(); ++k_) {
      const unsigned char c = s_[k_];
      if (c == '"') {
        ++k_;
        return true;
      }
      if (c < 0x20) return false;
      if (c == '\\') {
        if (++k_ >= s_.size()) return false;
        const char e = s_[k_];
        if (e == 'u') {
          for (int h = 0; h < 4; ++h) {
            if (++k_ >= s_.size() ||
                !std::isxdigit(static_cast<unsigned char>(s_[k_]))) {
              return false;
            }
          }
        } else if (std::string("\"\\/bfnrt").find(e) == std::string::npos) {
          return false;
        }
      }
    }
    return false;
  }
  template <typename Item>
  bool Sequence(char close, Item item) {
    ++k_;
    SkipSpace();
    if (k_ < s_.size() && s_[k_] == close) {
      ++k_;
      return true;
    }
    while (true) {
      SkipSpace();
      if (!item()) return false;
      SkipSpace();
      if (k_ >= s_.size()) return false;
      if (s_[k_] == close) {
        ++k_;
        return true;
      }
      if (s_[k_++] != ',') return false;
    }
  }
  bool Value() {
    if (k_ >= s_.size()) return false;
    switch (s_[k_]) {
      case '{':
        return Sequence('}', [&] {
          if (k_ >= s_.size() || !String()) return false;
          SkipSpace();
          if (k_ >= s_.size() || s_[k_++] != ':') return false;
          SkipSpace();
          return Value();
        });
      case '[':
        return Sequence(']', [&] { return Value(); });
      case '"':
        return String();
      case 't':
        return Literal("true");
      case 'f':
        return Literal("false");
      case 'n':
        return Literal("null");
      default:
        return Number();
    }
  }

  const std::string& s_;
  size_t k_ = 0;
};

}  // namespace

bool IsValidJson(const std::string& text) {
  return JsonValidator(text).Valid();
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

RunResult RunTool(const std::string& args) {
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
