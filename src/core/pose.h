#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

namespace ecv {

// Poses are Eigen::Isometry3d named by both frames: `camera_from_object` maps object-frame points to
// camera-frame points, x_camera = R x_object + t (metres).

/// Throws InputError naming `source` and `field` unless `matrix` is a rigid transform: finite, last
/// row (0, 0, 0, 1), |R^T R - I| (Frobenius) below `tolerance` and det R > 0. The rotation returned
/// is the nearest exact one, so rounded values in files (LM-O's have errors up to 0.003) are accepted.
Eigen::Isometry3d RigidFromMatrix(const Eigen::Matrix4d& matrix, const std::string& source, const std::string& field,
                                  double tolerance = 1e-2);

/// `camera_from_object` turned 180 degrees about the object-frame line through `centre` along `axis` (need not be
/// unit): for an object nearly symmetric about that line the turned pose puts its surface where it was.
Eigen::Isometry3d TurnedHalfWayAbout(const Eigen::Isometry3d& camera_from_object, const Eigen::Vector3d& centre,
                                     const Eigen::Vector3d& axis);

/// Angle of the rotation that takes `a` to `b`, radians in [0, pi].
double RotationAngle(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

/// Distance between the translations of `a` and `b`, metres.
double TranslationDistance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

/// One annotated object in a frame.
struct GroundTruth {
  int object_id = 0;                     ///< dataset id (YCB-Video cls_index, BOP obj_id)
  std::string object_name;               ///< e.g. "003_cracker_box", "obj_000005"
  Eigen::Isometry3d camera_from_object;  ///< metres
  double visible_fraction = -1.0;        ///< fraction of the object's pixels not hidden, -1 if unknown
  cv::Rect object_box;                   ///< projected box of the whole object, pixels; empty if unknown
  cv::Rect visible_box;                  ///< box of its visible pixels; empty if unknown
};

}  // namespace ecv
