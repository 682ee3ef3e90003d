// Cutting an object from a frame by its labels and reprojecting its pixels into another camera.

#include "scenes/composite_warp.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/point_index.h"

namespace ecv::bench {
namespace {

constexpr int kFillPasses = 10;  // passes of 5x5 interpolation into the cut's depth holes
constexpr int kHoleReachPx = 5;  // a hole in a target object's depth takes the nearest depth this far around it

// `known` (CV_32F, 0 = unknown) with the unknown pixels of `mask` filled by the mean of known 5x5 neighbours,
// growing inwards pass by pass.
cv::Mat FillHoles(const cv::Mat& known, const cv::Mat& mask) {
  cv::Mat filled = known.clone();
  for (int pass = 0; pass < kFillPasses; ++pass) {
    const cv::Mat valid = filled > 0.0F;
    cv::Mat valid_float, sum, count;
    valid.convertTo(valid_float, CV_32F, 1.0 / 255.0);
    cv::boxFilter(filled, sum, CV_32F, cv::Size(5, 5), cv::Point(-1, -1), false);
    cv::boxFilter(valid_float, count, CV_32F, cv::Size(5, 5), cv::Point(-1, -1), false);
    bool grew = false;
    for (int v = 0; v < filled.rows; ++v) {
      for (int u = 0; u < filled.cols; ++u) {
        if (mask.at<uint8_t>(v, u) == 0 || valid.at<uint8_t>(v, u) != 0 || count.at<float>(v, u) < 0.5F) continue;
        filled.at<float>(v, u) = sum.at<float>(v, u) / count.at<float>(v, u);
        grew = true;
      }
    }
    if (!grew) break;
  }
  return filled;
}

// Fills the empty pixels of `warp` with at least 5 of 8 filled neighbours by their mean.
void FillCracks(Warp* warp) {
  const cv::Mat depth = warp->depth.clone(), color = warp->color.clone(), measured = warp->measured.clone();
  const int v_end = std::min(warp->box.y + warp->box.height, depth.rows - 1);
  const int u_end = std::min(warp->box.x + warp->box.width, depth.cols - 1);
  for (int v = std::max(warp->box.y, 1); v < v_end; ++v) {
    for (int u = std::max(warp->box.x, 1); u < u_end; ++u) {
      if (depth.at<float>(v, u) > 0.0F) continue;
      int count = 0, all_measured = 1;
      double z = 0.0;
      cv::Vec3d rgb(0.0, 0.0, 0.0);
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          if (depth.at<float>(v + dv, u + du) <= 0.0F) continue;
          ++count;
          z += depth.at<float>(v + dv, u + du);
          rgb += cv::Vec3d(color.at<cv::Vec3b>(v + dv, u + du));
          all_measured &= measured.at<uint8_t>(v + dv, u + du);
        }
      }
      if (count < 5) continue;
      warp->depth.at<float>(v, u) = static_cast<float>(z / count);
      warp->color.at<cv::Vec3b>(v, u) = cv::Vec3b(rgb / count);
      warp->measured.at<uint8_t>(v, u) = static_cast<uint8_t>(all_measured);
    }
  }
}

}  // namespace

Cut CutObject(const SourceFrame& source, const GroundTruth& truth, const std::vector<Eigen::Vector3d>& model_points,
              const CompositeOptions& options) {
  const RgbdFrame& rgbd = source.frame.rgbd;
  std::vector<Eigen::Vector3f> surface;
  for (const Eigen::Vector3d& point : model_points) surface.push_back((truth.camera_from_object * point).cast<float>());
  const PointIndex surface_index(surface);
  const float max_squared = static_cast<float>(options.max_surface_distance_m * options.max_surface_distance_m);
  cv::Mat mask = source.labels == truth.object_id;
  const double median = ComputeDepthStats(rgbd.depth, mask).median_m;
  cv::Mat known(rgbd.depth.size(), CV_32F, cv::Scalar(0.0));
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      const float z = rgbd.depth.at<float>(v, u);
      if (mask.at<uint8_t>(v, u) == 0 || z <= 0.0F) continue;
      const Eigen::Vector3f point = rgbd.camera.BackProject(Eigen::Vector2d(u, v), z).cast<float>();
      if (std::abs(z - median) > options.max_label_depth_m || surface_index.Nearest(point).second > max_squared) {
        mask.at<uint8_t>(v, u) = 0;  // label noise or a pixel on the object's outline mixing it with what is behind
      } else {
        known.at<float>(v, u) = z;
      }
    }
  }
  const cv::Mat filled = FillHoles(known, mask);
  Cut cut;
  for (int v = 0; v < mask.rows; ++v) {
    for (int u = 0; u < mask.cols; ++u) {
      const float z = filled.at<float>(v, u);
      if (mask.at<uint8_t>(v, u) == 0 || z <= 0.0F) continue;
      cut.points.push_back(rgbd.camera.BackProject(Eigen::Vector2d(u, v), z));
      cut.colors.push_back(rgbd.color.at<cv::Vec3b>(v, u));
      cut.measured.push_back(known.at<float>(v, u) > 0.0F ? 1 : 0);
    }
  }
  return cut;
}

double WholeShare(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& camera_from_object,
                  const SourceFrame& source, int class_index) {
  cv::Mat near;
  cv::dilate(source.labels == class_index, near, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  const PinholeCamera& camera = source.frame.rgbd.camera;
  int covered = 0;
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector3d in_camera = camera_from_object * point;
    if (in_camera.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.Project(in_camera);
    if (!camera.Contains(pixel)) continue;
    const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
    covered += near.at<uint8_t>(std::clamp(v, 0, near.rows - 1), std::clamp(u, 0, near.cols - 1)) != 0 ? 1 : 0;
  }
  return points.empty() ? 0.0 : static_cast<double>(covered) / static_cast<double>(points.size());
}

Warp WarpCut(const Cut& cut, const Eigen::Isometry3d& target_from_source, const PinholeCamera& camera,
             double tolerance_m) {
  Warp warp;
  const cv::Size size(camera.width, camera.height);
  warp.depth = cv::Mat::zeros(size, CV_32F);
  warp.color = cv::Mat::zeros(size, CV_8UC3);
  warp.measured = cv::Mat::zeros(size, CV_8U);
  warp.points = static_cast<int>(cut.points.size());
  std::vector<Eigen::Vector3d> moved(cut.points.size());
  std::vector<Eigen::Vector2d> pixels(cut.points.size());
  cv::Point low(size.width, size.height), high(-1, -1);
  for (size_t i = 0; i < cut.points.size(); ++i) {
    moved[i] = target_from_source * cut.points[i];
    if (moved[i].z() <= 0.0) continue;
    pixels[i] = camera.Project(moved[i]);
    if (!camera.Contains(pixels[i])) continue;
    ++warp.inside;
    low = cv::Point(std::min<int>(low.x, std::floor(pixels[i].x())), std::min<int>(low.y, std::floor(pixels[i].y())));
    high = cv::Point(std::max<int>(high.x, std::ceil(pixels[i].x())), std::max<int>(high.y, std::ceil(pixels[i].y())));
  }
  warp.box = cv::Rect(low, high + cv::Point(1, 1)) & cv::Rect(cv::Point(0, 0), size);
  // Pass 0 finds each pixel's nearest splat, pass 1 picks its colour among the splats close to it in depth.
  cv::Mat nearest(size, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  cv::Mat centre_distance = nearest.clone();
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t i = 0; i < cut.points.size(); ++i) {
      if (moved[i].z() <= 0.0 || !camera.Contains(pixels[i])) continue;
      const int u0 = static_cast<int>(std::floor(pixels[i].x())), v0 = static_cast<int>(std::floor(pixels[i].y()));
      const float z = static_cast<float>(moved[i].z());
      for (int v = std::max(v0, 0); v <= std::min(v0 + 1, size.height - 1); ++v) {
        for (int u = std::max(u0, 0); u <= std::min(u0 + 1, size.width - 1); ++u) {
          float& near = nearest.at<float>(v, u);
          const float distance = static_cast<float>((pixels[i] - Eigen::Vector2d(u, v)).squaredNorm());
          if (pass == 0) near = std::min(near, z);
          if (pass == 0 || z > near + tolerance_m || distance >= centre_distance.at<float>(v, u)) continue;
          centre_distance.at<float>(v, u) = distance;
          warp.depth.at<float>(v, u) = z;
          warp.color.at<cv::Vec3b>(v, u) = cut.colors[i];
          warp.measured.at<uint8_t>(v, u) = cut.measured[i];
        }
      }
    }
  }
  FillCracks(&warp);
  return warp;
}

cv::Mat ShownMask(const Warp& warp, const cv::Mat& target_depth, const cv::Mat& target_labels, double tolerance_m) {
  cv::Mat shown = cv::Mat::zeros(warp.depth.size(), CV_8U);
  if (warp.box.empty()) return shown;
  // The holes of the target's labelled objects take the nearest depth around them (those along an outline belong to
  // the object in front).
  const cv::Rect around =
      (warp.box + cv::Size(2 * kHoleReachPx, 2 * kHoleReachPx) - cv::Point(kHoleReachPx, kHoleReachPx)) &
      cv::Rect(cv::Point(0, 0), target_depth.size());
  cv::Mat measured = target_depth(around).clone(), nearest_around;
  measured.setTo(std::numeric_limits<float>::infinity(), measured <= 0.0F);
  const cv::Size window(2 * kHoleReachPx + 1, 2 * kHoleReachPx + 1);
  cv::erode(measured, nearest_around, cv::getStructuringElement(cv::MORPH_RECT, window));
  for (int v = warp.box.y; v < warp.box.y + warp.box.height; ++v) {
    for (int u = warp.box.x; u < warp.box.x + warp.box.width; ++u) {
      const float z = warp.depth.at<float>(v, u), behind = nearest_around.at<float>(v - around.y, u - around.x);
      const float measured_z = target_depth.at<float>(v, u);
      const float target = measured_z > 0.0F || target_labels.at<uint8_t>(v, u) == 0 ? measured_z : behind;
      if (z > 0.0F && (target <= 0.0F || z < target + tolerance_m)) shown.at<uint8_t>(v, u) = 255;
    }
  }
  return shown;
}

}  // namespace ecv::bench
