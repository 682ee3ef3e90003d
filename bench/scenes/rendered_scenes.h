#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/mesh.h"
#include "io/frame_io.h"
#include "render/renderer.h"
#include "scenes/resting_poses.h"

namespace ecv::bench {

/// A mesh a generated scene may hold.
struct SceneAsset {
  std::string name;      ///< model name as the library has it ("003_cracker_box"), or the clutter's ("obj_000005")
  TriangleMesh mesh;     ///< object frame, metres; textured, vertex-coloured or grey
  bool modelled = true;  ///< in the 16-model library: put in the ground truth; false: unmodelled clutter
  bool repaint = false;  ///< no texture of its own: rendered in a random plain colour per scene
  std::vector<RestingPose> resting_poses;  ///< RestingPoses(mesh), filled by LoadSceneAssets; computed when empty
};

/// The meshes of the generalisation scenes from `data_dir` (../shared/data): the 16 YCB-Video models (6 google16k
/// textured meshes moved into the YCB-Video frame, the textured banana, 9 without texture, marked `repaint`) and
/// the 8 LM-O meshes as clutter (`modelled` false), with their resting poses; textures capped at 2048 pixels a side.
/// Throws InputError naming a missing file.
std::vector<SceneAsset> LoadSceneAssets(const std::string& data_dir);

/// Images the scenes' table tops and walls are cut from: real colour images with their objects filled in.
struct Backdrops {
  std::vector<cv::Mat> images;  ///< CV_8UC3 RGB
};

/// The colour images of `frame_prefixes` (YCB-Video) with the pixels of their labelled objects (-label.png > 0)
/// filled from around them (cv::inpaint), so that no modelled object shows in a backdrop.
Backdrops LoadBackdrops(const std::vector<std::string>& frame_prefixes);

/// How rendered scenes are drawn.
struct RenderedSceneOptions {
  int min_objects = 3;  ///< modelled objects per scene (inclusive range)
  int max_objects = 8;
  int min_clutter = 0;  ///< unmodelled clutter objects per scene (inclusive range)
  int max_clutter = 3;
  double min_distance_m = 0.6;  ///< camera to the table point it looks at, metres
  double max_distance_m = 1.1;
  double min_elevation_deg = 30.0;  ///< camera's angle above the table plane, degrees
  double max_elevation_deg = 70.0;
  double min_gain = 0.6;  ///< per-channel light gain (colour of the light), inclusive range
  double max_gain = 1.4;
  double min_intensity = 0.5;  ///< overall brightness factor of the light
  double max_intensity = 1.2;
  double ambient = 0.35;     ///< share of light reaching surfaces facing away and in shadow, 0..1
  double max_gap_m = 0.02;   ///< objects are pushed towards a neighbour until at most this far apart, metres
  bool shadows = true;       ///< shadows cast by the light (shadow map from the light's side)
  bool sensor_noise = true;  ///< Kinect-like depth noise and holes (render/sensor_noise.h)

  /// Throws InputError for empty or inverted ranges and values outside their domains.
  void Check() const;
};

/// One object of a rendered scene.
struct PlacedObject {
  std::string name;                            ///< SceneAsset::name
  bool modelled = true;                        ///< in the ground truth
  Eigen::Isometry3d camera_from_object;        ///< metres
  Eigen::Isometry3d table_from_object;         ///< metres; table frame z up, plane z = 0
  Eigen::Vector3f paint{-1.0F, -1.0F, -1.0F};  ///< the plain colour given to a repainted mesh, RGB 0..1; -1 if none
  int visible_pixels = 0;                      ///< pixels where it is seen in the scene
  int unoccluded_pixels = 0;                   ///< pixels it would cover alone in the image
};

/// A rendered scene with its ground truth.
struct RenderedScene {
  LoadedFrame frame;                    ///< colour, depth (noisy), camera and the modelled objects' ground truth
  std::vector<PlacedObject> objects;    ///< modelled and clutter, in drawing order
  cv::Mat labels;                       ///< CV_16UC1: 1 + index into `objects` of the object seen, 0 for table/wall
  Eigen::Isometry3d camera_from_table;  ///< metres
  Eigen::Vector3d light_gain;           ///< per-channel gain times intensity
  Eigen::Vector3d light_direction;      ///< unit, camera frame, towards the light
};

/// Draws a scene from `seed` (the same seed, assets and backdrops give the same scene): 3-8 modelled objects in
/// resting poses with random yaw, placed on a table textured with a backdrop cut, touching and hiding each other,
/// clutter among them, lit by a light of random colour, strength and direction, with the sensor's depth noise.
/// Objects hidden to less than 10 % of their pixels are left out of the ground truth (not of the image).
/// `mesh_ids[i]` is assets[i] uploaded to `renderer`; the table and wall are uploaded and removed per call. Throws
/// InputError when mesh_ids do not match the assets, there are no backdrops or fewer modelled assets than min_objects.
RenderedScene GenerateRenderedScene(Renderer& renderer, const std::vector<SceneAsset>& assets,
                                    const std::vector<MeshId>& mesh_ids, const Backdrops& backdrops, uint32_t seed,
                                    const RenderedSceneOptions& options = {});

}  // namespace ecv::bench
