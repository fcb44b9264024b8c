#include "ceres_sesync/internal/json_writer.h"

#include <cmath>
#include <cstdio>

#include "ceres_sesync/internal/file_util.h"
#include "glog/logging.h"

namespace ceres_sesync::internal {
namespace {

// Length of the valid UTF-8 sequence starting at s[i], or 0 if invalid.
size_t Utf8SequenceLength(std::string_view s, size_t i) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = byte(i);
  size_t length;
  uint32_t code;
  if (c < 0x80) return 1;
  if ((c & 0xE0) == 0xC0) {
    length = 2, code = c & 0x1F;
  } else if ((c & 0xF0) == 0xE0) {
    length = 3, code = c & 0x0F;
  } else if ((c & 0xF8) == 0xF0) {
    length = 4, code = c & 0x07;
  } else {
    return 0;
  }
  if (i + length > s.size()) return 0;
  for (size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    code = (code << 6) | (byte(i + k) & 0x3F);
  }
  static constexpr uint32_t kMinCode[] = {0, 0, 0x80, 0x800, 0x10000};
  if (code < kMinCode[length] || code > 0x10FFFF ||
      (code >= 0xD800 && code <= 0xDFFF)) {
    return 0;  // Overlong, out of range, or a surrogate.
  }
  return length;
}

}  // namespace

JsonWriter::JsonWriter() { Open('{', /*is_array=*/false); }

void JsonWriter::AppendQuoted(std::string_view value, std::string* out) {
  out->push_back('"');
  for (size_t i = 0; i < value.size();) {
    const unsigned char c = static_cast<unsigned char>(value[i]);
    if (c >= 0x80) {
      const size_t length = Utf8SequenceLength(value, i);
      if (length == 0) {
        out->append("\\ufffd");
        ++i;
      } else {
        out->append(value.substr(i, length));
        i += length;
      }
      continue;
    }
    switch (c) {
      case '"':
        out->append("\\\"");
        break;
      case '\\':
        out->append("\\\\");
        break;
      case '\b':
        out->append("\\b");
        break;
      case '\f':
        out->append("\\f");
        break;
      case '\n':
        out->append("\\n");
        break;
      case '\r':
        out->append("\\r");
        break;
      case '\t':
        out->append("\\t");
        break;
      default:
        if (c < 0x20) {
          char buffer[8];
          std::snprintf(buffer, sizeof(buffer), "\\u%04x", c);
          out->append(buffer);
        } else {
          out->push_back(static_cast<char>(c));
        }
    }
    ++i;
  }
  out->push_back('"');
}

void JsonWriter::AppendNumber(double value, std::string* out) {
  if (!std::isfinite(value)) {
    out->append("null");
    return;
  }
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  out->append(buffer);
}

void JsonWriter::StartMember(std::string_view key) {
  CHECK(!stack_.empty() && !stack_.back().is_array)
      << "JsonWriter: a keyed member must be inside an object";
  if (!stack_.back().empty) text_.push_back(',');
  stack_.back().empty = false;
  text_.push_back('\n');
  text_.append(2 * stack_.size(), ' ');
  AppendQuoted(key, &text_);
  text_.append(": ");
}

void JsonWriter::StartElement() {
  CHECK(!stack_.empty() && stack_.back().is_array)
      << "JsonWriter: an element without a key must be inside an array";
  if (!stack_.back().empty) text_.append(", ");
  stack_.back().empty = false;
}

void JsonWriter::Open(char bracket, bool is_array) {
  text_.push_back(bracket);
  stack_.push_back({is_array, true});
}

void JsonWriter::Close(char bracket, bool is_array) {
  CHECK(stack_.size() > 1 && stack_.back().is_array == is_array)
      << "JsonWriter: unbalanced End" << (is_array ? "Array" : "Object");
  const bool was_empty = stack_.back().empty;
  stack_.pop_back();
  if (!is_array && !was_empty) {
    text_.push_back('\n');
    text_.append(2 * stack_.size(), ' ');
  }
  text_.push_back(bracket);
}

void JsonWriter::String(std::string_view key, std::string_view value) {
  StartMember(key);
  AppendQuoted(value, &text_);
}
void JsonWriter::Number(std::string_view key, double value) {
  StartMember(key);
  AppendNumber(value, &text_);
}
void JsonWriter::Int(std::string_view key, int64_t value) {
  StartMember(key);
  text_.append(std::to_string(value));
}
void JsonWriter::Bool(std::string_view key, bool value) {
  StartMember(key);
  text_.append(value ? "true" : "false");
}
void JsonWriter::Null(std::string_view key) {
  StartMember(key);
  text_.append("null");
}
void JsonWriter::BeginObject(std::string_view key) {
  StartMember(key);
  Open('{', false);
}
void JsonWriter::BeginArray(std::string_view key) {
  StartMember(key);
  Open('[', true);
}

void JsonWriter::String(std::string_view value) {
  StartElement();
  AppendQuoted(value, &text_);
}
void JsonWriter::Number(double value) {
  StartElement();
  AppendNumber(value, &text_);
}
void JsonWriter::Int(int64_t value) {
  StartElement();
  text_.append(std::to_string(value));
}
void JsonWriter::Bool(bool value) {
  StartElement();
  text_.append(value ? "true" : "false");
}
void JsonWriter::Null() {
  StartElement();
  text_.append("null");
}
void JsonWriter::BeginObject() {
  StartElement();
  Open('{', false);
}
void JsonWriter::BeginArray() {
  StartElement();
  Open('[', true);
}

void JsonWriter::EndObject() { Close('}', false); }
void JsonWriter::EndArray() { Close(']', true); }

std::string JsonWriter::ToString() const {
  CHECK_EQ(stack_.size(), 1u) << "JsonWriter: unclosed object or array";
  std::string out = text_;
  out.append(stack_.back().empty ? "}\n" : "\n}\n");
  return out;
}

bool JsonWriter::WriteToFile(const std::string& path,
                             std::string* error) const {
  return WriteFileAtomically(path, ToString(), error);
}

}  // namespace ceres_sesync::internal
