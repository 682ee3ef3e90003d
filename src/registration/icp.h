#pragma once

#include <vector>

#include <Eigen/Geometry>

namespace ecv {

/// Point-to-plane ICP that refines an accepted pose against dense scene points.
struct IcpOptions {
  int max_iterations = 30;                  ///< Gauss-Newton steps at most
  double max_correspondence_m = 0.01;       ///< object points farther than this from the scene are ignored, metres
  double convergence_translation_m = 1e-5;  ///< stop when a step moves less than this, metres ...
  double convergence_rotation_rad = 1e-5;   ///< ... and turns less than this, radians
  int normal_neighbours = 10;               ///< scene normals from this many nearest points (PCA)

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

}  // namespace ecv
