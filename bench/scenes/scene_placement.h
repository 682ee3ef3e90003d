#pragma once

// Internal to ecv_bench_scenes: the camera's view of the table and the objects placed on it.

#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "scenes/rendered_scenes.h"

namespace ecv::bench {

/// A footprint on the table: table frame x, y, millimetres, counter-clockwise.
using Polygon = std::vector<cv::Point2f>;

/// The camera's view of the table: where it looks and its horizontal axes (table frame, unit).
struct View {
  PinholeCamera camera;
  Eigen::Isometry3d camera_from_table;      ///< metres
  Eigen::Vector3d look_at, right, forward;  ///< table frame; look_at in metres, right and forward unit
};

/// An object placed on the table.
struct Placed {
  size_t asset = 0;                     ///< index into the assets
  Eigen::Isometry3d table_from_object;  ///< metres
  Polygon footprint;                    ///< millimetres
};

/// A draw from [low, high) by `rng`.
double Uniform(std::mt19937& rng, double low, double high);

/// The camera at `eye` looking at `target` (table frame, metres) with its x axis parallel to the table (no roll):
/// camera_from_table.
Eigen::Isometry3d CameraLookingAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target);

/// The unit direction at `azimuth` about the table's z axis from its x axis and `elevation` above its plane (radians).
Eigen::Vector3d DirectionFromAngles(double azimuth, double elevation);

/// The camera (YCB-Video's): at a random distance, elevation and azimuth, looking at a point near the table's origin.
View DrawView(const RenderedSceneOptions& options, std::mt19937& rng);

/// Chooses distinct modelled objects and clutter (counts from the options) and places them one after the other, in
/// random order, each in a resting pose at a random yaw and place in view, not overlapping the others and pushed to
/// within `options.max_gap_m` of one of them; an object that finds no place gives way to the next of its kind.
std::vector<Placed> PlaceObjects(const std::vector<SceneAsset>& assets, const View& view,
                                 const RenderedSceneOptions& options, std::mt19937& rng);

}  // namespace ecv::bench
