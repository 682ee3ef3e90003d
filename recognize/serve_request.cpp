#include "recognize/serve_request.h"

#include <algorithm>
#include <set>
#include <sstream>
#include <utility>

#include "core/error.h"
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

// "depth_scale": a finite positive number, depth values per metre.
double DepthScale(const nlohmann::json& request) {
  if (!request.contains("depth_scale") || !request["depth_scale"].is_number()) {
    ThrowInputError(kSource, "depth_scale", "a number, depth units per metre");
  }
  const double depth_scale = request["depth_scale"].get<double>();
  CheckDepthScale(depth_scale, kSource);
  return depth_scale;
}

// "camera": [fx, fy, cx, cy], pixels.
std::array<double, 4> Camera(const nlohmann::json& request) {
  const nlohmann::json& camera = request.contains("camera") ? request["camera"] : nlohmann::json();
  if (!camera.is_array() || camera.size() != 4 ||
      !std::all_of(camera.begin(), camera.end(), [](const nlohmann::json& v) { return v.is_number(); })) {
    ThrowInputError(kSource, "camera", "[fx, fy, cx, cy] in pixels", camera.is_null() ? "" : camera.dump());
  }
  const std::array<double, 4> intrinsics = {camera[0].get<double>(), camera[1].get<double>(), camera[2].get<double>(),
                                            camera[3].get<double>()};
  CheckIntrinsics(intrinsics, kSource, "camera");
  return intrinsics;
}

// The frame's files: "frame", or "color", "depth", "depth_scale" and "camera".
FrameSpec FrameFiles(const nlohmann::json& request) {
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
  intrinsics.precision(17);  // read back exactly
  for (size_t i = 0; i < 4; ++i) intrinsics << (i > 0 ? "," : "") << camera[i];
  spec.camera = intrinsics.str();
  return spec;
}

// The frame's images: "color_png" and "depth_png", "depth_scale" and "camera"; the base64 text taken from `request`.
FrameBytes FrameImages(nlohmann::json& request) {
  for (const char* key : {"frame", "color", "depth"}) {
    if (request.contains(key)) ThrowInputError(kSource, key, "\"color_png\" and \"depth_png\" or paths, not both");
  }
  const auto text = [&](const char* key) {
    if (!request.contains(key) || !request[key].is_string()) {
      ThrowInputError(kSource, key, "base64 of a PNG file (beside \"color_png\" or \"depth_png\")");
    }
    return std::move(request[key].get_ref<std::string&>());
  };
  FrameBytes bytes;
  bytes.color_png = text("color_png");
  bytes.depth_png = text("depth_png");
  bytes.depth_scale = DepthScale(request);
  bytes.camera = Camera(request);
  return bytes;
}

bool Flag(const nlohmann::json& request, const char* key) {
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

std::string TooLongMessage(const RequestLimits& limits) {
  return std::string(kSource) + ": JSON: expected a line of at most " + std::to_string(limits.max_bytes) + " bytes";
}

void ParseRequest(const std::string& line, const RequestLimits& limits, ServeRequest* request) {
  *request = ServeRequest();
  if (line.size() > limits.max_bytes) throw InputError(TooLongMessage(limits));
  if (NestedDeeperThan(line, limits.max_depth)) {
    ThrowInputError(kSource, "JSON", "[ and { nested at most " + std::to_string(limits.max_depth) + " deep", "deeper");
  }
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception& error) {
    ThrowInputError(kSource, "JSON", "one JSON object per line", error.what());
  }
  if (!json.is_object())
    ThrowInputError(kSource, "JSON", "an object",
                    json.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).substr(0, 80));
  if (json.contains("id")) request->id = json["id"];
  static const std::set<std::string> kKeys = {"id",        "frame",       "color",  "depth", "color_png",
                                              "depth_png", "depth_scale", "camera", "track", "reset"};
  for (const auto& item : json.items()) {
    if (kKeys.count(item.key()) == 0) {
      ThrowInputError(kSource, item.key(),
                      "one of id, frame, color, depth, color_png, depth_png, depth_scale, camera, track, reset",
                      "an unknown key");
    }
  }
  if (json.contains("color_png") || json.contains("depth_png")) {
    request->in_memory = FrameImages(json);
  } else {
    request->frame = FrameFiles(json);
  }
  if (json.contains("track")) request->track = Flag(json, "track");
  if (json.contains("reset")) request->reset = Flag(json, "reset");
}

RgbdFrame DecodeFrameBytes(const FrameBytes& bytes) {
  const std::string color_source = std::string(kSource) + ": color_png";
  const std::string depth_source = std::string(kSource) + ": depth_png";
  const cv::Mat color = DecodeColorPng(DecodeBase64(bytes.color_png, kSource, "color_png"), color_source);
  const cv::Mat depth =
      DecodeDepthPng(DecodeBase64(bytes.depth_png, kSource, "depth_png"), bytes.depth_scale, depth_source);
  return FrameOfImages(color, depth, bytes.camera, color_source, depth_source, kSource);
}

nlohmann::json ErrorResponse(const nlohmann::json& id, const std::string& message) {
  return {{"id", id}, {"error", message}};
}

std::string ResponseLine(const nlohmann::json& response) {
  return response.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace ecv
