#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"

namespace ecv {

/// One registered RGB-D image.
struct RgbdFrame {
  cv::Mat color;         ///< CV_8UC3, RGB order, top row first
  cv::Mat depth;         ///< CV_32FC1, metres along the optical axis, 0 = missing; same size as color
  PinholeCamera camera;  ///< intrinsics of both images
  std::string name;      ///< where it came from, for messages

  /// Throws InputError naming `name` when the images are empty, of the wrong type or of a size that
  /// differs from each other or from the camera, or when the depth holds negative or NaN values.
  void Check() const;
};

/// Summary of a depth image.
struct DepthStats {
  double valid_fraction = 0.0;  ///< pixels with depth > 0, over all pixels
  double min_m = 0.0;           ///< smallest valid depth, metres (0 if none)
  double max_m = 0.0;           ///< largest valid depth, metres (0 if none)
  double median_m = 0.0;        ///< median valid depth, metres (0 if none)
};

/// Statistics over the valid (> 0) pixels of a CV_32FC1 depth image, optionally only where `mask` != 0.
DepthStats ComputeDepthStats(const cv::Mat& depth, const cv::Mat& mask = cv::Mat());

/// The frame as the same camera rolled 180 degrees about its optical axis sees it: both images turned, the
/// principal point mirrored (c' = size - 1 - c). A point p of the frame's camera is TurnedFromCamera() * p in the
/// turned one, so a pose camera_from_object becomes TurnedFromCamera() * camera_from_object. Used to measure how
/// recognition depends on how the camera is held (recognize_bench --turned).
RgbdFrame TurnUpsideDown(const RgbdFrame& frame);

/// A change of the light's colour and of the camera's response: each channel scaled by its gain, then the 0..1
/// intensities raised to `gamma`. Used to measure how recognition depends on the light (recognize_bench --casts).
struct ColorCast {
  Eigen::Vector3d rgb_gain = Eigen::Vector3d::Ones();
  double gamma = 1.0;
};

/// The frame as a camera under the cast light sees it: colours changed by `cast` (clipped to 0..255), depth the same.
RgbdFrame WithColorCast(const RgbdFrame& frame, const ColorCast& cast);

/// diag(-1, -1, 1): the turned camera of TurnUpsideDown from the original one (its own inverse).
Eigen::Isometry3d TurnedFromCamera();

/// The frame's depth samples of every `stride`-th pixel in each direction (row by row), as camera-frame points.
std::vector<Eigen::Vector3f> DepthPoints(const RgbdFrame& frame, int stride);

}  // namespace ecv
