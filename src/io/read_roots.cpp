#include "io/read_roots.h"

#include <algorithm>
#include <system_error>

#include "core/error.h"

namespace ecv {
namespace fs = std::filesystem;

ReadRoots::ReadRoots(const std::vector<std::string>& folders) {
  for (const std::string& folder : folders) {
    std::error_code error;
    const fs::path canonical = fs::canonical(folder, error);
    if (error || !fs::is_directory(canonical, error) || error) {
      ThrowInputError(folder, "--root", "an existing folder", error ? error.message() : "not a folder");
    }
    folders_.push_back(canonical);
  }
}

bool ReadRoots::Allows(const std::string& path) const {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // links followed
  if (folders_.empty()) return error || status.type() == fs::file_type::not_found || fs::is_regular_file(status);
  if (error || !fs::is_regular_file(status)) return false;
  const fs::path resolved = fs::canonical(path, error);
  if (error) return false;
  return std::any_of(folders_.begin(), folders_.end(), [&](const fs::path& folder) {
    // Below `folder`: its components start the resolved path's (canonical paths: no "." or "..", no links).
    return std::mismatch(folder.begin(), folder.end(), resolved.begin(), resolved.end()).first == folder.end();
  });
}

}  // namespace ecv
