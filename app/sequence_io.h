#pragma once

// The input and output of `ecvpose recognize --sequence` as a stream: frames as they come (a folder still being
// filled), detections written as each frame is done.

#include <chrono>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "io/frame_source.h"

namespace ecv::app {

/// Where results go line by line: a file, truncated when opened, or standard output for "-". Each Write reaches the
/// file in one system call, at once (no buffering), so that a reader following the file sees each line whole as
/// soon as it is written.
class LineOutput {
 public:
  /// No output for an empty `path`. Throws InputError naming `path` (and `flag`) when it cannot be opened.
  LineOutput(const std::string& path, const std::string& flag);
  ~LineOutput();
  LineOutput(const LineOutput&) = delete;
  LineOutput& operator=(const LineOutput&) = delete;

  bool active() const { return fd_ >= 0; }

  /// Appends `text` (whole lines); throws InputError naming the file when it cannot.
  void Write(const std::string& text);

 private:
  std::string path_;
  int fd_ = -1;
  bool owned_ = false;
};

/// The frame files of --sequence, in order. With `follow`, the frame JSONs of a folder still being filled, in name
/// order as they appear (a producer writes the images first and the JSON last, by rename), until `idle_timeout_s` pass
/// without a new one; with `latest` too, only the newest of the frames waiting, the others skipped.
class FrameFeed : public FrameSource {
 public:
  FrameFeed(const std::string& sequence, bool follow, double idle_timeout_s, bool latest = false);
  ~FrameFeed() override;
  FrameFeed(const FrameFeed&) = delete;
  FrameFeed& operator=(const FrameFeed&) = delete;

  /// The next frame's file (FRAME); nothing at the end.
  std::optional<std::string> Next() override;

  /// The frame Next named, read with the frame readers' warnings on stderr.
  LoadedFrame Load() override;

  /// "[3/10] " for a list of known length, "[3] " when following.
  std::string Counter() const override;

  int Skipped() const override { return skipped_; }

 private:
  void Scan();                                    // adds the folder's frame JSONs not seen yet, in name order
  void Wait(std::chrono::duration<double> most);  // until a file lands in the folder (inotify), or `most` passes

  std::string folder_;
  bool follow_;
  bool latest_;
  int skipped_ = 0;
  std::chrono::duration<double> idle_timeout_;
  std::vector<std::string> frames_;
  size_t next_ = 0;
  std::set<std::string> seen_;
  int watch_fd_ = -1;  // with `follow`: inotify on the folder's finished and moved-in files; -1: polled
};

}  // namespace ecv::app
