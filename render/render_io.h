#pragma once

// Files of the renderer: rendered views written as frames, and scene files. The rendering itself
// (renderer.h) and the models (view_sampling.h, sensor_noise.h) do no file I/O.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/mesh.h"
#include "render/renderer.h"
#include "render/sensor_noise.h"

namespace ecv {

/// Depth PNGs of rendered views hold metres * 10000 (0.1 mm steps, up to 6.5535 m), as YCB-Video's.
inline constexpr double kRenderedDepthScale = 10000.0;

/// What WriteRenderedView wrote (file names relative to the directory).
struct RenderedViewFiles {
  std::string json;
  std::string color;
  std::string depth;
  std::string mask;
  std::string labels;          ///< "" unless written
  int depth_out_of_range = 0;  ///< pixels beyond 6.5535 m written as 0 (missing)
};

/// Writes `<stem>-color.png` (RGB), `<stem>-depth.png` (16-bit, metres * kRenderedDepthScale, 0 =
/// missing), `<stem>-mask.png` (0/255), with `with_labels` `<stem>-labels.png` (1 + object index; 8-bit
/// up to 255 objects, else 16-bit), and last `<stem>.json`: a frame JSON as every command reads ("color",
/// "depth", "depth_scale", "camera": [fx, fy, cx, cy]) that LoadFrame reads, with "width", "height",
/// "mask", "depth_unit" and the keys of `extra` (e.g. "camera_from_object"). `depth` replaces the
/// rendered depth when not empty (a noisy one). Throws InputError when a file cannot be written.
RenderedViewFiles WriteRenderedView(const std::string& directory, const std::string& stem, const RenderResult& rendered,
                                    const PinholeCamera& camera, const nlohmann::json& extra, bool with_labels = false,
                                    const cv::Mat& depth = cv::Mat());

/// JSON {"fx", "fy", "cx", "cy", "width", "height"} of a camera, pixels.
nlohmann::json CameraToJson(const PinholeCamera& camera);

/// One mesh of a scene file.
struct SceneFileObject {
  std::string name;       ///< "name", else the mesh file stem
  std::string mesh_path;  ///< "mesh", resolved against the scene file's folder
  TriangleMesh mesh;      ///< loaded with "unit" (m, cm, mm) and "object_from_mesh"
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();  ///< metres
};

/// A scene file (SCENE.json) with its meshes loaded:
/// {"camera": [fx, fy, cx, cy], "width": W, "height": H,
///  "objects": [{"mesh": PATH, "unit": "m", "name": N, "object_from_mesh": 4x4,
///               "scene_from_object": 4x4 (or "camera_from_object" when there are no viewpoints)}],
///  "viewpoints": [4x4 camera_from_scene, ...]                     (optional; else one view at identity)
///  "sample_views": {"count": N, "min_elevation_rad", "max_elevation_rad", "up": [x, y, z],
///                   "forward": [x, y, z], "margin", "distance_m"}  (optional, instead of viewpoints:
///                   around the sphere that encloses all objects)
///  "noise": {"seed": S, any SensorNoiseOptions field}}            (optional: structured-light model)
struct SceneFile {
  std::string path;
  PinholeCamera camera;
  std::vector<SceneFileObject> objects;
  std::vector<Eigen::Isometry3d> camera_from_scene;  ///< one per view, metres
  bool add_noise = false;
  SensorNoiseOptions noise;
};

/// Reads a scene file and loads its meshes; throws InputError naming the file and field.
SceneFile ReadSceneFile(const std::string& path);

}  // namespace ecv
