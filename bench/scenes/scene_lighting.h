#pragma once

// Internal to ecv_bench_scenes: the table and wall behind the objects, and the light on the rendered image.

#include <array>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/mesh.h"
#include "render/renderer.h"
#include "scenes/rendered_scenes.h"
#include "scenes/scene_placement.h"

namespace ecv::bench {

/// The table top (table frame z = 0) up to a wall across the view behind the objects (metres), each textured with a
/// random cut of a backdrop: {table, wall}.
std::array<TriangleMesh, 2> TableAndWall(const View& view, const Backdrops& backdrops, std::mt19937& rng);

/// Camera-frame points (metres) of the pixels of `depth` (CV_32FC1, metres): CV_32FC3, z = 0 where there is no surface.
cv::Mat BackProject(const cv::Mat& depth, const PinholeCamera& camera);

/// The objects that cast shadows, in the table frame, and a sphere that holds them.
struct Casters {
  std::vector<SceneObject> objects;                  ///< camera_from_object holds table_from_object, metres
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  ///< table frame, metres
  double radius = 0.0;                               ///< metres
};

/// The `placed` objects as shadow casters; `mesh_ids[i]` is assets[i] uploaded to the renderer.
Casters CastersOf(const std::vector<SceneAsset>& assets, const std::vector<MeshId>& mesh_ids,
                  const std::vector<Placed>& placed);

/// Per pixel of `points` (CV_32FC3, camera frame, metres), the share (CV_8UC1, 0-255) of the light hidden by an
/// object, from a shadow map of `casters` seen from along `to_light` (unit, table frame); soft edges.
cv::Mat Shadows(Renderer& renderer, const Casters& casters, const View& view, const cv::Mat& points,
                const Eigen::Vector3d& to_light);

/// Lambertian shading of `albedo` (CV_8UC3) at `points` (CV_32FC3, camera frame, metres): albedo x gain x (ambient +
/// (1 - ambient) max(0, n.l) lit), l = `to_light_camera` (unit, camera frame), lit = 1 - the share of `shadow`
/// (CV_8UC1, 0-255; empty: no shadows); `ambient` in 0..1. Pixels without a point stay black.
cv::Mat Shade(const cv::Mat& albedo, const cv::Mat& points, const cv::Mat& shadow,
              const Eigen::Vector3d& to_light_camera, const Eigen::Vector3d& gain, double ambient);

}  // namespace ecv::bench
