#include "registration/icp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

#include "core/error.h"
#include "core/point_index.h"

namespace ecv {
namespace {

// Unit normals of `points` from the PCA of their k nearest neighbours (sign arbitrary: point-to-plane
// residuals do not depend on it).
std::vector<Eigen::Vector3f> EstimateNormals(const std::vector<Eigen::Vector3f>& points, const PointIndex& index,
                                             int k) {
  std::vector<Eigen::Vector3f> normals(points.size(), Eigen::Vector3f::Zero());
  for (size_t i = 0; i < points.size(); ++i) {
    const std::vector<int> neighbours = index.KNearest(points[i], k);
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (const int j : neighbours) mean += points[static_cast<size_t>(j)];
    mean /= static_cast<float>(neighbours.size());
    Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
    for (const int j : neighbours) {
      const Eigen::Vector3f offset = points[static_cast<size_t>(j)] - mean;
      covariance += offset * offset.transpose();
    }
    normals[i] = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f>(covariance).eigenvectors().col(0);
  }
  return normals;
}

// Small rigid motion exp([omega; t]) as an isometry.
Eigen::Isometry3d Increment(const Eigen::Matrix<double, 6, 1>& step) {
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
  const double angle = step.head<3>().norm();
  if (angle > 0.0) increment.linear() = Eigen::AngleAxisd(angle, step.head<3>() / angle).toRotationMatrix();
  increment.translation() = step.tail<3>();
  return increment;
}

}  // namespace

void IcpOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("ICP options", field, expected);
  };
  require(max_iterations >= 1, "max_iterations", "at least 1");
  require(max_correspondence_m > 0.0 && std::isfinite(max_correspondence_m), "max_correspondence_m", "> 0 m");
  require(convergence_translation_m >= 0.0 && convergence_rotation_rad >= 0.0, "convergence", ">= 0");
  require(normal_neighbours >= 3, "normal_neighbours", "at least 3");
}

IcpResult RefinePointToPlane(const std::vector<Eigen::Vector3f>& object_points,
                             const std::vector<Eigen::Vector3f>& scene_points, const Eigen::Isometry3d& initial,
                             const IcpOptions& options) {
  options.Check();
  IcpResult result;
  result.scene_from_object = initial;
  if (object_points.empty() || scene_points.size() < static_cast<size_t>(options.normal_neighbours)) return result;
  const PointIndex tree(scene_points);
  const std::vector<Eigen::Vector3f> normals = EstimateNormals(scene_points, tree, options.normal_neighbours);
  const float max_squared = static_cast<float>(options.max_correspondence_m * options.max_correspondence_m);

  for (result.iterations = 1; result.iterations <= options.max_iterations; ++result.iterations) {
    // Gauss-Newton on sum ((p' - q) . n)^2 with p' = exp(step) * T * p linearised at step = 0.
    Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
    double residual_sum = 0.0;
    int count = 0;
    const Eigen::Isometry3f transform = result.scene_from_object.cast<float>();
    for (const Eigen::Vector3f& point : object_points) {
      const Eigen::Vector3f moved = transform * point;
      const auto [nearest, squared] = tree.Nearest(moved);
      if (squared > max_squared) continue;
      const size_t index = static_cast<size_t>(nearest);
      const Eigen::Vector3d n = normals[index].cast<double>(), p = moved.cast<double>();
      const double residual = (p - scene_points[index].cast<double>()).dot(n);
      Eigen::Matrix<double, 6, 1> jacobian;
      jacobian << p.cross(n), n;
      normal_matrix += jacobian * jacobian.transpose();
      gradient += jacobian * residual;
      residual_sum += residual * residual;
      ++count;
    }
    result.inlier_fraction = static_cast<double>(count) / static_cast<double>(object_points.size());
    result.rmse_m = count > 0 ? std::sqrt(residual_sum / count) : 0.0;
    if (count < 6) return result;
    const Eigen::Matrix<double, 6, 1> step = normal_matrix.ldlt().solve(-gradient);
    if (!step.allFinite()) return result;
    result.scene_from_object = Increment(step) * result.scene_from_object;
    result.success = true;
    if (step.head<3>().norm() < options.convergence_rotation_rad &&
        step.tail<3>().norm() < options.convergence_translation_m) {
      break;
    }
  }
  result.iterations = std::min(result.iterations, options.max_iterations);
  return result;
}

}  // namespace ecv
