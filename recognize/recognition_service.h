#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "io/read_roots.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"
#include "recognize/serve_request.h"

namespace ecv {

/// The requests of `ecvpose serve`, one JSON object per line, and their responses: the rules of the protocol without
/// its input and output, so that they are tested alone (ParseRequest reads a line, recognize/serve_request.h).
///
/// A request names a frame, `{"frame": FRAME}` (what `recognize` takes) or `{"color": PATH, "depth": PATH,
/// "depth_scale": S, "camera": [fx, fy, cx, cy]}`, with optional `"id"` (any JSON value, echoed), `"track"` (follow
/// the objects of the previous tracked request; default: the service's) and `"reset": true` (forget the tracks
/// first). The response is the detections as `recognize --out-json` writes them, with `"id"` and `"frame"`, or
/// `{"id": ..., "error": MESSAGE}` for a request that is malformed, past `limits` or whose frame cannot be read. Every
/// file a frame names is checked against `roots` before anything reads it; a refused one gets the one message
/// "frame: not readable here: PATH", PATH as the request gives it, whatever the reason.
class RecognitionService {
 public:
  /// `recognizer` must outlive the service. `stream`: whether requests track by default, and the search schedule
  /// of tracked requests. `roots`: where frames may be read (default: anywhere, FIFOs, devices and folders aside).
  /// With stream.search_beside, `make_searcher` makes the recognizer that searches beside the tracked requests (on a
  /// thread of the service's own, from its first tracked request); a failure of that thread is the error response
  /// of the next tracked request, and the tracks start again.
  RecognitionService(Recognizer& recognizer, const StreamOptions& stream, const RequestLimits& limits = {},
                     ReadRoots roots = {}, RecognizerFactory make_searcher = {});

  /// The response to one request line.
  nlohmann::json Handle(const std::string& line);

  /// The response line to one request line: Handle's JSON as text, without a newline, always valid UTF-8 (bytes of
  /// the request that are not, echoed in a message, become U+FFFD).
  std::string Answer(const std::string& line);

  /// The response line to a request line longer than limits().max_bytes, which the caller did not keep.
  std::string AnswerTooLong() const;

  const RequestLimits& limits() const { return limits_; }

  /// Forgets the tracks: a new client.
  void Reset() { stream_.Reset(); }

 private:
  nlohmann::json Respond(const ServeRequest& request);

  Recognizer& recognizer_;
  bool track_by_default_;
  RequestLimits limits_;
  ReadRoots roots_;
  RecognitionStream stream_;  // of the tracked requests
};

}  // namespace ecv
