#pragma once

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/mesh.h"

namespace ecv::bench {

/// A way a rigid object rests on a flat table under gravity: the table frame has z up, its plane z = 0.
struct RestingPose {
  Eigen::Isometry3d table_from_object = Eigen::Isometry3d::Identity();  ///< lowest vertex at z = 0, centred on x, y
  double support_area_m2 = 0.0;  ///< area of the convex support polygon on the table, square metres
  double margin_m = 0.0;         ///< distance of the centre of mass's foot from the support polygon's edge, metres
};

/// Options of RestingPoses.
struct RestingPoseOptions {
  double contact_tolerance_m = 0.001;  ///< vertices this close to the support plane touch the table, metres
  double min_margin_m = 0.003;         ///< the centre of mass's foot lies at least this far inside the support, metres
  double merge_deg = 3.0;              ///< support planes whose normals differ by less than this are one, degrees
  double separation_deg = 20.0;        ///< of stable poses whose down directions differ by less, the larger support
                                       ///< stays (keeps a handful of a can's side poses), degrees

  /// Throws InputError for negative or non-finite values.
  void Check() const;
};

/// The stable resting poses of `mesh` (object frame, metres): the faces of its convex hull on which the centre of
/// mass (of the enclosed volume; of the vertices for open meshes) lies over the support polygon, by decreasing
/// support area. When none is stable by `min_margin_m`, the one of largest margin. Rotations about the table's z axis
/// are left free (yaw 0 here). Never empty for a mesh with volume.
std::vector<RestingPose> RestingPoses(const TriangleMesh& mesh, const RestingPoseOptions& options = {});

/// Convex outline of `mesh` seen from above when placed by `table_from_object`: its vertices projected onto the
/// table plane (x, y in metres), counter-clockwise. Two objects whose outlines do not overlap do not intersect.
std::vector<cv::Point2f> Footprint(const TriangleMesh& mesh, const Eigen::Isometry3d& table_from_object);

}  // namespace ecv::bench
