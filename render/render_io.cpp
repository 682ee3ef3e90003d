#include "render/render_io.h"

#include <cmath>
#include <filesystem>
#include <utility>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "render/view_sampling.h"

namespace ecv {
namespace fs = std::filesystem;
namespace {

void WritePng(const fs::path& path, const cv::Mat& image) {
  bool written = false;
  try {
    written = cv::imwrite(path.string(), image);
  } catch (const cv::Exception& error) {
    ThrowInputError(path.string(), "file", "a writable image path (.png)", error.what());
  }
  if (!written) ThrowInputError(path.string(), "file", "a writable image path (.png)");
}

// Depth in metres to 16-bit PNG values; counts values that do not fit (written as 0).
cv::Mat EncodeDepth(const cv::Mat& depth_m, int* out_of_range) {
  cv::Mat encoded(depth_m.size(), CV_16UC1);
  for (int v = 0; v < depth_m.rows; ++v) {
    for (int u = 0; u < depth_m.cols; ++u) {
      const double value = std::round(depth_m.at<float>(v, u) * kRenderedDepthScale);
      const bool fits = value <= 65535.0;
      if (!fits) ++*out_of_range;
      encoded.at<uint16_t>(v, u) = fits && value > 0.0 ? static_cast<uint16_t>(value) : 0;
    }
  }
  return encoded;
}

double Number(const nlohmann::json& object, const std::string& key, const std::string& source, double fallback) {
  if (!object.contains(key)) return fallback;
  if (!object[key].is_number()) ThrowInputError(source, key, "a number", object[key].dump());
  return object[key].get<double>();
}

Eigen::Vector3d Vector3(const nlohmann::json& object, const std::string& key, const std::string& source,
                        const Eigen::Vector3d& fallback) {
  if (!object.contains(key)) return fallback;
  const nlohmann::json& value = object[key];
  if (!value.is_array() || value.size() != 3 || !value[0].is_number() || !value[1].is_number() ||
      !value[2].is_number()) {
    ThrowInputError(source, key, "an array [x, y, z] of 3 numbers", value.dump());
  }
  return {value[0].get<double>(), value[1].get<double>(), value[2].get<double>()};
}

PinholeCamera ReadCamera(const nlohmann::json& json, const std::string& source) {
  const nlohmann::json& k = json.contains("camera") ? json["camera"] : nlohmann::json();
  if (!k.is_array() || k.size() != 4 || !k[0].is_number() || !k[1].is_number() || !k[2].is_number() ||
      !k[3].is_number()) {
    ThrowInputError(source, "camera", "an array [fx, fy, cx, cy] of 4 numbers in pixels");
  }
  for (const char* key : {"width", "height"}) {
    if (!json.contains(key) || !json[key].is_number_integer())
      ThrowInputError(source, key, "an integer number of pixels");
  }
  PinholeCamera camera{k[0].get<double>(), k[1].get<double>(),       k[2].get<double>(),
                       k[3].get<double>(), json["width"].get<int>(), json["height"].get<int>()};
  camera.Check(source);
  return camera;
}

SceneFileObject ReadSceneObject(const nlohmann::json& item, const std::string& source, const fs::path& base,
                                bool camera_frame) {
  if (!item.is_object() || !item.contains("mesh") || !item["mesh"].is_string()) {
    ThrowInputError(source, "mesh", "a mesh path (relative to the scene file)");
  }
  SceneFileObject object;
  object.mesh_path = (base / item["mesh"].get<std::string>()).string();
  MeshLoadOptions load;
  if (item.contains("unit")) {
    if (!item["unit"].is_string()) ThrowInputError(source, "unit", "\"m\", \"cm\" or \"mm\"", item["unit"].dump());
    load.metres_per_unit = MetresPerUnit(item["unit"].get<std::string>());
  }
  if (item.contains("object_from_mesh"))
    load.object_from_mesh = PoseFromJson(item["object_from_mesh"], source, "object_from_mesh");
  const char* pose_key =
      item.contains("scene_from_object") || !camera_frame ? "scene_from_object" : "camera_from_object";
  if (!item.contains(pose_key)) {
    ThrowInputError(source, "objects[].scene_from_object",
                    camera_frame ? "a 4x4 pose in metres (or camera_from_object, as there are no viewpoints)"
                                 : "a 4x4 pose in metres");
  }
  object.scene_from_object = PoseFromJson(item[pose_key], source, pose_key);
  object.mesh = LoadMesh(object.mesh_path, load);
  object.name = item.contains("name") && item["name"].is_string() ? item["name"].get<std::string>() : object.mesh.name;
  return object;
}

// Viewpoints around the sphere enclosing every object's bounding sphere (scene frame).
std::vector<Eigen::Isometry3d> SampleSceneViews(const SceneFile& scene, const nlohmann::json& json,
                                                const std::string& source) {
  if (!json.is_object() || !json.contains("count") || !json["count"].is_number_integer() ||
      json["count"].get<int>() < 1) {
    ThrowInputError(source, "sample_views.count", "a number of views >= 1");
  }
  ViewSamplingOptions options;
  options.num_views = json["count"].get<int>();
  options.min_elevation_rad = Number(json, "min_elevation_rad", source, options.min_elevation_rad);
  options.max_elevation_rad = Number(json, "max_elevation_rad", source, options.max_elevation_rad);
  options.margin = Number(json, "margin", source, options.margin);
  options.distance_m = Number(json, "distance_m", source, options.distance_m);
  options.up_object = Vector3(json, "up", source, options.up_object);
  options.forward_object = Vector3(json, "forward", source, options.forward_object);
  std::vector<BoundingSphere> spheres;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const SceneFileObject& object : scene.objects) {
    BoundingSphere sphere = ComputeBoundingSphere(object.mesh);
    sphere.center_object = object.scene_from_object * sphere.center_object;
    center += sphere.center_object / static_cast<double>(scene.objects.size());
    spheres.push_back(sphere);
  }
  BoundingSphere enclosing{center, 0.0};
  for (const BoundingSphere& sphere : spheres) {
    enclosing.radius_m = std::max(enclosing.radius_m, (sphere.center_object - center).norm() + sphere.radius_m);
  }
  return SampleViews(enclosing, scene.camera, options);  // "object" frame here = scene frame
}

SensorNoiseOptions ReadNoise(const nlohmann::json& json, const std::string& source) {
  if (!json.is_object()) ThrowInputError(source, "noise", "an object of sensor noise options", json.dump());
  SensorNoiseOptions noise;
  const std::pair<const char*, double*> fields[] = {{"axial_sigma_base_m", &noise.axial_sigma_base_m},
                                                    {"axial_sigma_quadratic_per_m", &noise.axial_sigma_quadratic_per_m},
                                                    {"axial_sigma_offset_m", &noise.axial_sigma_offset_m},
                                                    {"baseline_m", &noise.baseline_m},
                                                    {"disparity_step_px", &noise.disparity_step_px},
                                                    {"max_incidence_rad", &noise.max_incidence_rad},
                                                    {"edge_jump_m", &noise.edge_jump_m},
                                                    {"edge_dropout", &noise.edge_dropout},
                                                    {"random_dropout", &noise.random_dropout}};
  for (const auto& [key, field] : fields) *field = Number(json, key, source + " noise", *field);
  noise.seed = static_cast<uint32_t>(Number(json, "seed", source + " noise", noise.seed));
  noise.edge_width_px = static_cast<int>(Number(json, "edge_width_px", source + " noise", noise.edge_width_px));
  noise.Check();
  return noise;
}

}  // namespace

nlohmann::json CameraToJson(const PinholeCamera& camera) {
  return {{"fx", camera.fx}, {"fy", camera.fy},       {"cx", camera.cx},
          {"cy", camera.cy}, {"width", camera.width}, {"height", camera.height}};
}

RenderedViewFiles WriteRenderedView(const std::string& directory, const std::string& stem, const RenderResult& rendered,
                                    const PinholeCamera& camera, const nlohmann::json& extra, bool with_labels,
                                    const cv::Mat& depth) {
  const fs::path dir(directory);
  std::error_code error;
  fs::create_directories(dir, error);
  if (error) ThrowInputError(directory, "--out", "a directory that can be created", error.message());
  RenderedViewFiles files{stem + ".json", stem + "-color.png", stem + "-depth.png", stem + "-mask.png", "", 0};
  WriteColorImage((dir / files.color).string(), rendered.color);
  WritePng(dir / files.depth, EncodeDepth(depth.empty() ? rendered.depth : depth, &files.depth_out_of_range));
  WritePng(dir / files.mask, rendered.mask);
  nlohmann::json json = {{"color", files.color},
                         {"depth", files.depth},
                         {"depth_scale", kRenderedDepthScale},
                         {"depth_unit", "metres = depth PNG value / depth_scale; 0 = no surface"},
                         {"mask", files.mask},
                         {"camera", {camera.fx, camera.fy, camera.cx, camera.cy}},
                         {"width", camera.width},
                         {"height", camera.height}};
  if (with_labels) {
    files.labels = stem + "-labels.png";
    cv::Mat labels = rendered.labels;
    if (rendered.visible_pixels.size() <= 255) rendered.labels.convertTo(labels, CV_8U);
    WritePng(dir / files.labels, labels);
    json["labels"] = files.labels;
  }
  for (const auto& [key, value] : extra.items()) json[key] = value;
  WriteJsonFile((dir / files.json).string(), json);
  return files;
}

SceneFile ReadSceneFile(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  if (!json.is_object()) ThrowInputError(path, "scene", "a JSON object");
  SceneFile scene;
  scene.path = path;
  scene.camera = ReadCamera(json, path);
  if (!json.contains("objects") || !json["objects"].is_array() || json["objects"].empty()) {
    ThrowInputError(path, "objects", "a non-empty array of {\"mesh\", \"scene_from_object\", ...}");
  }
  const bool sampled = json.contains("sample_views");
  const bool listed = json.contains("viewpoints");
  if (sampled && listed) ThrowInputError(path, "viewpoints/sample_views", "one of the two, not both");
  const fs::path base = fs::path(path).parent_path();
  for (const nlohmann::json& item : json["objects"]) {
    scene.objects.push_back(ReadSceneObject(item, path, base, !sampled && !listed));
  }
  if (listed) {
    if (!json["viewpoints"].is_array() || json["viewpoints"].empty()) {
      ThrowInputError(path, "viewpoints", "a non-empty array of 4x4 camera_from_scene poses");
    }
    for (const nlohmann::json& pose : json["viewpoints"]) {
      scene.camera_from_scene.push_back(PoseFromJson(pose, path, "viewpoints"));
    }
  } else if (sampled) {
    scene.camera_from_scene = SampleSceneViews(scene, json["sample_views"], path);
  } else {
    scene.camera_from_scene.push_back(Eigen::Isometry3d::Identity());
  }
  if (json.contains("noise")) {
    scene.add_noise = true;
    scene.noise = ReadNoise(json["noise"], path);
  }
  return scene;
}

}  // namespace ecv
