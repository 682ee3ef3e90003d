#include "core/camera.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/error.h"

namespace ecv {
namespace {

void CheckPositive(const std::string& source, const char* field, double value, const char* unit) {
  if (!std::isfinite(value) || value <= 0.0) {
    ThrowInputError(source, field, std::string("a finite positive value in ") + unit, std::to_string(value));
  }
}

// Solves image_coordinate = focal * ratio + centre in the least-squares sense.
Eigen::Vector2d FitAxis(const std::vector<double>& ratios, const std::vector<double>& pixels) {
  Eigen::MatrixX2d a(ratios.size(), 2);
  Eigen::VectorXd b(ratios.size());
  for (size_t i = 0; i < ratios.size(); ++i) {
    a(i, 0) = ratios[i];
    a(i, 1) = 1.0;
    b(i) = pixels[i];
  }
  return a.colPivHouseholderQr().solve(b);
}

}  // namespace

void PinholeCamera::Check(const std::string& source) const {
  CheckPositive(source, "fx", fx, "pixels");
  CheckPositive(source, "fy", fy, "pixels");
  if (!std::isfinite(cx)) ThrowInputError(source, "cx", "a finite principal point in pixels", std::to_string(cx));
  if (!std::isfinite(cy)) ThrowInputError(source, "cy", "a finite principal point in pixels", std::to_string(cy));
  if (width <= 0 || height <= 0) {
    ThrowInputError(source, "width/height", "a positive image size",
                    std::to_string(width) + "x" + std::to_string(height));
  }
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Vector2d PinholeCamera::Project(const Eigen::Vector3d& point_camera) const {
  return {fx * point_camera.x() / point_camera.z() + cx, fy * point_camera.y() / point_camera.z() + cy};
}

Eigen::Vector3d PinholeCamera::BackProject(const Eigen::Vector2d& pixel, double z) const {
  return {(pixel.x() - cx) * z / fx, (pixel.y() - cy) * z / fy, z};
}

bool PinholeCamera::Contains(const Eigen::Vector2d& pixel) const {
  return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < width - 0.5 && pixel.y() < height - 0.5;
}

PinholeCamera PinholeCamera::Sampled(int stride) const {
  if (stride < 1) ThrowInputError("camera", "stride", "at least 1", std::to_string(stride));
  PinholeCamera sampled = *this;
  const double scale = 1.0 / stride;
  sampled.fx *= scale;
  sampled.fy *= scale;
  sampled.cx *= scale;
  sampled.cy *= scale;
  sampled.width = (width + stride - 1) / stride;
  sampled.height = (height + stride - 1) / stride;
  return sampled;
}

CameraFit FitPinholeCamera(const cv::Mat& organized_points, const std::string& source) {
  if (organized_points.type() != CV_32FC3) {
    ThrowInputError(source, "points", "an organized CV_32FC3 cloud");
  }
  std::vector<double> x_over_z, y_over_z, us, vs;
  for (int v = 0; v < organized_points.rows; ++v) {
    for (int u = 0; u < organized_points.cols; ++u) {
      const cv::Vec3f& p = organized_points.at<cv::Vec3f>(v, u);
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) || p[2] <= 0.0F) continue;
      x_over_z.push_back(p[0] / p[2]);
      y_over_z.push_back(p[1] / p[2]);
      us.push_back(u);
      vs.push_back(v);
    }
  }
  if (us.size() < 3) ThrowInputError(source, "points", "at least 3 valid points", std::to_string(us.size()));
  const auto [min_x, max_x] = std::minmax_element(x_over_z.begin(), x_over_z.end());
  const auto [min_y, max_y] = std::minmax_element(y_over_z.begin(), y_over_z.end());
  if (*max_x - *min_x < 1e-9 || *max_y - *min_y < 1e-9) {
    ThrowInputError(source, "points", "points spread over the image to fit intrinsics");
  }

  const Eigen::Vector2d fit_x = FitAxis(x_over_z, us);
  const Eigen::Vector2d fit_y = FitAxis(y_over_z, vs);
  CameraFit fit;
  fit.camera = {fit_x[0], fit_y[0], fit_x[1], fit_y[1], organized_points.cols, organized_points.rows};
  fit.num_points = static_cast<int>(us.size());
  double sum_squared = 0.0;
  for (size_t i = 0; i < us.size(); ++i) {
    const double du = fit.camera.fx * x_over_z[i] + fit.camera.cx - us[i];
    const double dv = fit.camera.fy * y_over_z[i] + fit.camera.cy - vs[i];
    const double squared = du * du + dv * dv;
    sum_squared += squared;
    fit.max_reprojection_px = std::max(fit.max_reprojection_px, std::sqrt(squared));
  }
  fit.rms_reprojection_px = std::sqrt(sum_squared / static_cast<double>(us.size()));
  return fit;
}

}  // namespace ecv
