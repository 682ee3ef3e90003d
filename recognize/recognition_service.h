#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"

namespace ecv {

/// The requests of `ecvpose serve`, one JSON object per line, and their responses: the rules of the protocol without
/// its input and output, so that they are tested alone.
///
/// A request names a frame, `{"frame": FRAME}` (what `recognize` takes) or `{"color": PATH, "depth": PATH,
/// "depth_scale": S, "camera": [fx, fy, cx, cy]}`, with optional `"id"` (any JSON value, echoed), `"track"` (follow
/// the objects of the previous tracked request; default: the service's) and `"reset": true` (forget the tracks
/// first). The response is the detections as `recognize --out-json` writes them, with `"id"` and `"frame"`, or
/// `{"id": ..., "error": MESSAGE}` for a request that is malformed or whose frame cannot be read.
class RecognitionService {
 public:
  /// `recognizer` must outlive the service. `stream`: whether requests track by default, and the search schedule
  /// of tracked requests.
  RecognitionService(Recognizer& recognizer, const StreamOptions& stream);

  /// The response to one request line.
  nlohmann::json Handle(const std::string& line);

  /// Forgets the tracks: a new client.
  void Reset() { stream_.Reset(); }

 private:
  nlohmann::json Respond(const nlohmann::json& request);

  Recognizer& recognizer_;
  bool track_by_default_;
  RecognitionStream stream_;  // of the tracked requests
};

}  // namespace ecv
