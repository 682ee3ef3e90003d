#include "recognize/recognition_service.h"

#include <new>
#include <utility>

#include "core/error.h"
#include "io/frame_io.h"
#include "recognize/recognition_json.h"

namespace ecv {
namespace {

StreamOptions Tracking(StreamOptions stream) {
  stream.track = true;
  return stream;
}

// Throws "frame: not readable here: PATH" for the first file `spec` would read that `roots` refuses, PATH as the
// request names it: one message whether the file is missing, outside the roots or no regular file, and never its text.
void CheckReadable(const FrameSpec& spec, const ReadRoots& roots) {
  const auto refuse_as = [&roots](const std::string& named) {
    return [&roots, named](const std::string& file) {
      if (!roots.Allows(file)) throw InputError("frame: not readable here: " + named);
    };
  };
  if (!spec.positional.empty()) {
    CheckFrameFiles(spec, refuse_as(spec.positional));
  } else {
    refuse_as(spec.color_path)(spec.color_path);
    refuse_as(spec.depth_path)(spec.depth_path);
  }
}

}  // namespace

RecognitionService::RecognitionService(Recognizer& recognizer, const StreamOptions& stream, const RequestLimits& limits,
                                       ReadRoots roots, RecognizerFactory make_searcher)
    : recognizer_(recognizer),
      track_by_default_(stream.track),
      limits_(limits),
      roots_(std::move(roots)),
      stream_(recognizer, Tracking(stream), std::move(make_searcher)) {
  limits_.Check();
}

nlohmann::json RecognitionService::Handle(const std::string& line) {
  ServeRequest request;
  try {
    ParseRequest(line, limits_, &request);
    return Respond(request);
  } catch (const InputError& error) {
    return ErrorResponse(request.id, error.what());
  } catch (const BackgroundSearchError& error) {  // the stream has started again
    return ErrorResponse(request.id, error.what());
  } catch (const std::bad_alloc&) {  // the request's, not the service's: the next one is answered
    stream_.Reset();
    return ErrorResponse(request.id,
                         "request: memory: expected a frame that fits in the memory left, got out of memory");
  }
}

std::string RecognitionService::Answer(const std::string& line) {
  return ResponseLine(Handle(line));
}

std::string RecognitionService::AnswerTooLong() const {
  return ResponseLine(ErrorResponse(nullptr, TooLongMessage(limits_)));
}

nlohmann::json RecognitionService::Respond(const ServeRequest& request) {
  const bool track = request.track.value_or(track_by_default_);
  if (request.reset) stream_.Reset();
  LoadedFrame frame;
  try {
    if (request.in_memory) {
      frame.rgbd = DecodeFrameBytes(*request.in_memory);
    } else {
      CheckReadable(request.frame, roots_);
      frame = LoadFrame(request.frame);
    }
  } catch (const InputError&) {
    stream_.Reset();  // as a broken frame of a sequence: the next tracked frame searches every model
    throw;
  }
  RecognitionResult result;
  if (track) {
    result = stream_.Next(frame.rgbd);
  } else {
    stream_.Reset();  // a frame on its own: the tracks no longer describe the scene
    result = recognizer_.Recognize(frame.rgbd);
  }
  nlohmann::json response = RecognitionToJson(result);
  const FrameSpec& spec = request.frame;
  response["frame"] = request.in_memory         ? nlohmann::json()
                      : spec.positional.empty() ? nlohmann::json(spec.color_path)
                                                : nlohmann::json(spec.positional);
  response["id"] = request.id;
  return response;
}

}  // namespace ecv
