// A tiny writer for JSON summaries (the command-line program's --json files).
//
// The writer holds one root object, opened by the constructor. Inside an
// object every value needs a key (the two-argument methods); inside an array
// values have none (the one-argument methods). Example:
//
//   JsonWriter json;
//   json.String("file", path);
//   json.Int("num_poses", 1045);
//   json.BeginObject("kappa");
//   json.Number("min", 1.5);
//   json.EndObject();
//   json.BeginArray("sizes");
//   json.Int(3);
//   json.EndArray();
//   std::string text = json.ToString();
//
// Strings are escaped per RFC 8259 (invalid UTF-8 bytes become U+FFFD);
// numbers are printed with "%.17g" (exact round trip) and NaN/Inf as null.
// Misuse (a key inside an array, unbalanced End*) is a programming error and
// is caught by CHECKs.

#ifndef CERES_SESYNC_INTERNAL_JSON_WRITER_H_
#define CERES_SESYNC_INTERNAL_JSON_WRITER_H_

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace ceres_sesync::internal {

class JsonWriter {
 public:
  // Opens the root object.
  JsonWriter();

  // Object members.
  void String(std::string_view key, std::string_view value);
  void Number(std::string_view key, double value);
  void Int(std::string_view key, int64_t value);
  void Bool(std::string_view key, bool value);
  void Null(std::string_view key);
  void BeginObject(std::string_view key);
  void BeginArray(std::string_view key);

  // Array elements.
  void String(std::string_view value);
  void Number(double value);
  void Int(int64_t value);
  void Bool(bool value);
  void Null();
  void BeginObject();
  void BeginArray();

  // Close the innermost open object / array.
  void EndObject();
  void EndArray();

  // The finished document (root object closed, trailing newline). Every
  // nested object and array must have been closed.
  std::string ToString() const;

  // Writes ToString() to `path` atomically (see file_util.h).
  bool WriteToFile(const std::string& path, std::string* error) const;

  // Appends `value` as a quoted, escaped JSON string to `out`.
  static void AppendQuoted(std::string_view value, std::string* out);
  // Appends `value` as a JSON number ("%.17g"), or null if not finite.
  static void AppendNumber(double value, std::string* out);

 private:
  void StartMember(std::string_view key);
  void StartElement();
  void Open(char bracket, bool is_array);
  void Close(char bracket, bool is_array);

  std::string text_;
  // One entry per open container: whether it is an array, and whether it has
  // no members yet.
  struct Level {
    bool is_array;
    bool empty;
  };
  std::vector<Level> stack_;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_JSON_WRITER_H_
