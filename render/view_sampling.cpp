#include "render/view_sampling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

namespace ecv {
namespace {

constexpr double kHalfPi = 1.5707963267948966;
constexpr double kTiny = 1e-9;

bool IsDirection(const Eigen::Vector3d& vector) {
  return vector.allFinite() && vector.norm() > kTiny;
}

}  // namespace

void ViewSamplingOptions::Check() const {
  const std::string source = "view sampling options";
  if (num_views < 1) ThrowInputError(source, "num_views", "at least 1", std::to_string(num_views));
  if (!(min_elevation_rad >= -kHalfPi - kTiny && max_elevation_rad <= kHalfPi + kTiny &&
        min_elevation_rad <= max_elevation_rad)) {
    ThrowInputError(source, "min/max_elevation_rad", "-pi/2 <= min <= max <= pi/2",
                    std::to_string(min_elevation_rad) + "/" + std::to_string(max_elevation_rad));
  }
  if (!IsDirection(up_object)) ThrowInputError(source, "up_object", "a non-zero finite vector");
  if (!IsDirection(forward_object) || up_object.normalized().cross(forward_object.normalized()).norm() < 1e-6) {
    ThrowInputError(source, "forward_object", "a non-zero finite vector not parallel to up_object");
  }
  if (!(margin >= 0.0 && margin <= 0.9))
    ThrowInputError(source, "margin", "a value in [0, 0.9]", std::to_string(margin));
  if (!(distance_m >= 0.0) || !std::isfinite(distance_m)) {
    ThrowInputError(source, "distance_m", "0 (fit) or a positive distance in metres", std::to_string(distance_m));
  }
}

BoundingSphere ComputeBoundingSphere(const TriangleMesh& mesh) {
  if (mesh.NumVertices() == 0) ThrowInputError("mesh '" + mesh.name + "'", "positions", "at least one vertex", "0");
  BoundingSphere sphere;
  sphere.center_object = mesh.BoundingBox().center();
  double radius_squared = 0.0;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& position : part.positions) {
      radius_squared = std::max(radius_squared, (position.cast<double>() - sphere.center_object).squaredNorm());
    }
  }
  sphere.radius_m = std::sqrt(radius_squared);
  return sphere;
}

double FitViewDistance(double radius_m, const PinholeCamera& camera, double margin) {
  camera.Check("view sampling camera");
  // Tangent of the half-angle available around the principal axis: the nearest image border, with pixel
  // centres 0 .. width-1 (borders at -0.5 and width - 0.5).
  const double left = (camera.cx + 0.5) / camera.fx;
  const double right = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double top = (camera.cy + 0.5) / camera.fy;
  const double bottom = (camera.height - 0.5 - camera.cy) / camera.fy;
  const double tangent = (1.0 - margin) * std::min({left, right, top, bottom});
  if (!(tangent > 0.0)) {
    ThrowInputError("view sampling camera", "cx/cy", "a principal point inside the image",
                    std::to_string(camera.cx) + "/" + std::to_string(camera.cy));
  }
  // A sphere of radius r at distance d subtends a half-angle asin(r / d): need tan(asin(r / d)) <= tangent.
  return radius_m * std::sqrt(1.0 + tangent * tangent) / tangent;
}

Eigen::Isometry3d LookAt(const Eigen::Vector3d& camera_position_object, const Eigen::Vector3d& target_object,
                         const Eigen::Vector3d& up_object, const Eigen::Vector3d& fallback_up_object) {
  const Eigen::Vector3d z = (target_object - camera_position_object).normalized();
  Eigen::Vector3d up = up_object - up_object.dot(z) * z;
  if (up.norm() < 1e-6 * up_object.norm()) up = fallback_up_object - fallback_up_object.dot(z) * z;
  const Eigen::Vector3d y = -up.normalized();  // image y points down
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d object_from_camera_rotation;
  object_from_camera_rotation << x, y, z;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  camera_from_object.linear() = object_from_camera_rotation.transpose();
  camera_from_object.translation() = -object_from_camera_rotation.transpose() * camera_position_object;
  return camera_from_object;
}

std::vector<Eigen::Isometry3d> SampleViews(const BoundingSphere& sphere, const PinholeCamera& camera,
                                           const ViewSamplingOptions& options) {
  options.Check();
  const double distance =
      options.distance_m > 0.0 ? options.distance_m : FitViewDistance(sphere.radius_m, camera, options.margin);
  const Eigen::Vector3d up = options.up_object.normalized();
  const Eigen::Vector3d forward = (options.forward_object - options.forward_object.dot(up) * up).normalized();
  const Eigen::Vector3d side = up.cross(forward);
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  const double sin_min = std::sin(options.min_elevation_rad);
  const double sin_max = std::sin(options.max_elevation_rad);
  std::vector<Eigen::Isometry3d> views;
  views.reserve(static_cast<size_t>(options.num_views));
  for (int i = 0; i < options.num_views; ++i) {
    // Equal steps in sin(elevation) give equal areas on the sphere (Archimedes); the golden angle spreads
    // the azimuths.
    const double height = sin_min + (i + 0.5) / options.num_views * (sin_max - sin_min);
    const double ring = std::sqrt(std::max(0.0, 1.0 - height * height));
    const double azimuth = golden_angle * i;
    const Eigen::Vector3d direction = ring * (std::cos(azimuth) * forward + std::sin(azimuth) * side) + height * up;
    views.push_back(LookAt(sphere.center_object + distance * direction, sphere.center_object, up, forward));
  }
  return views;
}

}  // namespace ecv
