#include "render/sensor_noise.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ecv {
namespace {

const char* const kSource = "sensor noise options";

void RequireNonNegative(double value, const char* field) {
  if (!(value >= 0.0) || !std::isfinite(value)) {
    ThrowInputError(kSource, field, "a finite value >= 0", std::to_string(value));
  }
}

void RequireProbability(double value, const char* field) {
  if (!(value >= 0.0 && value <= 1.0))
    ThrowInputError(kSource, field, "a probability in [0, 1]", std::to_string(value));
}

// Valid pixels next to (4-neighbourhood) a missing pixel or a depth step above `jump_m`, widened by
// `width_px`.
cv::Mat EdgeZone(const cv::Mat& depth, double jump_m, int width_px) {
  cv::Mat edges = cv::Mat::zeros(depth.size(), CV_8UC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      const int neighbours[4][2] = {{v - 1, u}, {v + 1, u}, {v, u - 1}, {v, u + 1}};
      for (const auto& [nv, nu] : neighbours) {
        if (nv < 0 || nu < 0 || nv >= depth.rows || nu >= depth.cols) continue;
        const float other = depth.at<float>(nv, nu);
        if (other <= 0.0F || std::abs(other - z) > jump_m) edges.at<uint8_t>(v, u) = 255;
      }
    }
  }
  if (width_px > 1) {
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * width_px - 1, 2 * width_px - 1));
    cv::dilate(edges, edges, kernel);
  }
  return edges;
}

// Cosine of the angle between the surface normal (from central differences of back-projected depth)
// and the viewing ray at interior pixel (u, v); 1 when a neighbour is missing.
double IncidenceCosine(const cv::Mat& depth, const PinholeCamera& camera, int u, int v) {
  auto point = [&](int pu, int pv) { return camera.BackProject({pu, pv}, depth.at<float>(pv, pu)); };
  if (depth.at<float>(v, u - 1) <= 0.0F || depth.at<float>(v, u + 1) <= 0.0F || depth.at<float>(v - 1, u) <= 0.0F ||
      depth.at<float>(v + 1, u) <= 0.0F) {
    return 1.0;
  }
  const Eigen::Vector3d normal = (point(u + 1, v) - point(u - 1, v)).cross(point(u, v + 1) - point(u, v - 1));
  const Eigen::Vector3d ray = point(u, v);
  const double norms = normal.norm() * ray.norm();
  return norms > 0.0 ? std::abs(normal.dot(ray)) / norms : 1.0;
}

// Depth z (metres) with axial noise of `standard_normal` standard deviations, then quantised in disparity
// (Kinect: disparity = fx b / z in steps of 1/8 pixel); 0 when nothing is left.
double NoisyDepth(double z, const SensorNoiseOptions& options, double focal_baseline, double standard_normal) {
  const double offset = z - options.axial_sigma_offset_m;
  const double sigma = options.axial_sigma_base_m + options.axial_sigma_quadratic_per_m * offset * offset;
  const double noisy = z + sigma * standard_normal;
  if (focal_baseline <= 0.0 || noisy <= 0.0) return std::max(noisy, 0.0);
  const double disparity = std::round(focal_baseline / noisy / options.disparity_step_px) * options.disparity_step_px;
  return disparity > 0.0 ? focal_baseline / disparity : 0.0;
}

}  // namespace

void SensorNoiseOptions::Check() const {
  RequireNonNegative(axial_sigma_base_m, "axial_sigma_base_m");
  RequireNonNegative(axial_sigma_quadratic_per_m, "axial_sigma_quadratic_per_m");
  RequireNonNegative(axial_sigma_offset_m, "axial_sigma_offset_m");
  RequireNonNegative(baseline_m, "baseline_m");
  RequireNonNegative(edge_jump_m, "edge_jump_m");
  if (!(disparity_step_px > 0.0) || !std::isfinite(disparity_step_px)) {
    ThrowInputError(kSource, "disparity_step_px", "a positive number of pixels", std::to_string(disparity_step_px));
  }
  if (!(max_incidence_rad > 0.0 && max_incidence_rad <= M_PI / 2)) {
    ThrowInputError(kSource, "max_incidence_rad", "an angle in (0, pi/2]", std::to_string(max_incidence_rad));
  }
  if (edge_width_px < 0) ThrowInputError(kSource, "edge_width_px", "a value >= 0", std::to_string(edge_width_px));
  RequireProbability(edge_dropout, "edge_dropout");
  RequireProbability(random_dropout, "random_dropout");
}

SensorNoiseResult SimulateStructuredLight(const cv::Mat& depth, const PinholeCamera& camera,
                                          const SensorNoiseOptions& options) {
  options.Check();
  camera.Check("sensor noise camera");
  if (depth.type() != CV_32FC1 || depth.cols != camera.width || depth.rows != camera.height) {
    ThrowInputError("sensor noise", "depth", "a CV_32FC1 image of the camera's size");
  }
  const cv::Mat edges = options.edge_width_px > 0 ? EdgeZone(depth, options.edge_jump_m, options.edge_width_px)
                                                  : cv::Mat::zeros(depth.size(), CV_8UC1);
  const double min_cosine = std::cos(options.max_incidence_rad);
  const double focal_baseline = camera.fx * options.baseline_m;  // disparity (px) = fx b / z
  std::mt19937 random(options.seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::normal_distribution<double> gaussian(0.0, 1.0);

  SensorNoiseResult result;
  result.depth = cv::Mat::zeros(depth.size(), CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const double z = depth.at<float>(v, u);
      if (z <= 0.0) continue;
      const bool edge = edges.at<uint8_t>(v, u) != 0;
      const double draw = uniform(random);
      const bool interior = u > 0 && v > 0 && u + 1 < depth.cols && v + 1 < depth.rows;
      const bool steep = interior && IncidenceCosine(depth, camera, u, v) < min_cosine;
      if (steep || draw < (edge ? options.edge_dropout : options.random_dropout)) {
        ++result.dropped_pixels;
        continue;
      }
      const double noisy = NoisyDepth(z, options, focal_baseline, gaussian(random));
      if (noisy > 0.0) {
        result.depth.at<float>(v, u) = static_cast<float>(noisy);
      } else {
        ++result.dropped_pixels;
      }
    }
  }
  return result;
}

}  // namespace ecv
