#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "core/frame.h"
#include "modeldb/model_library.h"
#include "recognize/background_search.h"
#include "recognize/recognizer.h"

namespace ecv {

/// How a stream of frames is recognised.
struct StreamOptions {
  /// Follow objects between frames: each detection of the previous frame is first tried at its pose (refined and
  /// verified); objects tracked so skip view ranking and RANSAC (Recognizer::Recognize with priors).
  bool track = false;
  /// With `track`: models not tracked are searched for in every search_every-th frame only (the first of the stream,
  /// then every N-th after it); in between, tracked objects are followed and a lost one is searched for at once
  /// (SearchScope::kLostTracks). 1: every frame is a full search.
  int search_every = 1;
  /// With `track`: the search runs beside the tracking. Each frame only follows the previous frame's detections
  /// (SearchScope::kPriorsOnly) and returns; a second recognizer searches every model on a thread of its own, handed a
  /// copy of the current frame whenever it is idle (and at most every search_every-th frame), and its detections join
  /// the priors of the frame after it finishes: tracked from the searched pose into that frame, they compete with the
  /// tracks on score and confirm those they find on the same surface. New objects are found a search's time late.
  bool search_beside = false;

  /// Throws InputError on values outside their ranges (search_every > 1 or search_beside without track).
  void Check() const;
};

/// The options of a stream's tracking recognizer and of its searching one: `options` for both; with search_beside,
/// their worker threads (RansacOptions::threads) shared out: the tracker the larger half, the searcher the rest, each
/// at least one (on 2, one thread tracks and one searches; on 1, the two take turns on it).
struct StreamRecognizerOptions {
  RecognizerOptions track;
  RecognizerOptions search;
};
StreamRecognizerOptions ShareThreads(const RecognizerOptions& options, const StreamOptions& stream);

/// A factory of recognizers over `library` (which must outlive them) with `options`.
RecognizerFactory MakeRecognizerFactory(const ModelLibrary& library, const RecognizerOptions& options);

/// Which frames of a stream search every model: the first, then every search_every-th after it, and the first after
/// a Reset.
class SearchSchedule {
 public:
  explicit SearchSchedule(int search_every = 1);
  /// The scope of the next frame (and that frame counted).
  SearchScope Next();
  /// The next frame searches every model, and the count starts again from it.
  void Reset() { since_full_search_ = -1; }

 private:
  int search_every_;
  int since_full_search_ = -1;  // frames since the last full search; -1: none yet
};

/// The streaming rules, one place for every caller (the CLI's --sequence, the benchmarks, later a service and
/// Python): which frame searches which models, and the detections carried from one frame to the next.
class RecognitionStream {
 public:
  /// `recognizer` must outlive the stream; it is used in the caller's thread only. With options.search_beside,
  /// `make_searcher` makes the searching recognizer (InputError without it), on the search thread, which starts with
  /// the first frame; give the two recognizers ShareThreads of the threads.
  RecognitionStream(Recognizer& recognizer, const StreamOptions& options, RecognizerFactory make_searcher = {});
  /// Waits for a search in progress beside the tracking to end, then joins its thread.
  ~RecognitionStream();
  RecognitionStream(RecognitionStream&&) noexcept;
  RecognitionStream& operator=(RecognitionStream&&) = delete;

  /// Recognises the stream's next frame. When it throws (a broken frame; a failure of the search beside the tracking,
  /// as BackgroundSearchError), the stream starts again: see Reset.
  RecognitionResult Next(const RgbdFrame& frame);

  /// Forgets the previous frame's detections and starts the search schedule again: the next frame searches every
  /// model (with search_beside: the frame in the searcher's hand is dropped, its search's detections with it, and the
  /// next frame is handed to the searcher once it is idle). For a new video, or after a frame that could not be read.
  void Reset();

  /// The last frame's detections: the priors of the next frame when tracking.
  const std::vector<Detection>& previous() const { return previous_; }

 private:
  RecognitionResult NextBeside(const RgbdFrame& frame);

  Recognizer& recognizer_;
  StreamOptions options_;
  SearchSchedule schedule_;
  std::vector<Detection> previous_;
  std::unique_ptr<BackgroundSearch> search_;  // with search_beside
  int64_t frames_ = 0;                        // frames given to Next
  int64_t next_search_ = 0;                   // with search_beside: the first frame that may be handed to the searcher
};

}  // namespace ecv
