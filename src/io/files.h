#pragma once

// Files without exceptions of the standard library's making: paths that may not exist, descriptors that may close.

#include <cstddef>
#include <filesystem>
#include <string>

namespace ecv {

/// Whether `path` names an existing file or folder. Never throws: a path that cannot be looked at (a name longer than
/// the system allows, a folder without search permission) counts as missing, so that the caller's "no such file"
/// error names it; std::filesystem::exists would throw filesystem_error instead.
bool PathExists(const std::filesystem::path& path);

/// Whether `path` names an existing folder; false, never a throw, where it cannot be looked at.
bool IsDirectory(const std::filesystem::path& path);

/// Throws InputError "<path>: <what>: expected a regular file, got ..." unless `path`, links followed, is a regular
/// file: a folder, a FIFO, a device or a socket is named as such ("got a directory"), a missing path "got no such
/// file". A FIFO or /dev/zero would make a reader wait or read without end.
void RequireRegularFile(const std::string& path, const std::string& what);

/// The bytes of the regular file `path` (links followed), at most `max_bytes` of them. Opened without waiting, then
/// checked as RequireRegularFile says, so that a FIFO or a device is refused without being read; a larger file is
/// refused before it is read ("<path>: <what>: expected at most N bytes, got M"). Throws InputError naming `path`
/// and `what`.
std::string ReadFileBytes(const std::string& path, const std::string& what, size_t max_bytes);

/// Writes all `size` bytes to the file descriptor `fd`, through short writes and interrupted calls; false when the
/// other end has gone (a closed pipe or socket) or the write fails (errno says why).
bool WriteAll(int fd, const void* bytes, size_t size);

}  // namespace ecv
