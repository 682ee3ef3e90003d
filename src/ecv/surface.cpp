#include "ecv/surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Eigenvalues>

namespace ecv {
namespace {

constexpr int kDepthWindow = 2;      // FrontSurfaceDepth looks at a (2k+1)^2 window
constexpr int kMaxPlaneWindow = 24;  // pixels; bounds the plane-fit window at close range
constexpr int kMinPlanePoints = 6;

// Unit plane normal of `points`, facing the camera at the origin.
Eigen::Vector3f FitNormal(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& towards) {
  Eigen::Vector3f normal = FitPlane(points).normal;
  if (normal.dot(towards) > 0.0F) normal = -normal;
  return normal;
}

Eigen::Vector3f Ray(const PinholeCamera& camera, const Eigen::Vector2f& pixel) {
  return camera.BackProject(pixel.cast<double>(), 1.0).cast<float>();
}

}  // namespace

Plane FitPlane(const std::vector<Eigen::Vector3f>& points) {
  Plane plane;
  for (const Eigen::Vector3f& p : points) plane.centroid += p;
  plane.centroid /= static_cast<float>(points.size());
  Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
  for (const Eigen::Vector3f& p : points) covariance += (p - plane.centroid) * (p - plane.centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> solver(covariance);
  plane.normal = solver.eigenvectors().col(0).normalized();
  return plane;
}

std::optional<float> FrontSurfaceDepth(const cv::Mat& depth, const cv::Point& pixel, double depth_gap_m) {
  float values[(2 * kDepthWindow + 1) * (2 * kDepthWindow + 1)];
  int count = 0;
  float nearest = std::numeric_limits<float>::max();
  for (int y = std::max(0, pixel.y - kDepthWindow); y <= std::min(depth.rows - 1, pixel.y + kDepthWindow); ++y) {
    const float* row = depth.ptr<float>(y);
    for (int x = std::max(0, pixel.x - kDepthWindow); x <= std::min(depth.cols - 1, pixel.x + kDepthWindow); ++x) {
      if (row[x] > 0.0F) {
        values[count++] = row[x];
        nearest = std::min(nearest, row[x]);
      }
    }
  }
  if (count == 0) return std::nullopt;
  const float limit = nearest + static_cast<float>(depth_gap_m);
  float* end = std::remove_if(values, values + count, [limit](float z) { return z > limit; });
  const long n = end - values;
  std::nth_element(values, values + n / 2, end);
  return values[n / 2];
}

std::optional<LocalSurface> ReconstructSurface(const RgbdFrame& frame, const cv::Point& pixel,
                                               const SurfaceOptions& options) {
  const std::optional<float> z = FrontSurfaceDepth(frame.depth, pixel, options.depth_gap_m);
  if (!z) return std::nullopt;
  const PinholeCamera& camera = frame.camera;
  LocalSurface surface;
  surface.position = camera.BackProject(Eigen::Vector2d(pixel.x, pixel.y), *z).cast<float>();

  // Colour: mean over the small window on this surface.
  const float gap = static_cast<float>(options.depth_gap_m);
  Eigen::Vector3f color_sum = Eigen::Vector3f::Zero();
  int color_count = 0;
  const int r = options.color_radius_px;
  for (int y = std::max(0, pixel.y - r); y <= std::min(frame.depth.rows - 1, pixel.y + r); ++y) {
    for (int x = std::max(0, pixel.x - r); x <= std::min(frame.depth.cols - 1, pixel.x + r); ++x) {
      const float d = frame.depth.at<float>(y, x);
      if (d <= 0.0F || std::abs(d - *z) > gap) continue;
      const cv::Vec3b& c = frame.color.at<cv::Vec3b>(y, x);
      color_sum += Eigen::Vector3f(c[0], c[1], c[2]);
      ++color_count;
    }
  }
  const cv::Vec3b& centre = frame.color.at<cv::Vec3b>(pixel);
  surface.color = color_count > 0 ? Eigen::Vector3f(color_sum / (255.0F * static_cast<float>(color_count)))
                                  : Eigen::Vector3f(centre[0], centre[1], centre[2]) / 255.0F;

  // Plane over the points within radius_m, sampled on a grid of at most 9x9 pixels.
  const int window = std::clamp(static_cast<int>(std::ceil(options.radius_m * camera.fx / *z)), 2, kMaxPlaneWindow);
  const int step = std::max(1, (window + 3) / 4);
  const float radius_squared = static_cast<float>(options.radius_m * options.radius_m);
  std::vector<Eigen::Vector3f> points;
  points.reserve(81);
  for (int y = pixel.y - window; y <= pixel.y + window; y += step) {
    if (y < 0 || y >= frame.depth.rows) continue;
    for (int x = pixel.x - window; x <= pixel.x + window; x += step) {
      if (x < 0 || x >= frame.depth.cols) continue;
      const float d = frame.depth.at<float>(y, x);
      if (d <= 0.0F) continue;
      const Eigen::Vector3f point = camera.BackProject(Eigen::Vector2d(x, y), d).cast<float>();
      if ((point - surface.position).squaredNorm() <= radius_squared) points.push_back(point);
    }
  }
  surface.normal = points.size() >= kMinPlanePoints ? FitNormal(points, surface.position) : Eigen::Vector3f::Zero();
  return surface;
}

Eigen::Vector3f EdgeDirection(const PinholeCamera& camera, const Eigen::Vector2f& pixel, float image_orientation,
                              const LocalSurface& surface) {
  // The edge runs perpendicular to the monogenic orientation in the image.
  const Eigen::Vector2f along(-std::sin(image_orientation), std::cos(image_orientation));
  const Eigen::Vector3f ray_a = Ray(camera, pixel - 2.0F * along), ray_b = Ray(camera, pixel + 2.0F * along);
  const Eigen::Vector3f fronto_parallel = (ray_b - ray_a).normalized();
  if (surface.normal.isZero()) return fronto_parallel;
  const Eigen::Vector3f interpretation_normal = ray_a.cross(ray_b).normalized();
  const Eigen::Vector3f direction = surface.normal.cross(interpretation_normal);
  const float length = direction.norm();
  if (length < 0.2F) return fronto_parallel;  // surface nearly contains the viewing rays: seen edge-on
  return direction / length;
}

}  // namespace ecv
