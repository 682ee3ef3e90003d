#include "registration/registration_draw.h"

#include <cmath>

namespace ecv {

cv::Mat DrawAlignedFrame(const RgbdFrame& a, const RgbdFrame& b, const Eigen::Isometry3d& b_from_a, double opacity,
                         double tolerance_m, int square_px) {
  a.Check();
  b.Check();
  // Nearest depth of A's surface seen from B, then a blend where it is not hidden behind B's surface.
  cv::Mat nearest(b.depth.size(), CV_32FC1, cv::Scalar(0.0F));
  cv::Mat moved_color(b.color.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int v = 0; v < a.depth.rows; ++v) {
    for (int u = 0; u < a.depth.cols; ++u) {
      const float z = a.depth.at<float>(v, u);
      if (z <= 0.0F) continue;
      const Eigen::Vector3d point = b_from_a * a.camera.BackProject({u, v}, z);
      if (point.z() <= 0.0) continue;
      const Eigen::Vector2d pixel = b.camera.Project(point);
      if (!b.camera.Contains(pixel)) continue;
      const int row = static_cast<int>(std::lround(pixel.y())), column = static_cast<int>(std::lround(pixel.x()));
      float& depth = nearest.at<float>(row, column);
      if (depth == 0.0F || point.z() < depth) {
        depth = static_cast<float>(point.z());
        moved_color.at<cv::Vec3b>(row, column) = a.color.at<cv::Vec3b>(v, u);
      }
    }
  }
  cv::Mat picture = b.color.clone();
  for (int v = 0; v < picture.rows; ++v) {
    for (int u = 0; u < picture.cols; ++u) {
      const float z = nearest.at<float>(v, u), scene = b.depth.at<float>(v, u);
      if (z <= 0.0F || (scene > 0.0F && z > scene + tolerance_m)) continue;
      if (((u / square_px) + (v / square_px)) % 2 == 0) continue;  // B's own pixels in every other square
      const cv::Vec3b& source = moved_color.at<cv::Vec3b>(v, u);
      picture.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<uchar>((1.0 - opacity) * source[0] + opacity * 255.0),
                    static_cast<uchar>((1.0 - opacity) * source[1]), static_cast<uchar>((1.0 - opacity) * source[2]));
    }
  }
  return picture;
}

}  // namespace ecv
