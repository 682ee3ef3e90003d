#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/mesh.h"

namespace ecv {

/// Where to put the cameras that look at an object.
struct ViewSamplingOptions {
  int num_views = 100;  ///< number of viewpoints
  /// Band of elevations, radians: angle between the viewing direction from the object centre to the
  /// camera and the plane orthogonal to `up_object`; -pi/2 .. pi/2 is the whole sphere.
  double min_elevation_rad = -1.5707963267948966;
  double max_elevation_rad = 1.5707963267948966;
  /// Object-frame direction that appears upward in every image (the camera's -y is the projection of
  /// `up_object` onto the image plane); where the camera looks along it, `forward_object` takes its role.
  Eigen::Vector3d up_object = Eigen::Vector3d::UnitZ();
  /// Azimuth 0 lies in the plane spanned by `up_object` and this object-frame direction.
  Eigen::Vector3d forward_object = Eigen::Vector3d::UnitX();
  /// Fraction of the smaller image half-extent (from the principal point) left free around the object's
  /// bounding sphere, 0 .. 0.9.
  double margin = 0.1;
  /// Camera distance from the object centre, metres; 0 = the smallest distance that fits the bounding
  /// sphere in the image with `margin`.
  double distance_m = 0.0;

  /// Throws InputError for num_views < 1, an elevation band outside [-pi/2, pi/2] or reversed, a
  /// zero or non-finite up/forward vector or two parallel ones, a margin outside [0, 0.9] or a
  /// negative distance.
  void Check() const;
};

/// Smallest sphere found around the object: centre of the bounding box and the largest vertex
/// distance from it (object frame, metres).
struct BoundingSphere {
  Eigen::Vector3d center_object = Eigen::Vector3d::Zero();
  double radius_m = 0.0;
};

/// Bounding sphere of all vertices of `mesh`; throws InputError for a mesh without vertices.
BoundingSphere ComputeBoundingSphere(const TriangleMesh& mesh);

/// Distance from the sphere centre (metres) at which a sphere of `radius_m`, seen by `camera` looking at
/// its centre, leaves `margin` of the smaller half-extent of the image free on every side.
double FitViewDistance(double radius_m, const PinholeCamera& camera, double margin);

/// Viewpoints spread evenly (a Fibonacci lattice on the band of elevations: equal area per view) around
/// `sphere`, each looking at its centre with the principal axis, upright as `options.up_object`.
/// Returns camera_from_object for each (metres), in lattice order (elevation rising).
std::vector<Eigen::Isometry3d> SampleViews(const BoundingSphere& sphere, const PinholeCamera& camera,
                                           const ViewSamplingOptions& options = {});

/// camera_from_object of a camera at `camera_position_object` looking at `target_object` (principal
/// axis through it), with the image's upward direction the projection of `up_object` (or of
/// `fallback_up_object` when the camera looks along `up_object`). Object frame, metres.
Eigen::Isometry3d LookAt(const Eigen::Vector3d& camera_position_object, const Eigen::Vector3d& target_object,
                         const Eigen::Vector3d& up_object, const Eigen::Vector3d& fallback_up_object);

}  // namespace ecv
