#include "io/frame_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/files.h"
#include "io/image_bytes.h"
#include "io/pose_io.h"
#include "io/read_roots.h"

namespace ecv {
namespace fs = std::filesystem;
namespace {

constexpr const char* kFrameForms =
    "a frame JSON, a YCB-Video prefix (.../0001/000001 with -color.png beside it), a BOP image "
    "SCENE_DIR:IMAGE_ID or an organized .pcd";

bool EndsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "SCENE_DIR:IMAGE_ID" with an existing directory and a decimal id.
bool SplitBopImage(const std::string& text, std::string* scene_dir, int* image_id) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos || colon + 1 >= text.size()) return false;
  const std::string id = text.substr(colon + 1);
  if (id.find_first_not_of("0123456789") != std::string::npos || id.size() > 9) return false;
  *scene_dir = text.substr(0, colon);
  *image_id = std::stoi(id);
  return IsDirectory(*scene_dir);
}

bool HasFlagForm(const FrameSpec& spec) {
  return !spec.color_path.empty() || !spec.depth_path.empty() || spec.depth_scale || spec.camera;
}

// The forms of a positional FRAME, told apart in this order.
enum class PositionalForm { kBopImage, kJson, kPcd, kYcbvPrefix, kNone };

PositionalForm FormOf(const std::string& path, std::string* scene_dir, int* image_id) {
  if (SplitBopImage(path, scene_dir, image_id)) return PositionalForm::kBopImage;
  if (EndsWith(path, ".json")) return PositionalForm::kJson;
  if (EndsWith(path, ".pcd")) return PositionalForm::kPcd;
  if (PathExists(path + "-color.png")) return PositionalForm::kYcbvPrefix;
  return PositionalForm::kNone;
}

LoadedFrame LoadPositional(const FrameSpec& spec) {
  const std::string& path = spec.positional;
  std::string scene_dir;
  int image_id = 0;
  const PositionalForm form = FormOf(path, &scene_dir, &image_id);
  if (form == PositionalForm::kBopImage) {
    if (!spec.color_path.empty() || spec.camera) {
      ThrowInputError(path, "--color/--camera", "no --color or --camera with a BOP image (only --depth)");
    }
    if (spec.depth_scale) CheckDepthScale(*spec.depth_scale, "--depth-scale");
    LoadedFrame loaded = LoadBopFrame(scene_dir, image_id, spec.depth_path);
    if (spec.depth_scale) {
      const std::string depth = BopFrameFiles(scene_dir, image_id, spec.depth_path).at(2);  // the depth image read
      loaded.rgbd.depth = ReadDepthImage(depth, *spec.depth_scale);
    }
    loaded.rgbd.Check();
    return loaded;
  }
  if (HasFlagForm(spec)) {
    ThrowInputError(path, "FRAME", "either a positional FRAME or --color/--depth/--depth-scale/--camera, not both");
  }
  if (form == PositionalForm::kJson) return LoadFrameJson(path);
  if (form == PositionalForm::kPcd) return LoadPcdFrame(path);
  if (form == PositionalForm::kYcbvPrefix) return LoadYcbvFrame(path);
  if (PathExists(path)) ThrowInputError(path, "FRAME", kFrameForms, "a file of none of these forms");
  ThrowInputError(path, "FRAME", kFrameForms, "no such file, YCB-Video prefix or BOP scene directory");
}

// The colour and depth files of a frame JSON, relative to it; empty for a key that is not a string.
std::string FrameJsonFile(const nlohmann::json& json, const std::string& path, const char* key) {
  if (!json.is_object() || !json.contains(key) || !json[key].is_string()) return "";
  return (fs::path(path).parent_path() / json[key].get<std::string>()).string();
}

// Image ids of a BOP scene whose colour (rgb/ PNG or JPG, or gray/) and depth/ PNG exist, in increasing order.
std::vector<std::string> ListBopSceneFrames(const fs::path& scene_dir) {
  const std::string camera_path = (scene_dir / "scene_camera.json").string();
  const nlohmann::json cameras = ReadJsonFile(camera_path);
  if (!cameras.is_object()) ThrowInputError(camera_path, "image ids", "an object keyed by image id");
  std::vector<int> ids;
  for (const auto& item : cameras.items()) {
    const std::string& key = item.key();
    if (key.empty() || key.size() > 9 || key.find_first_not_of("0123456789") != std::string::npos) {
      ThrowInputError(camera_path, key, "image ids as decimal keys");
    }
    ids.push_back(std::stoi(key));
  }
  std::sort(ids.begin(), ids.end());
  if (!IsDirectory(scene_dir / "depth")) {
    ThrowInputError((scene_dir / "depth").string(), "depth",
                    "a depth/ folder with the depth PNGs of the images of scene_camera.json",
                    "no such folder (a single image can be given as SCENE_DIR:ID with --depth)");
  }
  std::vector<std::string> frames;
  for (const int id : ids) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d", id);
    const std::string stem = name;
    bool has_color = false;
    for (const auto& [folder, extension] :
         {std::pair{"rgb", ".png"}, std::pair{"rgb", ".jpg"}, std::pair{"gray", ".png"}, std::pair{"gray", ".tif"}}) {
      has_color = has_color || PathExists(scene_dir / folder / (stem + extension));
    }
    if (has_color && PathExists(scene_dir / "depth" / (stem + ".png"))) {
      frames.push_back(scene_dir.string() + ":" + std::to_string(id));
    }
  }
  if (frames.empty()) {
    ThrowInputError(
        scene_dir.string(), "sequence",
        "an image of scene_camera.json with both rgb/ and depth/ files (" + std::to_string(ids.size()) + " ids listed)",
        "none");
  }
  return frames;
}

// YCB-Video prefixes (*-color.png) and frame JSONs of a directory, in name order.
std::vector<std::string> ListDirectoryFrames(const fs::path& directory) {
  std::vector<std::string> frames;
  std::error_code error;
  fs::directory_iterator entries(directory, error);
  if (error) ThrowInputError(directory.string(), "sequence", "a folder this user can list", error.message());
  for (const auto& entry : entries) {
    const std::string name = entry.path().string();
    const std::string suffix = "-color.png";
    if (EndsWith(name, suffix)) {
      frames.push_back(name.substr(0, name.size() - suffix.size()));
    } else if (entry.path().extension() == ".json") {
      frames.push_back(name);
    }
  }
  std::sort(frames.begin(), frames.end());
  return frames;
}

// One FRAME per line of a text file; '#' starts a comment.
std::vector<std::string> ListFileFrames(const std::string& path) {
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "sequence", "a directory of frames or a text file with one FRAME per line");
  std::vector<std::string> frames;
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    line.erase(0, line.find_first_not_of(" \t\r"));
    line.erase(line.find_last_not_of(" \t\r") + 1);
    if (!line.empty()) frames.push_back(line);
  }
  return frames;
}

}  // namespace

void CheckFrameFiles(const FrameSpec& spec, const std::function<void(const std::string&)>& check) {
  std::vector<std::string> files = {spec.color_path, spec.depth_path};
  const std::string& path = spec.positional;
  std::string scene_dir;
  int image_id = 0;
  switch (path.empty() ? PositionalForm::kNone : FormOf(path, &scene_dir, &image_id)) {
    case PositionalForm::kBopImage: {
      const std::vector<std::string> bop = BopFrameFiles(scene_dir, image_id, spec.depth_path);
      files.insert(files.end(), bop.begin(), bop.end());
      break;
    }
    case PositionalForm::kJson: {
      check(path);  // before it is parsed
      const nlohmann::json json = ReadJsonFile(path);
      files.push_back(FrameJsonFile(json, path, "color"));
      files.push_back(FrameJsonFile(json, path, "depth"));
      break;
    }
    case PositionalForm::kYcbvPrefix:
      for (const char* suffix : {"-meta.mat", "-color.png", "-depth.png"}) files.push_back(path + suffix);
      break;
    case PositionalForm::kPcd:
    case PositionalForm::kNone: files.push_back(path); break;
  }
  for (const std::string& file : files) {
    if (!file.empty()) check(file);
  }
}

std::vector<std::string> ListSequenceFrames(const std::string& dir_or_list) {
  if (!PathExists(dir_or_list)) {
    ThrowInputError(dir_or_list, "sequence", "a directory of frames or a text file with one FRAME per line",
                    "no such file or directory");
  }
  if (!IsDirectory(dir_or_list)) {
    std::vector<std::string> frames = ListFileFrames(dir_or_list);
    if (frames.empty()) ThrowInputError(dir_or_list, "sequence", "at least one FRAME line", "none");
    return frames;
  }
  fs::path directory(dir_or_list);
  if (!directory.has_filename()) directory = directory.parent_path();  // "dir/" -> "dir"
  if (PathExists(directory / "scene_camera.json")) return ListBopSceneFrames(directory);
  std::vector<std::string> frames = ListDirectoryFrames(directory);
  if (frames.empty()) {
    ThrowInputError(dir_or_list, "sequence",
                    "a BOP scene (scene_camera.json), YCB-Video frames (*-color.png) or frame JSONs (*.json)", "none");
  }
  return frames;
}

LoadedFrame LoadFrame(const FrameSpec& spec, std::vector<std::string>* warnings) {
  LoadedFrame loaded;
  std::string depth_source = spec.depth_path;
  if (!spec.positional.empty()) {
    loaded = LoadPositional(spec);
    if (depth_source.empty()) depth_source = spec.positional;
  } else {
    if (spec.color_path.empty() || spec.depth_path.empty() || !spec.depth_scale || !spec.camera) {
      ThrowInputError("frame", "--color/--depth/--depth-scale/--camera",
                      std::string("all four flags, or one positional FRAME: ") + kFrameForms);
    }
    // The flags' values are named by the flags, before an image is read.
    const std::array<double, 4> intrinsics = ParseIntrinsics(*spec.camera, "--camera");
    CheckDepthScale(*spec.depth_scale, "--depth-scale");
    CheckIntrinsics(intrinsics, "--camera", "fx,fy,cx,cy");
    loaded.rgbd = MakeFrame(spec.color_path, spec.depth_path, *spec.depth_scale, intrinsics, spec.color_path);
  }
  if (warnings != nullptr) {
    if (std::optional<std::string> warning = DepthRangeWarning(loaded.rgbd.depth, depth_source)) {
      warnings->push_back(std::move(*warning));
    }
  }
  return loaded;
}

std::optional<std::string> DepthRangeWarning(const cv::Mat& depth_m, const std::string& source) {
  constexpr double kNearest = 0.1, kFarthest = 10.0;  // metres: what RGB-D cameras measure
  const DepthStats stats = ComputeDepthStats(depth_m);
  if (stats.valid_fraction == 0.0) return std::nullopt;
  const double median = stats.median_m;
  if (median >= kNearest && median <= kFarthest) return std::nullopt;
  std::ostringstream text;
  text << source << ": median depth " << median << " m, outside " << kNearest << "-" << kFarthest
       << " m: is the depth scale right? (--depth-scale S = depth values per metre: YCB-Video 10000, millimetre PNGs "
          "1000)";
  return text.str();
}

cv::Mat ReadColorImage(const std::string& path) {
  return ColorImageAsRgb(ReadImageFile(path, "colour image"), path);
}

void WriteColorImage(const std::string& path, const cv::Mat& image) {
  CV_Assert(image.type() == CV_8UC3 || image.type() == CV_8UC1);
  cv::Mat converted;  // a new buffer: converting into a copy of the header would swap the caller's channels
  if (image.channels() == 3) {
    cv::cvtColor(image, converted, cv::COLOR_RGB2BGR);
  } else {
    converted = image;
  }
  bool written = false;
  try {
    written = cv::imwrite(path, converted);
  } catch (const cv::Exception& error) {
    ThrowInputError(path, "image", "a writable .png or .jpg path", error.what());
  }
  if (!written) ThrowInputError(path, "image", "a writable .png or .jpg path");
}

cv::Mat ReadDepthImage(const std::string& path, double depth_scale) {
  CheckDepthScale(depth_scale, path);
  return DepthImageAsMetres(ReadImageFile(path, "depth image"), depth_scale, path);
}

std::array<double, 4> ParseIntrinsics(const std::string& text, const std::string& source) {
  std::vector<double> values;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || item.find_first_not_of(" \t", used) != std::string::npos) {
      ThrowInputError(source, "camera", "four numbers fx,fy,cx,cy in pixels", "'" + text + "'");
    }
    values.push_back(value);
  }
  if (values.size() != 4) ThrowInputError(source, "camera", "four numbers fx,fy,cx,cy in pixels", "'" + text + "'");
  return {values[0], values[1], values[2], values[3]};
}

RgbdFrame MakeFrame(const std::string& color_path, const std::string& depth_path, double depth_scale,
                    const std::array<double, 4>& intrinsics, const std::string& source) {
  const cv::Mat color = ReadColorImage(color_path);  // first: its errors are said first
  const cv::Mat depth = ReadDepthImage(depth_path, depth_scale);
  return FrameOfImages(color, depth, intrinsics, color_path, depth_path, source);
}

int NumberOfName(const std::string& name) {
  if (name.empty() || name.size() > 9 || name.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(name);
}

LoadedFrame LoadFrameJson(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  auto string_field = [&](const char* key) {
    std::string file = FrameJsonFile(json, path, key);
    if (file.empty()) ThrowInputError(path, key, "a string (a path relative to the JSON)");
    return file;
  };
  if (!json.contains("depth_scale") || !json["depth_scale"].is_number()) {
    ThrowInputError(path, "depth_scale", "a number S (metres = depth value / S)");
  }
  if (!json.contains("camera") || !json["camera"].is_array() || json["camera"].size() != 4) {
    ThrowInputError(path, "camera", "an array [fx, fy, cx, cy] of 4 numbers in pixels");
  }
  std::array<double, 4> intrinsics{};
  for (size_t i = 0; i < 4; ++i) {
    const nlohmann::json& value = json["camera"][i];
    if (!value.is_number()) ThrowInputError(path, "camera", "an array [fx, fy, cx, cy] of 4 numbers in pixels");
    intrinsics[i] = value.get<double>();
  }
  // The values the JSON holds are its errors, before an image is read.
  const double depth_scale = json["depth_scale"].get<double>();
  CheckDepthScale(depth_scale, path);
  CheckIntrinsics(intrinsics, path, "camera");
  LoadedFrame loaded;
  loaded.rgbd = MakeFrame(string_field("color"), string_field("depth"), depth_scale, intrinsics, path);
  for (auto [key, id] : {std::pair{"scene_id", &loaded.scene_id}, std::pair{"image_id", &loaded.image_id}}) {
    if (!json.contains(key)) continue;
    if (!json[key].is_number_integer() || json[key].get<int64_t>() < 0 || json[key].get<int64_t>() > 999999999) {
      ThrowInputError(path, key, "a whole number >= 0 (the BOP id)", json[key].dump());
    }
    *id = json[key].get<int>();
  }
  if (loaded.image_id >= 0 && loaded.scene_id < 0) loaded.scene_id = 0;
  if (loaded.scene_id >= 0 && loaded.image_id < 0)
    ThrowInputError(path, "image_id", "a whole number >= 0 beside scene_id");
  return loaded;
}

void WriteFrameJson(const std::string& path, const RgbdFrame& frame, double depth_scale) {
  frame.Check();
  if (!(depth_scale > 0.0)) ThrowInputError(path, "depth_scale", "> 0");
  double deepest = 0.0;
  cv::minMaxLoc(frame.depth, nullptr, &deepest);
  if (deepest * depth_scale > 65535.0) {
    ThrowInputError(path, "depth_scale", "small enough for a 16-bit PNG: depth up to 65535 / S metres");
  }
  const fs::path json_path(path);
  const std::string stem = json_path.stem().string();
  const std::string color_name = stem + "-color.png", depth_name = stem + "-depth.png";
  const fs::path base = json_path.parent_path();
  WriteColorImage((base / color_name).string(), frame.color);
  cv::Mat depth_units;
  frame.depth.convertTo(depth_units, CV_16UC1, depth_scale);
  bool written = false;
  try {
    written = cv::imwrite((base / depth_name).string(), depth_units);
  } catch (const cv::Exception&) {
  }
  if (!written) ThrowInputError((base / depth_name).string(), "depth", "a writable PNG path");
  const PinholeCamera& camera = frame.camera;
  WriteJsonFile(path, {{"color", color_name},
                       {"depth", depth_name},
                       {"depth_scale", depth_scale},
                       {"camera", {camera.fx, camera.fy, camera.cx, camera.cy}}});
}

}  // namespace ecv
