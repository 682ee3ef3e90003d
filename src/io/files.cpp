#include "io/files.h"

#include <errno.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <system_error>

#include "core/error.h"

namespace ecv {
namespace {

// What a file that is not a regular one is, for messages.
std::string KindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a named pipe (FIFO)";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "a special file";
}

// The InputError of a failed stat or open: a path that cannot be looked at counts as missing, as in PathExists.
[[noreturn]] void ThrowUnreadable(const std::string& path, const std::string& what, int error) {
  if (error == EACCES || error == EPERM) ThrowInputError(path, what, "a file this user can read", std::strerror(error));
  ThrowInputError(path, what, "an existing file", "no such file");
}

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() { close(fd_); }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

bool PathExists(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::exists(path, error) && !error;
}

bool IsDirectory(const std::filesystem::path& path) {
  std::error_code error;
  return std::filesystem::is_directory(path, error) && !error;
}

void RequireRegularFile(const std::string& path, const std::string& what) {
  struct stat status {};
  if (stat(path.c_str(), &status) != 0) ThrowUnreadable(path, what, errno);
  if (!S_ISREG(status.st_mode)) ThrowInputError(path, what, "a regular file", KindOf(status.st_mode));
}

std::string ReadFileBytes(const std::string& path, const std::string& what, size_t max_bytes) {
  RequireRegularFile(path, what);  // a device is not even opened
  // Without waiting: a FIFO put in the file's place meanwhile opens at once, and fstat refuses it unread.
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) ThrowUnreadable(path, what, errno);
  const FileDescriptor file(fd);
  struct stat status {};
  if (fstat(fd, &status) != 0) ThrowUnreadable(path, what, errno);
  if (!S_ISREG(status.st_mode)) ThrowInputError(path, what, "a regular file", KindOf(status.st_mode));
  const auto size = static_cast<size_t>(status.st_size);
  if (size > max_bytes) {
    ThrowInputError(path, what, "at most " + std::to_string(max_bytes) + " bytes", std::to_string(size) + " bytes");
  }
  std::string bytes(size, '\0');
  size_t done = 0;
  while (done < size) {  // the size stat gave, even if the file grows meanwhile
    const ssize_t got = read(fd, &bytes[done], size - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) ThrowInputError(path, what, "a readable file", std::strerror(errno));
    if (got == 0) break;  // shrunk meanwhile
    done += static_cast<size_t>(got);
  }
  bytes.resize(done);
  return bytes;
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
