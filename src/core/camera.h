#pragma once

#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ecv {

/// A pinhole camera without distortion, OpenCV convention: x right, y down, z forward; pixel
/// (0, 0) is the centre of the top-left pixel.
struct PinholeCamera {
  double fx = 0.0;  ///< focal length along x, pixels
  double fy = 0.0;  ///< focal length along y, pixels
  double cx = 0.0;  ///< principal point x, pixels
  double cy = 0.0;  ///< principal point y, pixels
  int width = 0;    ///< image width, pixels
  int height = 0;   ///< image height, pixels

  /// Throws InputError naming `source` when a value is not finite, a focal length is not positive or
  /// the image size is not positive.
  void Check(const std::string& source = "camera") const;

  /// 3x3 intrinsic matrix K.
  Eigen::Matrix3d K() const;

  /// Pixel of a camera-frame point (metres); the point must have z > 0.
  Eigen::Vector2d Project(const Eigen::Vector3d& point_camera) const;

  /// Camera-frame point (metres) seen at `pixel` with depth `z` (metres along the optical axis).
  Eigen::Vector3d BackProject(const Eigen::Vector2d& pixel, double z) const;

  /// True when `pixel` lies inside the image (pixel centres 0 .. width-1, 0 .. height-1, ±0.5).
  bool Contains(const Eigen::Vector2d& pixel) const;

  /// The camera of every `stride`-th pixel: its pixel (u, v) sees along the ray of this camera's pixel
  /// (stride u, stride v), so an image made for it equals every stride-th pixel of one made for this camera.
  PinholeCamera Sampled(int stride) const;
};

/// Result of fitting a pinhole camera to an organized point cloud.
struct CameraFit {
  PinholeCamera camera;
  int num_points = 0;                ///< valid points used
  double rms_reprojection_px = 0.0;  ///< RMS distance of re-projected points to their own pixel
  double max_reprojection_px = 0.0;  ///< largest such distance
};

/// Least-squares intrinsics from an organized cloud (CV_32FC3, camera-frame metres, NaN or z <= 0 for
/// missing): u = fx x/z + cx and v = fy y/z + cy solved over all valid pixels. Throws InputError when
/// fewer than 3 valid points or the points span no range in x/z or y/z.
CameraFit FitPinholeCamera(const cv::Mat& organized_points, const std::string& source = "point cloud");

}  // namespace ecv
