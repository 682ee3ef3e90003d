#pragma once

// One request line of `ecvpose serve`, parsed into what it asks without reading any file: the part of the protocol a
// client's bytes reach first, as pure functions for the tests and the fuzzer (fuzz/fuzz_serve_request.cpp).

#include <array>
#include <cstddef>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/frame.h"
#include "io/frame_io.h"

namespace ecv {

/// Bounds on one request line, checked before it is parsed: a line past them gets an error answer.
struct RequestLimits {
  size_t max_bytes = size_t{64} << 20;  ///< bytes of one line (64 MiB: room for a frame's images in base64)
  int max_depth = 64;                   ///< nesting of [ and { (the serialiser recurses once per level)

  /// Throws InputError for a bound < 1 or a depth past what the stack holds.
  void Check() const;
};

/// A frame's images carried in a request: "color_png" and "depth_png", "depth_scale" and "camera".
struct FrameBytes {
  std::string color_png;              ///< base64 of a colour PNG file, as the request holds it
  std::string depth_png;              ///< base64 of a 16-bit one-channel depth PNG file
  double depth_scale = 0.0;           ///< depth values per metre, finite and positive
  std::array<double, 4> camera = {};  ///< fx, fy, cx, cy in pixels
};

/// What one request asks (the keys of docs/serve.md).
struct ServeRequest {
  nlohmann::json id;                    ///< "id", echoed in the response; null when absent
  FrameSpec frame;                      ///< the frame's files ("frame", or the four frame keys); empty when in memory
  std::optional<FrameBytes> in_memory;  ///< the frame's images, when the request carries them
  std::optional<bool> track;            ///< "track"; absent: the service's default
  bool reset = false;                   ///< "reset": forget the tracks first
};

/// Parses one request line: at most `limits.max_bytes`, [ and { nested at most `limits.max_depth` deep (both checked
/// before the JSON parser sees the line), one JSON object of known keys, each of its type. `request->id` is set as
/// soon as it is read, so that the error of a later key can echo it. Throws InputError "request: <key>: expected ...".
void ParseRequest(const std::string& line, const RequestLimits& limits, ServeRequest* request);

/// The frame of a request's images: base64 and PNG checked, the PNG headers' size first (io/image_bytes.h); InputError
/// naming the key ("request: depth_png: ...").
RgbdFrame DecodeFrameBytes(const FrameBytes& bytes);

/// The error answer to a request: {"id": id, "error": message}.
nlohmann::json ErrorResponse(const nlohmann::json& id, const std::string& message);

/// The error message of a line longer than `limits.max_bytes`.
std::string TooLongMessage(const RequestLimits& limits);

/// `response` as one line of text without its newline, always valid UTF-8 (bytes of a request that are not, echoed in
/// a message, become U+FFFD).
std::string ResponseLine(const nlohmann::json& response);

}  // namespace ecv
