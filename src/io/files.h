#pragma once

// Files without exceptions of the standard library's making: paths that may not exist, descriptors that may close.

#include <cstddef>
#include <filesystem>

namespace ecv {

/// Whether `path` names an existing file or folder. Never throws: a path that cannot be looked at (a name longer than
/// the system allows, a folder without search permission) counts as missing, so that the caller's "no such file"
/// error names it; std::filesystem::exists would throw filesystem_error instead.
bool PathExists(const std::filesystem::path& path);

/// Whether `path` names an existing folder; false, never a throw, where it cannot be looked at.
bool IsDirectory(const std::filesystem::path& path);

/// Writes all `size` bytes to the file descriptor `fd`, through short writes and interrupted calls; false when the
/// other end has gone (a closed pipe or socket) or the write fails (errno says why).
bool WriteAll(int fd, const void* bytes, size_t size);

}  // namespace ecv
