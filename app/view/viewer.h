#pragma once

// The window of ecvpose-view: each frame of the recognizer in the child process as it comes, keys to pause, step,
// save and quit.

#include <csignal>
#include <string>

#include "app/view/recognizer_child.h"

namespace ecv::view {

struct ViewerOptions {
  std::string window = "ecvpose-view";  ///< the window's title
  std::string save_dir = ".";           ///< where `s` saves the shown picture
  bool exit_at_end = false;             ///< close when the sequence ends instead of keeping its last frame shown
};

/// Shows the frames of `child` (`ecvpose recognize --sequence ... --out-json - --overlay DIR`; each picture removed
/// once read) until the user quits (q, Esc, closing the window), `stop` becomes non-zero (a signal) or, with
/// exit_at_end, the sequence ends. Keys: space pauses and resumes, n or the right arrow shows one more frame while
/// paused, s saves the picture. Returns the exit code: the recognizer's when it failed, else 0.
int RunViewer(RecognizerChild& child, const ViewerOptions& options, const volatile std::sig_atomic_t& stop);

}  // namespace ecv::view
