#include "app/sequence_io.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <thread>

#include "app/frame_args.h"
#include "core/error.h"
#include "io/files.h"
#include "io/frame_io.h"

namespace ecv::app {
namespace fs = std::filesystem;

LineOutput::LineOutput(const std::string& path, const std::string& flag) : path_(path) {
  if (path.empty()) return;
  if (path == "-") {
    fd_ = STDOUT_FILENO;
    return;
  }
  fd_ = open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) ThrowInputError(path, flag, "a file that can be written", std::strerror(errno));
  owned_ = true;
}

LineOutput::~LineOutput() {
  if (owned_) close(fd_);
}

void LineOutput::Write(const std::string& text) {
  if (!WriteAll(fd_, text.data(), text.size())) {
    ThrowInputError(path_ == "-" ? "standard output" : path_, "output", "room to write", std::strerror(errno));
  }
}

FrameFeed::FrameFeed(const std::string& sequence, bool follow, double idle_timeout_s, bool latest)
    : folder_(sequence), follow_(follow), latest_(latest && follow), idle_timeout_(idle_timeout_s) {
  if (!follow) {
    frames_ = ListSequenceFrames(sequence);
    return;
  }
  if (!IsDirectory(sequence)) {
    ThrowInputError(sequence, "--follow", "a folder that frame JSONs are written into", "no such folder");
  }
  watch_fd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (watch_fd_ >= 0 && inotify_add_watch(watch_fd_, sequence.c_str(), IN_CLOSE_WRITE | IN_MOVED_TO) < 0) {
    close(watch_fd_);
    watch_fd_ = -1;
  }
  Scan();
}

FrameFeed::~FrameFeed() {
  if (watch_fd_ >= 0) close(watch_fd_);
}

void FrameFeed::Wait(std::chrono::duration<double> most) {
  const auto most_ms = std::chrono::duration_cast<std::chrono::milliseconds>(most).count();
  if (watch_fd_ < 0) {  // no inotify (another file system, say): the folder is looked at every 10 ms
    std::this_thread::sleep_for(std::chrono::milliseconds(std::min<long long>(10, most_ms)));
    return;
  }
  pollfd watch{watch_fd_, POLLIN, 0};
  if (poll(&watch, 1, static_cast<int>(std::min<long long>(most_ms, 1000))) > 0) {
    char events[4096];
    while (read(watch_fd_, events, sizeof events) > 0) {
    }
  }
}

void FrameFeed::Scan() {
  std::error_code error;
  std::vector<std::string> found;
  for (fs::directory_iterator entry(folder_, error), end; !error && entry != end; entry.increment(error)) {
    const fs::path& path = entry->path();
    if (path.extension() == ".json" && seen_.insert(path.string()).second) found.push_back(path.string());
  }
  std::sort(found.begin(), found.end());
  frames_.insert(frames_.end(), found.begin(), found.end());
}

std::optional<std::string> FrameFeed::Next() {
  if (latest_) Scan();  // what arrived while the last frame was recognised
  if (follow_ && next_ == frames_.size()) {
    const auto since = std::chrono::steady_clock::now();
    while (next_ == frames_.size()) {
      const auto waited = std::chrono::steady_clock::now() - since;
      if (waited >= idle_timeout_) break;
      Wait(idle_timeout_ - waited);
      Scan();
    }
  }
  if (next_ == frames_.size()) return std::nullopt;
  skipped_ = latest_ ? static_cast<int>(frames_.size() - 1 - next_) : 0;
  next_ += static_cast<size_t>(skipped_);
  return frames_[next_++];
}

LoadedFrame FrameFeed::Load() {
  FrameSpec spec;
  spec.positional = frames_.at(next_ - 1);
  return LoadFrameWithWarnings(spec);
}

std::string FrameFeed::Counter() const {
  return "[" + std::to_string(next_) + (follow_ ? "" : "/" + std::to_string(frames_.size())) + "] ";
}

}  // namespace ecv::app
