#include "registration/ransac.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "core/error.h"
#include "core/point_index.h"

namespace ecv {
namespace {

// Rigid motion (Kabsch/Umeyama, no scale) taking `from` onto `to`; false when degenerate.
bool FitRigid(const std::vector<Eigen::Vector3f>& from, const std::vector<Eigen::Vector3f>& to,
              Eigen::Isometry3d* result) {
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) {
    a.col(static_cast<long>(i)) = from[i].cast<double>();
    b.col(static_cast<long>(i)) = to[i].cast<double>();
  }
  const Eigen::Vector3d centred_extent = (a.colwise() - a.rowwise().mean()).rowwise().norm();
  if (centred_extent.maxCoeff() < 1e-9) return false;  // all points identical
  const Eigen::Matrix4d transform = Eigen::umeyama(a, b, false);
  if (!transform.allFinite()) return false;
  result->matrix() = transform;
  return true;
}

// Inliers of `scene_from_object`: object points within eps of their nearest scene point, with those points.
struct Inliers {
  std::vector<Eigen::Vector3f> object, scene;
  double distance_sum = 0.0;
};

Inliers FindInliers(const std::vector<Eigen::Vector3f>& object_points, const std::vector<Eigen::Vector3f>& scene_points,
                    const PointIndex& index, const Eigen::Isometry3d& scene_from_object, double eps) {
  Inliers inliers;
  const Eigen::Isometry3f transform = scene_from_object.cast<float>();
  const float eps_squared = static_cast<float>(eps * eps);
  for (const Eigen::Vector3f& point : object_points) {
    const auto [nearest, squared] = index.Nearest(transform * point);
    if (squared > eps_squared) continue;
    inliers.object.push_back(point);
    inliers.scene.push_back(scene_points[static_cast<size_t>(nearest)]);
    inliers.distance_sum += std::sqrt(squared);
  }
  return inliers;
}

}  // namespace

void RansacOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("RANSAC options", field, expected);
  };
  require(sample_size >= 3, "sample_size", "at least 3");
  require(std::isfinite(polygon_threshold) && polygon_threshold < 1.0, "polygon_threshold", "below 1 (<= 0 disables)");
  require(inlier_threshold_m > 0.0 && std::isfinite(inlier_threshold_m), "inlier_threshold_m", "> 0 m");
  require(required_inlier_fraction > 0.0 && required_inlier_fraction <= 1.0, "required_inlier_fraction", "in (0, 1]");
  require(success_probability > 0.0 && success_probability < 1.0, "success_probability", "in (0, 1)");
  require(expected_inlier_ratio > 0.0 && expected_inlier_ratio <= 1.0, "expected_inlier_ratio", "in (0, 1]");
  require(max_iterations >= 0, "max_iterations", ">= 0 (0: from p, w and n)");
}

int RansacOptions::Iterations() const {
  if (max_iterations > 0) return max_iterations;
  const double good_sample = std::pow(expected_inlier_ratio, sample_size);
  if (good_sample >= 1.0) return 1;
  return static_cast<int>(std::ceil(std::log(1.0 - success_probability) / std::log(1.0 - good_sample)));
}

bool PolygonEdgeCheck::operator()(const std::vector<Eigen::Vector3f>& object_sample,
                                  const std::vector<Eigen::Vector3f>& scene_sample) const {
  const size_t n = object_sample.size();
  for (size_t i = 0; i < n; ++i) {
    const float d_p = (object_sample[(i + 1) % n] - object_sample[i]).norm();
    const float d_q = (scene_sample[(i + 1) % n] - scene_sample[i]).norm();
    const float longer = std::max(d_p, d_q);
    if (longer <= 0.0F || std::abs(d_p - d_q) / longer > threshold_) return false;
  }
  return true;
}

RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  RansacResult result;
  const int n = options.sample_size;
  if (static_cast<int>(correspondences.size()) < n || object_points.empty() || scene_points.empty()) return result;
  for (const Correspondence& c : correspondences) {
    if (c.object < 0 || c.scene < 0 || c.object >= static_cast<int>(object_points.size()) ||
        c.scene >= static_cast<int>(scene_points.size())) {
      ThrowInputError("RANSAC", "correspondences", "indices inside the point sets");
    }
  }
  const PointIndex tree(scene_points);

  const PolygonEdgeCheck polygon(options.polygon_threshold);
  std::mt19937_64 random(options.seed);
  std::uniform_int_distribution<size_t> pick(0, correspondences.size() - 1);
  std::vector<Eigen::Vector3f> object_sample(static_cast<size_t>(n)), scene_sample(static_cast<size_t>(n));
  const size_t required = static_cast<size_t>(std::ceil(options.required_inlier_fraction * object_points.size()));
  double best_error = std::numeric_limits<double>::max();
  const int iterations = options.Iterations();
  for (result.iterations = 0; result.iterations < iterations;) {
    ++result.iterations;
    for (int k = 0; k < n; ++k) {
      const Correspondence& c = correspondences[pick(random)];
      object_sample[static_cast<size_t>(k)] = object_points[static_cast<size_t>(c.object)];
      scene_sample[static_cast<size_t>(k)] = scene_points[static_cast<size_t>(c.scene)];
    }
    if (options.polygon_threshold > 0.0 && !polygon(object_sample, scene_sample)) {
      ++result.rejected_by_polygon;
      continue;
    }
    Eigen::Isometry3d hypothesis;
    if (!FitRigid(object_sample, scene_sample, &hypothesis)) continue;
    Inliers inliers = FindInliers(object_points, scene_points, tree, hypothesis, options.inlier_threshold_m);
    if (inliers.object.size() < required || inliers.object.size() < 3) continue;
    if (!FitRigid(inliers.object, inliers.scene, &hypothesis)) continue;  // re-estimate on the inliers
    inliers = FindInliers(object_points, scene_points, tree, hypothesis, options.inlier_threshold_m);
    if (inliers.object.size() < required || inliers.object.empty()) continue;
    const double error = inliers.distance_sum / static_cast<double>(inliers.object.size());
    if (error < best_error) {
      best_error = error;
      result.success = true;
      result.scene_from_object = hypothesis;
      result.inlier_fraction = static_cast<double>(inliers.object.size()) / static_cast<double>(object_points.size());
      result.fit_error_m = error;
      if (options.early_stop_fit_error_m > 0.0 && error < options.early_stop_fit_error_m) break;
    }
  }
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace ecv
