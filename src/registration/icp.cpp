#include "registration/icp.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

// Gauss-Newton normal equations of sum ((p' - q) . n)^2, p' = exp(step) * T * p linearised at step = 0.
struct PointToPlaneSystem {
  Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> gradient = Eigen::Matrix<double, 6, 1>::Zero();
  double residual_sum = 0.0;
  int count = 0;

  // `moved` = T * p paired with scene point `target` of normal `normal`.
  void Add(const Eigen::Vector3f& moved, const Eigen::Vector3f& target, const Eigen::Vector3f& normal) {
    const Eigen::Vector3d n = normal.cast<double>(), p = moved.cast<double>();
    const double residual = (p - target.cast<double>()).dot(n);
    Eigen::Matrix<double, 6, 1> jacobian;
    jacobian << p.cross(n), n;
    normal_matrix += jacobian * jacobian.transpose();
    gradient += jacobian * residual;
    residual_sum += residual * residual;
    ++count;
  }
};

// Small rigid motion exp([omega; t]) as an isometry.
Eigen::Isometry3d Increment(const Eigen::Matrix<double, 6, 1>& step) {
  Eigen::Isometry3d increment = Eigen::Isometry3d::Identity();
  const double angle = step.head<3>().norm();
  if (angle > 0.0) increment.linear() = Eigen::AngleAxisd(angle, step.head<3>() / angle).toRotationMatrix();
  increment.translation() = step.tail<3>();
  return increment;
}

// Gauss-Newton steps on `result`'s pose until convergence or max_iterations; `pair(transform, system)` adds
// the point pairs of the current pose to the system. Fails (result.success stays false) when a step has
// fewer than 6 pairs or no finite solution.
template <typename Pair>
void Iterate(size_t object_count, const IcpOptions& options, IcpResult* result, Pair pair) {
  double best_rmse_m = std::numeric_limits<double>::infinity();
  int stalled = 0;  // small steps in a row since the residual last fell by plateau_ratio
  for (result->iterations = 1; result->iterations <= options.max_iterations; ++result->iterations) {
    PointToPlaneSystem system;
    pair(result->scene_from_object.cast<float>(), &system);
    result->inlier_fraction = static_cast<double>(system.count) / static_cast<double>(object_count);
    result->rmse_m = system.count > 0 ? std::sqrt(system.residual_sum / system.count) : 0.0;
    if (system.count < 6) return;
    const Eigen::Matrix<double, 6, 1> step = system.normal_matrix.ldlt().solve(-system.gradient);
    if (!step.allFinite()) return;
    const bool small =
        step.head<3>().norm() < options.plateau_step_rad && step.tail<3>().norm() < options.plateau_step_m;
    if (result->rmse_m < (1.0 - options.plateau_ratio) * best_rmse_m) {
      best_rmse_m = result->rmse_m;
      stalled = 0;
    } else {
      stalled = small ? stalled + 1 : 0;
    }
    if (options.plateau_iterations > 0 && stalled >= options.plateau_iterations) break;
    result->scene_from_object = Increment(step) * result->scene_from_object;
    result->success = true;
    if (step.head<3>().norm() < options.convergence_rotation_rad &&
        step.tail<3>().norm() < options.convergence_translation_m) {
      break;
    }
  }
  result->iterations = std::min(result->iterations, options.max_iterations);
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
  require(plateau_iterations >= 0, "plateau_iterations", ">= 0 (0: never)");
  require(plateau_ratio >= 0.0 && plateau_ratio < 1.0, "plateau_ratio", "in [0, 1)");
  require(plateau_step_m >= 0.0 && plateau_step_rad >= 0.0, "plateau_step", ">= 0");
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
  // Pairs lie within max_correspondence_m (metres), so the nearest scene point within that radius is the nearest
  // one: a RadiusGrid finds it with fewer distance tests than the kd-tree, and gives the same pairs.
  const RadiusGrid grid(scene_points, static_cast<float>(options.max_correspondence_m));

  Iterate(object_points.size(), options, &result, [&](const Eigen::Isometry3f& transform, PointToPlaneSystem* system) {
    for (const Eigen::Vector3f& point : object_points) {
      const Eigen::Vector3f moved = transform * point;
      const int nearest = grid.NearestWithin(moved).first;
      if (nearest < 0) continue;
      const size_t index = static_cast<size_t>(nearest);
      system->Add(moved, scene_points[index], normals[index]);
    }
  });
  return result;
}

OrganizedScene MakeOrganizedScene(const cv::Mat& depth, const PinholeCamera& camera, int stride, double max_gap_m) {
  if (depth.type() != CV_32FC1 || depth.cols != camera.width || depth.rows != camera.height) {
    ThrowInputError("organized scene", "depth", "a CV_32FC1 image of the camera's size");
  }
  if (!(max_gap_m > 0.0)) ThrowInputError("organized scene", "max_gap_m", "> 0 m", std::to_string(max_gap_m));
  OrganizedScene scene;
  scene.camera = camera.Sampled(stride);
  scene.points = cv::Mat(scene.camera.height, scene.camera.width, CV_32FC3, cv::Scalar::all(0));
  scene.normals = cv::Mat(scene.camera.height, scene.camera.width, CV_32FC3, cv::Scalar::all(0));
  for (int v = 0; v < scene.points.rows; ++v) {
    for (int u = 0; u < scene.points.cols; ++u) {
      const float z = depth.at<float>(v * stride, u * stride);
      if (z <= 0.0F) continue;
      const Eigen::Vector3f point = scene.camera.BackProject(Eigen::Vector2d(u, v), z).cast<float>();
      scene.points.at<cv::Vec3f>(v, u) = cv::Vec3f(point.x(), point.y(), point.z());
    }
  }
  constexpr int kStep = 2;  // samples to either side for the normal's tangents
  const auto gap = static_cast<float>(max_gap_m);
  auto at = [&](int u, int v) {
    const cv::Vec3f& p = scene.points.at<cv::Vec3f>(v, u);
    return Eigen::Vector3f(p[0], p[1], p[2]);
  };
  for (int v = kStep; v + kStep < scene.points.rows; ++v) {
    for (int u = kStep; u + kStep < scene.points.cols; ++u) {
      const Eigen::Vector3f centre = at(u, v);
      const Eigen::Vector3f left = at(u - kStep, v), right = at(u + kStep, v);
      const Eigen::Vector3f up = at(u, v - kStep), down = at(u, v + kStep);
      const bool usable = centre.z() > 0.0F && std::abs(left.z() - centre.z()) < gap &&
                          std::abs(right.z() - centre.z()) < gap && std::abs(up.z() - centre.z()) < gap &&
                          std::abs(down.z() - centre.z()) < gap;  // missing neighbours have z = 0: too far
      if (!usable) continue;
      const Eigen::Vector3f normal = (right - left).cross(down - up);
      const float length = normal.norm();
      if (length <= 0.0F) continue;
      const Eigen::Vector3f unit = normal / length;
      scene.normals.at<cv::Vec3f>(v, u) = cv::Vec3f(unit.x(), unit.y(), unit.z());
    }
  }
  return scene;
}

IcpResult RefinePointToPlaneProjective(const std::vector<Eigen::Vector3f>& object_points, const OrganizedScene& scene,
                                       const Eigen::Isometry3d& initial, const IcpOptions& options) {
  options.Check();
  IcpResult result;
  result.scene_from_object = initial;
  if (object_points.empty() || scene.points.empty()) return result;
  const float max_squared = static_cast<float>(options.max_correspondence_m * options.max_correspondence_m);
  const PinholeCamera& camera = scene.camera;
  Iterate(object_points.size(), options, &result, [&](const Eigen::Isometry3f& transform, PointToPlaneSystem* system) {
    for (const Eigen::Vector3f& point : object_points) {
      const Eigen::Vector3f moved = transform * point;
      if (moved.z() <= 0.0F) continue;
      const int u = static_cast<int>(std::lround(camera.fx * moved.x() / moved.z() + camera.cx));
      const int v = static_cast<int>(std::lround(camera.fy * moved.y() / moved.z() + camera.cy));
      float best_squared = max_squared;
      Eigen::Vector3f target, normal;
      bool found = false;
      for (int y = std::max(v - 1, 0); y <= std::min(v + 1, camera.height - 1); ++y) {
        for (int x = std::max(u - 1, 0); x <= std::min(u + 1, camera.width - 1); ++x) {
          const cv::Vec3f& n = scene.normals.at<cv::Vec3f>(y, x);
          if (n[0] == 0.0F && n[1] == 0.0F && n[2] == 0.0F) continue;  // no depth or no normal
          const cv::Vec3f& q = scene.points.at<cv::Vec3f>(y, x);
          const Eigen::Vector3f candidate(q[0], q[1], q[2]);
          const float squared = (candidate - moved).squaredNorm();
          if (squared > best_squared) continue;
          best_squared = squared;
          target = candidate;
          normal = Eigen::Vector3f(n[0], n[1], n[2]);
          found = true;
        }
      }
      if (found) system->Add(moved, target, normal);
    }
  });
  return result;
}

}  // namespace ecv
