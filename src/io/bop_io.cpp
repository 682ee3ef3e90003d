// BOP scene images: SCENE_DIR/{scene_camera,scene_gt,scene_gt_info}.json, rgb/ (or gray/) and depth/
// images named by the 6-digit image id. Depth in millimetres times depth_scale; poses in millimetres.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "io/files.h"
#include "io/frame_io.h"
#include "io/image_bytes.h"
#include "io/pose_io.h"
#include "io/read_roots.h"

namespace ecv {
namespace fs = std::filesystem;
namespace {

std::string ImageFile(const std::string& scene_dir, const char* folder, int image_id, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d%s", image_id, extension);
  return (fs::path(scene_dir) / folder / name).string();
}

// The colour image of `image_id`: the first of rgb/ (PNG, JPG) and gray/ (PNG, TIFF) that exists; rgb/*.png, to be
// named in the error, when none does.
std::string ColorImageFile(const std::string& scene_dir, int image_id) {
  for (const auto& [folder, extension] :
       {std::pair{"rgb", ".png"}, std::pair{"rgb", ".jpg"}, std::pair{"gray", ".png"}, std::pair{"gray", ".tif"}}) {
    std::string path = ImageFile(scene_dir, folder, image_id, extension);
    if (PathExists(path)) return path;
  }
  return ImageFile(scene_dir, "rgb", image_id, ".png");
}

const nlohmann::json& ImageEntry(const nlohmann::json& json, const std::string& path, int image_id) {
  const std::string key = std::to_string(image_id);
  if (!json.is_object() || !json.contains(key)) ThrowInputError(path, key, "an entry for image " + key);
  return json[key];
}

std::vector<double> Numbers(const nlohmann::json& entry, const char* key, size_t count, const std::string& path) {
  if (!entry.contains(key) || !entry[key].is_array() || entry[key].size() != count) {
    ThrowInputError(path, key, "an array of " + std::to_string(count) + " numbers");
  }
  std::vector<double> values;
  for (const nlohmann::json& value : entry[key]) {
    if (!value.is_number()) ThrowInputError(path, key, "an array of " + std::to_string(count) + " numbers");
    values.push_back(value.get<double>());
  }
  return values;
}

// `entry[key]` as a number, `fallback` when absent; an InputError naming `path` and `key` when it is not a number.
double OptionalNumber(const nlohmann::json& entry, const char* key, double fallback, const std::string& path) {
  if (!entry.is_object() || !entry.contains(key)) return fallback;
  if (!entry[key].is_number()) ThrowInputError(path, key, "a number", entry[key].dump());
  return entry[key].get<double>();
}

cv::Rect Box(const nlohmann::json& entry, const char* key, const std::string& path) {
  const std::vector<double> box = Numbers(entry, key, 4, path);
  for (const double value : box) {
    if (!(std::abs(value) <= 1e6)) {  // also NaN; pixels of any real image
      ThrowInputError(path, key, "4 pixel numbers (x, y, width, height) within +-1e6", std::to_string(value));
    }
  }
  return {static_cast<int>(box[0]), static_cast<int>(box[1]), static_cast<int>(box[2]), static_cast<int>(box[3])};
}

}  // namespace

std::vector<GroundTruth> ReadBopGroundTruth(const std::string& scene_dir, int image_id) {
  const std::string gt_path = (fs::path(scene_dir) / "scene_gt.json").string();
  if (!PathExists(gt_path)) return {};
  const nlohmann::json gt_file = ReadJsonFile(gt_path);
  const nlohmann::json& objects = ImageEntry(gt_file, gt_path, image_id);
  if (!objects.is_array()) ThrowInputError(gt_path, std::to_string(image_id), "an array of objects");
  const std::string info_path = (fs::path(scene_dir) / "scene_gt_info.json").string();
  const nlohmann::json info =
      PathExists(info_path) ? ImageEntry(ReadJsonFile(info_path), info_path, image_id) : nlohmann::json::array();
  if (!info.empty() && info.size() != objects.size()) {
    ThrowInputError(info_path, std::to_string(image_id), std::to_string(objects.size()) + " entries as scene_gt.json");
  }

  std::vector<GroundTruth> truths;
  for (size_t i = 0; i < objects.size(); ++i) {
    const nlohmann::json& object = objects[i];
    const std::vector<double> r = Numbers(object, "cam_R_m2c", 9, gt_path);
    const std::vector<double> t = Numbers(object, "cam_t_m2c", 3, gt_path);
    if (!object.contains("obj_id") || !object["obj_id"].is_number_integer() || object["obj_id"].get<int64_t>() < 0 ||
        object["obj_id"].get<int64_t>() > 999999) {
      ThrowInputError(gt_path, "obj_id", "an integer object id from 0 to 999999");
    }
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) matrix(row, col) = r[static_cast<size_t>(3 * row + col)];
      matrix(row, 3) = t[static_cast<size_t>(row)] / 1000.0;  // mm -> m
    }
    GroundTruth truth;
    truth.object_id = object["obj_id"].get<int>();
    char name[32];
    std::snprintf(name, sizeof(name), "obj_%06d", truth.object_id);
    truth.object_name = name;
    truth.camera_from_object = RigidFromMatrix(matrix, gt_path, "cam_R_m2c");
    if (!info.empty()) {
      truth.visible_fraction = OptionalNumber(info[i], "visib_fract", -1.0, info_path);
      truth.object_box = Box(info[i], "bbox_obj", info_path);
      truth.visible_box = Box(info[i], "bbox_visib", info_path);
    }
    truths.push_back(truth);
  }
  return truths;
}

LoadedFrame LoadBopFrame(const std::string& scene_dir, int image_id, const std::string& depth_override) {
  const std::string camera_path = (fs::path(scene_dir) / "scene_camera.json").string();
  const nlohmann::json camera_file = ReadJsonFile(camera_path);
  const nlohmann::json& camera = ImageEntry(camera_file, camera_path, image_id);
  const std::vector<double> k = Numbers(camera, "cam_K", 9, camera_path);
  const double depth_scale_mm = OptionalNumber(camera, "depth_scale", 1.0, camera_path);  // mm = value * depth_scale
  // The scene camera's values are its errors, before an image is read.
  const std::string image = " (image " + std::to_string(image_id) + ")";
  if (!(std::isfinite(depth_scale_mm) && depth_scale_mm > 0.0 && std::isfinite(1000.0 / depth_scale_mm))) {
    std::ostringstream given;
    given << depth_scale_mm;
    ThrowInputError(camera_path, "depth_scale" + image,
                    "a finite positive scale (millimetres = depth value x depth_scale)", given.str());
  }
  const std::array<double, 4> intrinsics = {k[0], k[4], k[2], k[5]};
  CheckIntrinsics(intrinsics, camera_path, "cam_K" + image);

  const std::string color_path = ColorImageFile(scene_dir, image_id);
  const std::string depth_path =
      depth_override.empty() ? ImageFile(scene_dir, "depth", image_id, ".png") : depth_override;

  LoadedFrame loaded;
  loaded.rgbd = MakeFrame(color_path, depth_path, 1000.0 / depth_scale_mm, intrinsics,
                          scene_dir + ":" + std::to_string(image_id));
  loaded.ground_truth = ReadBopGroundTruth(scene_dir, image_id);
  fs::path folder = fs::path(scene_dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "…/000002/"
  loaded.scene_id = std::max(0, NumberOfName(folder.filename().string()));
  loaded.image_id = image_id;
  return loaded;
}

std::vector<std::string> BopFrameFiles(const std::string& scene_dir, int image_id, const std::string& depth_override) {
  const fs::path scene(scene_dir);
  std::vector<std::string> files = {
      (scene / "scene_camera.json").string(), ColorImageFile(scene_dir, image_id),
      depth_override.empty() ? ImageFile(scene_dir, "depth", image_id, ".png") : depth_override};
  for (const char* name : {"scene_gt.json", "scene_gt_info.json"}) {
    if (PathExists(scene / name)) files.push_back((scene / name).string());
  }
  return files;
}

}  // namespace ecv
