#pragma once

// The recognizer in a child process: ecvpose-view starts `ecvpose recognize ... --out-json -` and reads its JSON lines.
// A process of its own because the recognizer renders with OSMesa and the viewer's window (OpenCV's Qt) links libGL:
// in one process every GL call of one of them would go to the other's library.

#include <sys/types.h>

#include <optional>
#include <string>
#include <vector>

namespace ecv::view {

/// A running `ecvpose recognize`: its standard output read line by line without blocking, its standard error passed
/// through to ours. Stopped (SIGTERM, then waited for) when destroyed.
class RecognizerChild {
 public:
  /// Starts `program` with `arguments` (not including the program's name). Throws std::runtime_error naming the
  /// program when it cannot be started.
  RecognizerChild(const std::string& program, const std::vector<std::string>& arguments);
  ~RecognizerChild();
  RecognizerChild(const RecognizerChild&) = delete;
  RecognizerChild& operator=(const RecognizerChild&) = delete;

  /// The next whole line of the child's standard output (without its newline), waiting at most `timeout_ms`
  /// milliseconds for it; nothing when none is complete by then or the output has ended.
  std::optional<std::string> NextLine(int timeout_ms);

  /// True once the child's standard output has ended and every line of it has been returned.
  bool Ended() const { return output_ended_ && buffer_.find('\n') == std::string::npos; }

  /// The child's exit code once it has exited (128 + signal when a signal ended it); nothing while it runs.
  std::optional<int> ExitCode();

 private:
  void ReadAvailable(int timeout_ms);

  pid_t pid_ = -1;
  int output_ = -1;  ///< read end of the pipe on the child's standard output
  bool output_ended_ = false;
  std::string buffer_;  ///< bytes read that do not make a whole line yet
  std::optional<int> exit_code_;
};

}  // namespace ecv::view
