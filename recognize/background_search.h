#pragma once

// Full searches on a thread of their own, one frame at a time: the search that runs beside a stream's tracking
// (StreamOptions::search_beside).

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/frame.h"
#include "recognize/recognizer.h"

namespace ecv {

/// Makes the recognizer that searches beside the tracking. Called on the search thread, the one thread that then uses
/// the recognizer (and its GL context) and destroys it.
using RecognizerFactory = std::function<std::unique_ptr<Recognizer>()>;

/// A failure of the search thread (its recognizer could not be made, or a search threw), raised in the caller's
/// thread; the message names the frame and the failure.
class BackgroundSearchError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The detections of one finished search.
struct FinishedSearch {
  std::vector<Detection> detections;  ///< as Recognizer::Recognize(frame) gives them
  int64_t frame = 0;                  ///< the number the frame was offered with
  double search_ms = 0.0;             ///< the search's total time, milliseconds
};

/// A searching Recognizer on a thread of its own that searches the frames offered to it, one at a time. The thread
/// starts with the first offer and makes its recognizer then (about a second for a library of a few models). Its
/// methods are for one caller thread.
class BackgroundSearch {
 public:
  explicit BackgroundSearch(RecognizerFactory make_recognizer);
  /// Waits for a search in progress to end (it cannot be cut short), then joins the thread.
  ~BackgroundSearch();
  BackgroundSearch(const BackgroundSearch&) = delete;
  BackgroundSearch& operator=(const BackgroundSearch&) = delete;

  /// When the searcher is idle (no frame in hand, no failure to report), `frame` (copied) is searched next as number
  /// `number`; returns whether it was taken.
  bool Offer(const RgbdFrame& frame, int64_t number);

  /// The search finished since the last call, if any (the last one, if more). Throws BackgroundSearchError when the
  /// thread failed; it has then ended, and the next Offer starts a new one with a new recognizer.
  std::optional<FinishedSearch> TakeFinished();

  /// Forgets the frame in hand: a search in progress runs on, but its detections are dropped.
  void Forget();

 private:
  struct Job {
    RgbdFrame frame;
    int64_t number = 0;
    uint64_t generation = 0;
  };

  void Run();

  RecognizerFactory make_recognizer_;
  std::thread thread_;
  std::mutex mutex_;  // guards the members below
  std::condition_variable wake_;
  std::optional<Job> job_;  // offered, not yet taken by the thread
  bool searching_ = false;  // the thread holds a job
  bool stop_ = false;
  uint64_t generation_ = 0;  // raised by Forget: a job of an earlier one is dropped when it ends
  std::optional<FinishedSearch> finished_;
  std::optional<std::string> failure_;  // the thread's failure, its message; the thread has ended
};

}  // namespace ecv
