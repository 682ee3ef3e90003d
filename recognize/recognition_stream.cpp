#include "recognize/recognition_stream.h"

#include <string>

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

RecognitionStream::RecognitionStream(Recognizer& recognizer, const StreamOptions& options)
    : recognizer_(recognizer), options_(Checked(options)), schedule_(options.search_every) {}

RecognitionResult RecognitionStream::Next(const RgbdFrame& frame) {
  const SearchScope scope = schedule_.Next();
  RecognitionResult result;
  try {
    result = options_.track ? recognizer_.Recognize(frame, previous_, scope) : recognizer_.Recognize(frame);
  } catch (...) {
    Reset();
    throw;
  }
  previous_ = result.detections;
  return result;
}

void RecognitionStream::Reset() {
  previous_.clear();
  schedule_.Reset();
}

}  // namespace ecv
