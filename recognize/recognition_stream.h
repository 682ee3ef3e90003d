#pragma once

#include <vector>

#include "core/frame.h"
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

  /// Throws InputError on values outside their ranges (search_every > 1 without track).
  void Check() const;
};

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
  /// `recognizer` must outlive the stream.
  RecognitionStream(Recognizer& recognizer, const StreamOptions& options);

  /// Recognises the stream's next frame. When it throws (a broken frame), the stream starts again: see Reset.
  RecognitionResult Next(const RgbdFrame& frame);

  /// Forgets the previous frame's detections and starts the search schedule again: the next frame searches every
  /// model. For a new video, or after a frame that could not be read.
  void Reset();

  /// The last frame's detections: the priors of the next frame when tracking.
  const std::vector<Detection>& previous() const { return previous_; }

 private:
  Recognizer& recognizer_;
  StreamOptions options_;
  SearchSchedule schedule_;
  std::vector<Detection> previous_;
};

}  // namespace ecv
