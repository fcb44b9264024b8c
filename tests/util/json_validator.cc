#include "tests/util/json_validator.h"

#include <cctype>
#include <string>

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

}  // namespace ceres_sesync::test_util
