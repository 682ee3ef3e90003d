#include "io/files.h"

#include <errno.h>
#include <unistd.h>

#include <system_error>

namespace ecv {

bool PathExists(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::exists(path, error) && !error;
}

bool IsDirectory(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::is_directory(path, error) && !error;
}

bool WriteAll(int fd, const void* bytes, size_t size) {
  const auto* data = static_cast<const char*>(bytes);
  while (size > 0) {
    const ssize_t written = write(fd, data, size);
    if (written < 0 && errno == EINTR) continue;
    if (written <= 0) return false;
    data += written;
    size -= static_cast<size_t>(written);
  }
  return true;
}

}  // namespace ecv
