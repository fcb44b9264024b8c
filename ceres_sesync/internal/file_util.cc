#include "ceres_sesync/internal/file_util.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace ceres_sesync::internal {
namespace {

bool Fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::string ErrnoMessage(const std::string& what, const std::string& path) {
  return what + " '" + path + "': " + std::strerror(errno);
}

}  // namespace

bool WriteFileAtomically(const std::string& path, std::string_view contents,
                         std::string* error) {
  if (path.empty()) return Fail(error, "cannot write: empty output path");
  std::string temp = path + ".tmp.XXXXXX";
  std::vector<char> temp_name(temp.begin(), temp.end());
  temp_name.push_back('\0');
  const int fd = mkstemp(temp_name.data());
  if (fd < 0)
    return Fail(error, ErrnoMessage("cannot create a file next to", path));
  temp.assign(temp_name.data());

  auto fail_and_clean = [&](const std::string& message) {
    unlink(temp.c_str());
    return Fail(error, message);
  };

  // mkstemp creates the file with mode 0600; use the mode of the file being
  // replaced, or 0644 for a new one.
  struct stat existing;
  const mode_t mode =
      stat(path.c_str(), &existing) == 0 ? (existing.st_mode & 07777) : 0644;
  if (fchmod(fd, mode) != 0) {
    const std::string message = ErrnoMessage("cannot set the mode of", temp);
    close(fd);
    return fail_and_clean(message);
  }

  const char* data = contents.data();
  size_t remaining = contents.size();
  while (remaining > 0) {
    const ssize_t n = write(fd, data, remaining);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string message = ErrnoMessage("cannot write", temp);
      close(fd);
      return fail_and_clean(message);
    }
    data += n;
    remaining -= static_cast<size_t>(n);
  }
  if (close(fd) != 0) return fail_and_clean(ErrnoMessage("cannot close", temp));
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    return fail_and_clean(
        ErrnoMessage("cannot rename the temporary file to", path));
  }
  return true;
}

bool ReadFileToString(const std::string& path, std::string* contents,
                      std::string* error) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return Fail(error, ErrnoMessage("cannot open", path));
  contents->clear();
  char buffer[1 << 16];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof(buffer), file)) > 0) {
    contents->append(buffer, n);
  }
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return Fail(error, ErrnoMessage("cannot read", path));
  return true;
}

}  // namespace ceres_sesync::internal
