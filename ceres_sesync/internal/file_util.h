// File helpers shared by the readers, writers and the command-line program.

#ifndef CERES_SESYNC_INTERNAL_FILE_UTIL_H_
#define CERES_SESYNC_INTERNAL_FILE_UTIL_H_

#include <string>
#include <string_view>

namespace ceres_sesync::internal {

// Writes `contents` to `path` atomically: the bytes go to a temporary file
// "PATH.tmp.XXXXXX" in the same directory (mkstemp), which is then renamed
// over `path`. Readers therefore see either the old file or the complete new
// one, never a partial file. On any failure the temporary file is removed,
// `path` is left untouched, and false is returned with a message in `error`
// (if not null). A new file gets mode 0644; an existing file keeps its mode.
// No fsync is done (crash durability is not a goal).
bool WriteFileAtomically(const std::string& path, std::string_view contents,
                         std::string* error);

// Reads the whole file at `path` into `contents`. Returns false with a
// message in `error` (if not null) if it cannot be opened or read.
bool ReadFileToString(const std::string& path, std::string* contents,
                      std::string* error);

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_FILE_UTIL_H_
