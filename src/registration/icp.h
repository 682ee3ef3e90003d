#pragma once

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"

namespace ecv {

/// Point-to-plane ICP that refines an accepted pose against dense scene points.
struct IcpOptions {
  int max_iterations = 30;                  ///< Gauss-Newton steps at most
  double max_correspondence_m = 0.01;       ///< object points farther than this from the scene are ignored, metres
  double convergence_translation_m = 1e-4;  ///< stop when a step moves less than this, metres ...
  double convergence_rotation_rad = 1e-4;   ///< ... and turns less than this, radians
  int normal_neighbours = 10;               ///< scene normals from this many nearest points (PCA)
  /// Stop after this many small steps in a row (each under plateau_step_m and plateau_step_rad) that did not lower the
  /// RMS residual by plateau_ratio (relative; 0: never stop so): the pairs then only cycle, or the pose slides along a
  /// direction the surface leaves free (a cylinder's axis). Large steps go on: a pose far off may get worse before it
  /// gets better.
  int plateau_iterations = 3;
  double plateau_ratio = 0.005;
  double plateau_step_m = 0.001;
  double plateau_step_rad = 0.001;

  void Check() const;
};

struct IcpResult {
  bool success = false;  ///< false when too few correspondences (< 6) were found
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();
  double rmse_m = 0.0;           ///< point-to-plane RMS residual of the last correspondences, metres
  double inlier_fraction = 0.0;  ///< object points with a scene point within max_correspondence_m
  int iterations = 0;
};

/// Refines `initial` (scene_from_object) so that the object points lie on the scene surface (metres).
IcpResult RefinePointToPlane(const std::vector<Eigen::Vector3f>& object_points,
                             const std::vector<Eigen::Vector3f>& scene_points, const Eigen::Isometry3d& initial,
                             const IcpOptions& options = {});

/// A depth image prepared as the target of projective ICP: the camera-frame point and unit normal of every
/// `stride`-th pixel.
struct OrganizedScene {
  PinholeCamera camera;  ///< of the samples (PinholeCamera::Sampled)
  cv::Mat points;        ///< CV_32FC3, metres; (0, 0, 0) where the depth is missing
  cv::Mat normals;       ///< CV_32FC3, unit; (0, 0, 0) where a neighbour is missing or across a depth gap
};

/// Samples `depth` (CV_32FC1, metres, 0 = missing; `camera`'s size) every `stride` pixels. A sample's normal is
/// the cross product of the differences between its neighbours two samples away, left-right and up-down; it
/// is left unknown when one of them is missing or lies more than `max_gap_m` off the sample's depth.
OrganizedScene MakeOrganizedScene(const cv::Mat& depth, const PinholeCamera& camera, int stride,
                                  double max_gap_m = 0.02);

/// Point-to-plane ICP with projective association (as in KinectFusion): each object point is paired with the
/// nearest of the 3x3 scene samples around the one it projects to, within max_correspondence_m. No search
/// structure is built and normals come from the image grid, so the scene is prepared once per frame. Its
/// basin is narrower than RefinePointToPlane's (pairs lie near the point's line of sight, not anywhere
/// within max_correspondence_m).
/// Same options (normal_neighbours unused) and result as RefinePointToPlane.
IcpResult RefinePointToPlaneProjective(const std::vector<Eigen::Vector3f>& object_points, const OrganizedScene& scene,
                                       const Eigen::Isometry3d& initial, const IcpOptions& options = {});

}  // namespace ecv
