#include "core/frame.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "core/error.h"

namespace ecv {
namespace {

std::string SizeText(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

}  // namespace

void RgbdFrame::Check() const {
  if (color.empty() || color.type() != CV_8UC3) ThrowInputError(name, "color", "an 8-bit 3-channel RGB image");
  if (depth.empty() || depth.type() != CV_32FC1) ThrowInputError(name, "depth", "a float depth image in metres");
  if (color.size() != depth.size()) {
    ThrowInputError(name, "depth", "the colour image's size " + SizeText(color), SizeText(depth));
  }
  camera.Check(name + ": camera");
  if (camera.width != color.cols || camera.height != color.rows) {
    ThrowInputError(name, "camera", "the image size " + SizeText(color),
                    std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  for (int v = 0; v < depth.rows; ++v) {
    const float* row = depth.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!(row[u] >= 0.0F) || !std::isfinite(row[u])) {
        ThrowInputError(name, "depth", "finite values >= 0 (0 = missing)",
                        std::to_string(row[u]) + " at pixel (" + std::to_string(u) + ", " + std::to_string(v) + ")");
      }
    }
  }
}

DepthStats ComputeDepthStats(const cv::Mat& depth, const cv::Mat& mask) {
  CV_Assert(depth.type() == CV_32FC1 && (mask.empty() || mask.size() == depth.size()));
  std::vector<float> valid;
  valid.reserve(depth.total());
  for (int v = 0; v < depth.rows; ++v) {
    const float* row = depth.ptr<float>(v);
    const uchar* mask_row = mask.empty() ? nullptr : mask.ptr<uchar>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (row[u] > 0.0F && (mask_row == nullptr || mask_row[u] != 0)) valid.push_back(row[u]);
    }
  }
  DepthStats stats;
  if (valid.empty()) return stats;
  stats.valid_fraction = static_cast<double>(valid.size()) / static_cast<double>(depth.total());
  const auto [min_it, max_it] = std::minmax_element(valid.begin(), valid.end());
  stats.min_m = *min_it;
  stats.max_m = *max_it;
  std::nth_element(valid.begin(), valid.begin() + static_cast<long>(valid.size() / 2), valid.end());
  stats.median_m = valid[valid.size() / 2];
  return stats;
}

RgbdFrame TurnUpsideDown(const RgbdFrame& frame) {
  RgbdFrame turned;
  cv::rotate(frame.color, turned.color, cv::ROTATE_180);
  cv::rotate(frame.depth, turned.depth, cv::ROTATE_180);
  turned.camera = frame.camera;
  turned.camera.cx = frame.camera.width - 1 - frame.camera.cx;
  turned.camera.cy = frame.camera.height - 1 - frame.camera.cy;
  turned.name = frame.name + " (turned 180 degrees)";
  return turned;
}

RgbdFrame WithColorCast(const RgbdFrame& frame, const ColorCast& cast) {
  if (!(cast.gamma > 0.0) || !(cast.rgb_gain.minCoeff() >= 0.0) || !cast.rgb_gain.allFinite()) {
    ThrowInputError("colour cast", "gains and gamma", "finite gains >= 0 and a gamma > 0");
  }
  // One table per channel: 256 values in, 256 out.
  cv::Mat table(1, 256, CV_8UC3);
  for (int value = 0; value < 256; ++value) {
    for (int channel = 0; channel < 3; ++channel) {
      const double scaled = std::min(1.0, cast.rgb_gain[channel] * value / 255.0);
      table.at<cv::Vec3b>(0, value)[channel] = cv::saturate_cast<uchar>(255.0 * std::pow(scaled, cast.gamma));
    }
  }
  RgbdFrame cast_frame = frame;
  cast_frame.color = cv::Mat();  // a new image, not the caller's
  cv::LUT(frame.color, table, cast_frame.color);
  cast_frame.depth = frame.depth.clone();
  return cast_frame;
}

Eigen::Isometry3d TurnedFromCamera() {
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
  return turned;
}

std::vector<Eigen::Vector3f> DepthPoints(const RgbdFrame& frame, int stride) {
  std::vector<Eigen::Vector3f> points;
  for (int v = 0; v < frame.depth.rows; v += stride) {
    for (int u = 0; u < frame.depth.cols; u += stride) {
      const float z = frame.depth.at<float>(v, u);
      if (z > 0.0F) points.push_back(frame.camera.BackProject({u, v}, z).cast<float>());
    }
  }
  return points;
}

}  // namespace ecv
