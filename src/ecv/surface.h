#pragma once

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "core/frame.h"

namespace ecv {

/// The surface a keypoint lies on, reconstructed from the depth image.
struct LocalSurface {
  Eigen::Vector3f position;  ///< camera frame, metres
  Eigen::Vector3f normal;    ///< unit, facing the camera; zero when too few points to fit a plane
  Eigen::Vector3f color;     ///< mean RGB in [0, 1] around the keypoint on this surface
};

/// A least-squares plane: the points' centroid and unit normal (smallest principal axis, sign arbitrary).
struct Plane {
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();
};

/// The least-squares plane of `points` (at least 3).
Plane FitPlane(const std::vector<Eigen::Vector3f>& points);

/// Options of the reconstruction (a subset of EcvOptions).
struct SurfaceOptions {
  double radius_m = 0.01;     ///< plane fit over the points within this distance of the keypoint's point
  double depth_gap_m = 0.01;  ///< depths this far behind the nearest one belong to another surface
  int color_radius_px = 2;    ///< colour window half-size
};

/// Depth of the front-most surface in the 5x5 window around `pixel`: the median of the valid depths within
/// `depth_gap_m` of the nearest one. At an occluding contour this is the occluder, to which the edge belongs.
std::optional<float> FrontSurfaceDepth(const cv::Mat& depth, const cv::Point& pixel, double depth_gap_m);

/// Position, plane normal and colour of the surface at `pixel`; nullopt when it has no valid depth.
std::optional<LocalSurface> ReconstructSurface(const RgbdFrame& frame, const cv::Point& pixel,
                                               const SurfaceOptions& options);

/// 3D direction of an image edge through `pixel` whose normal in the image is at `image_orientation` (rad):
/// the intersection of the surface plane with the plane through the camera centre and the 2D edge line.
/// Falls back to a fronto-parallel direction when the surface is seen edge-on or has no normal.
Eigen::Vector3f EdgeDirection(const PinholeCamera& camera, const Eigen::Vector2f& pixel, float image_orientation,
                              const LocalSurface& surface);

}  // namespace ecv
