#pragma once

// What a service may read for a request: files below the folders it was given, and which files a frame names.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "io/frame_io.h"

namespace ecv {

/// The folders below which files may be read, resolved once (links followed); none: anywhere.
class ReadRoots {
 public:
  ReadRoots() = default;

  /// Throws InputError naming a folder of `folders` that is not an existing folder.
  explicit ReadRoots(const std::vector<std::string>& folders);

  /// Whether `path` may be read. With roots: it is, links followed, a regular file below one of them. Without: it is
  /// a regular file or does not exist (its reader then says so); a FIFO, device or folder never is. Never throws.
  bool Allows(const std::string& path) const;

  const std::vector<std::filesystem::path>& folders() const { return folders_; }

 private:
  std::vector<std::filesystem::path> folders_;  // canonical
};

/// Calls `check` with each file LoadFrame(spec) reads, before LoadFrame reads any of them: the files `spec` names,
/// those a YCB-Video prefix or a BOP image implies (the optional ones where they exist) and, once `check` has passed
/// a frame JSON, the colour and depth files it names. `check` throws to refuse a file. A frame JSON that cannot be
/// parsed gives ReadJsonFile's InputError.
void CheckFrameFiles(const FrameSpec& spec, const std::function<void(const std::string&)>& check);

/// The files LoadBopFrame(scene_dir, image_id, depth_override) reads: its camera, colour and depth files and the
/// ground-truth files that exist (bop_io.cpp).
std::vector<std::string> BopFrameFiles(const std::string& scene_dir, int image_id, const std::string& depth_override);

}  // namespace ecv
