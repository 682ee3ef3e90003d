#include "recognize/recognition_service.h"

#include <algorithm>
#include <array>
#include <set>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/image_bytes.h"

namespace ecv {
namespace {

constexpr const char* kSource = "request";
// A bound on RequestLimits::max_depth, far below the nesting that exhausts the stack.
constexpr int kDeepestLimit = 1000;

// Whether [ and { nest deeper than `max_depth` in `line`, strings aside: a scan, so that a deep line is refused
// before anything recurses over it.
bool NestedDeeperThan(const std::string& line, int max_depth) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (const char c : line) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > max_depth) return true;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return false;
}

std::string TooLongMessage(size_t max_bytes) {
  return std::string(kSource) + ": JSON: expected a line of at most " + std::to_string(max_bytes) + " bytes";
}

StreamOptions Tracking(StreamOptions stream) {
  stream.track = true;
  return stream;
}

double DepthScale(const nlohmann::json& request) {
  if (!request.contains("depth_scale") || !request["depth_scale"].is_number()) {
    ThrowInputError(kSource, "depth_scale", "a number, depth units per metre");
  }
  return request["depth_scale"].get<double>();
}

std::array<double, 4> Camera(const nlohmann::json& request) {
  const nlohmann::json& camera = request.contains("camera") ? request["camera"] : nlohmann::json();
  if (!camera.is_array() || camera.size() != 4 ||
      !std::all_of(camera.begin(), camera.end(), [](const nlohmann::json& v) { return v.is_number(); })) {
    ThrowInputError(kSource, "camera", "[fx, fy, cx, cy] in pixels", camera.is_null() ? "" : camera.dump());
  }
  return {camera[0].get<double>(), camera[1].get<double>(), camera[2].get<double>(), camera[3].get<double>()};
}

// Whether a request carries its frame's images instead of naming files.
bool InMemory(const nlohmann::json& request) {
  return request.contains("color_png") || request.contains("depth_png");
}

// The frame a request names, as FrameSpec; InputError naming the key when it is missing or malformed.
FrameSpec RequestedFrame(const nlohmann::json& request) {
  FrameSpec spec;
  if (request.contains("frame")) {
    for (const char* key : {"color", "depth", "depth_scale", "camera"}) {
      if (request.contains(key)) ThrowInputError(kSource, key, "\"frame\" or the four frame keys, not both");
    }
    if (!request["frame"].is_string()) ThrowInputError(kSource, "frame", "a FRAME string", request["frame"].dump());
    spec.positional = request["frame"].get<std::string>();
    return spec;
  }
  const auto text = [&](const char* key) {
    if (!request.contains(key) || !request[key].is_string()) {
      ThrowInputError(kSource, key, "a path string (or \"frame\": FRAME instead of the frame keys)");
    }
    return request[key].get<std::string>();
  };
  spec.color_path = text("color");
  spec.depth_path = text("depth");
  spec.depth_scale = DepthScale(request);
  const std::array<double, 4> camera = Camera(request);
  std::ostringstream intrinsics;
  intrinsics.precision(17);
  for (size_t i = 0; i < 4; ++i) intrinsics << (i > 0 ? "," : "") << camera[i];
  spec.camera = intrinsics.str();
  return spec;
}

// The frame a request carries: "color_png" and "depth_png" (base64 of PNG files), "depth_scale" and "camera".
RgbdFrame FrameInMemory(const nlohmann::json& request) {
  for (const char* key : {"frame", "color", "depth"}) {
    if (request.contains(key)) ThrowInputError(kSource, key, "\"color_png\" and \"depth_png\" or paths, not both");
  }
  const auto bytes = [&](const char* key) {
    if (!request.contains(key) || !request[key].is_string()) {
      ThrowInputError(kSource, key, "base64 of a PNG file (beside \"color_png\" or \"depth_png\")");
    }
    return DecodeBase64(request[key].get_ref<const std::string&>(), kSource, key);
  };
  const std::string color_source = std::string(kSource) + ": color_png";
  const std::string depth_source = std::string(kSource) + ": depth_png";
  const cv::Mat color = DecodeColorPng(bytes("color_png"), color_source);
  const double depth_scale = DepthScale(request);
  const cv::Mat depth = DecodeDepthPng(bytes("depth_png"), depth_scale, depth_source);
  return FrameOfImages(color, depth, Camera(request), color_source, depth_source, kSource);
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

bool Flag(const nlohmann::json& request, const char* key, bool otherwise) {
  if (!request.contains(key)) return otherwise;
  if (!request[key].is_boolean()) ThrowInputError(kSource, key, "true or false", request[key].dump());
  return request[key].get<bool>();
}

}  // namespace

void RequestLimits::Check() const {
  if (max_bytes < 1) ThrowInputError("request limits", "max_bytes", "at least 1", std::to_string(max_bytes));
  if (max_depth < 1 || max_depth > kDeepestLimit) {
    ThrowInputError("request limits", "max_depth", "1 to " + std::to_string(kDeepestLimit), std::to_string(max_depth));
  }
}

RecognitionService::RecognitionService(Recognizer& recognizer, const StreamOptions& stream, const RequestLimits& limits,
                                       ReadRoots roots)
    : recognizer_(recognizer),
      track_by_default_(stream.track),
      limits_(limits),
      roots_(std::move(roots)),
      stream_(recognizer, Tracking(stream)) {
  limits_.Check();
}

nlohmann::json RecognitionService::Handle(const std::string& line) {
  nlohmann::json request;
  nlohmann::json id;
  try {
    if (line.size() > limits_.max_bytes) return {{"id", nullptr}, {"error", TooLongMessage(limits_.max_bytes)}};
    if (NestedDeeperThan(line, limits_.max_depth)) {
      ThrowInputError(kSource, "JSON", "[ and { nested at most " + std::to_string(limits_.max_depth) + " deep",
                      "deeper");
    }
    try {
      request = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& error) {
      ThrowInputError(kSource, "JSON", "one JSON object per line", error.what());
    }
    if (!request.is_object()) ThrowInputError(kSource, "JSON", "an object", request.dump().substr(0, 80));
    if (request.contains("id")) id = request["id"];
    return Respond(request);
  } catch (const InputError& error) {
    return {{"id", id}, {"error", error.what()}};
  }
}

std::string RecognitionService::Answer(const std::string& line) {
  return Handle(line).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string RecognitionService::AnswerTooLong() const {
  return nlohmann::json{{"id", nullptr}, {"error", TooLongMessage(limits_.max_bytes)}}.dump();
}

nlohmann::json RecognitionService::Respond(const nlohmann::json& request) {
  static const std::set<std::string> kKeys = {"id",        "frame",       "color",  "depth", "color_png",
                                              "depth_png", "depth_scale", "camera", "track", "reset"};
  for (const auto& [key, value] : request.items()) {
    if (kKeys.count(key) == 0) {
      ThrowInputError(kSource, key,
                      "one of id, frame, color, depth, color_png, depth_png, depth_scale, camera, track, reset",
                      "an unknown key");
    }
  }
  const bool in_memory = InMemory(request);
  const FrameSpec spec = in_memory ? FrameSpec() : RequestedFrame(request);
  const bool track = Flag(request, "track", track_by_default_);
  if (Flag(request, "reset", false)) stream_.Reset();
  LoadedFrame frame;
  try {
    if (in_memory) {
      frame.rgbd = FrameInMemory(request);
    } else {
      CheckReadable(spec, roots_);
      frame = LoadFrame(spec);
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
  response["frame"] = in_memory                 ? nlohmann::json()
                      : spec.positional.empty() ? nlohmann::json(spec.color_path)
                                                : nlohmann::json(spec.positional);
  response["id"] = request.contains("id") ? request["id"] : nlohmann::json();
  return response;
}

}  // namespace ecv
