#include "recognize/recognition_stream.h"

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "core/error.h"

namespace ecv {
namespace {

const StreamOptions& Checked(const StreamOptions& options) {
  options.Check();
  return options;
}

}  // namespace

void StreamOptions::Check() const {
  if (search_every < 1) ThrowInputError("stream options", "search_every", "at least 1", std::to_string(search_every));
  if (search_every > 1 && !track) ThrowInputError("stream options", "search_every", "tracking as well (track)");
  if (search_beside && !track) ThrowInputError("stream options", "search_beside", "tracking as well (track)");
}

StreamRecognizerOptions ShareThreads(const RecognizerOptions& options, const StreamOptions& stream) {
  StreamRecognizerOptions shared{options, options};
  if (stream.search_beside) {
    const int threads = options.threads;
    shared.track.threads = std::max(1, threads - threads / 2);
    shared.search.threads = std::max(1, threads / 2);
  }
  return shared;
}

RecognizerFactory MakeRecognizerFactory(const ModelLibrary& library, const RecognizerOptions& options) {
  return [&library, options] { return std::make_unique<Recognizer>(library, options); };
}

SearchSchedule::SearchSchedule(int search_every) : search_every_(search_every) {
  if (search_every < 1) ThrowInputError("search schedule", "search_every", "at least 1", std::to_string(search_every));
}

SearchScope SearchSchedule::Next() {
  if (since_full_search_ < 0 || since_full_search_ + 1 >= search_every_) {
    since_full_search_ = 0;
    return SearchScope::kAllModels;
  }
  ++since_full_search_;
  return SearchScope::kLostTracks;
}

RecognitionStream::RecognitionStream(Recognizer& recognizer, const StreamOptions& options,
                                     RecognizerFactory make_searcher)
    : recognizer_(recognizer), options_(Checked(options)), schedule_(options.search_every) {
  if (options_.search_beside) {
    if (!make_searcher) ThrowInputError("stream options", "search_beside", "a factory of the searching recognizer");
    search_ = std::make_unique<BackgroundSearch>(std::move(make_searcher));
  }
}

RecognitionStream::~RecognitionStream() = default;
RecognitionStream::RecognitionStream(RecognitionStream&&) noexcept = default;

RecognitionResult RecognitionStream::Next(const RgbdFrame& frame) {
  RecognitionResult result;
  try {
    if (search_) {
      result = NextBeside(frame);
    } else {
      const SearchScope scope = schedule_.Next();
      result = options_.track ? recognizer_.Recognize(frame, previous_, scope) : recognizer_.Recognize(frame);
    }
  } catch (...) {
    Reset();
    throw;
  }
  ++frames_;
  previous_ = result.detections;
  return result;
}

// The finished search's detections join the previous frame's as priors, counted as followed since the searched frame;
// the searcher, if idle, takes this frame before it is tracked.
RecognitionResult RecognitionStream::NextBeside(const RgbdFrame& frame) {
  frame.Check();  // a broken frame is not handed to the searcher
  std::vector<Detection> priors = previous_;
  int searched_frames_ago = -1;
  if (std::optional<FinishedSearch> finished = search_->TakeFinished()) {
    searched_frames_ago = static_cast<int>(frames_ - finished->frame);
    for (Detection& detection : finished->detections) {
      detection.frames_followed = searched_frames_ago - 1;  // Track counts this frame
      priors.push_back(std::move(detection));
    }
  }
  if (frames_ >= next_search_ && search_->Offer(frame, frames_)) next_search_ = frames_ + options_.search_every;
  RecognitionResult result = recognizer_.Recognize(frame, priors, SearchScope::kPriorsOnly);
  result.searched_frames_ago = searched_frames_ago;
  return result;
}

void RecognitionStream::Reset() {
  previous_.clear();
  schedule_.Reset();
  if (search_) search_->Forget();
  next_search_ = 0;
}

}  // namespace ecv
