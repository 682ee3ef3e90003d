#include "ecv/draw.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace ecv {

cv::Mat DrawPrimitives(const cv::Mat& rgb, const std::vector<Primitive>& primitives, double stroke_px) {
  CV_Assert(rgb.type() == CV_8UC3);
  cv::Mat canvas;
  rgb.convertTo(canvas, CV_8UC3, 0.6);
  const cv::Scalar blue(40, 90, 255), green(40, 220, 60);  // RGB order
  constexpr int kShift = 4;                                // sub-pixel drawing
  const double scale = 1 << kShift;
  for (const Primitive& primitive : primitives) {
    const cv::Point centre(static_cast<int>(std::lround(primitive.pixel.x() * scale)),
                           static_cast<int>(std::lround(primitive.pixel.y() * scale)));
    if (primitive.type == PrimitiveType::kSegment) {
      // Along the edge: perpendicular to the monogenic orientation.
      const double dx = -std::sin(primitive.image_orientation) * stroke_px * scale;
      const double dy = std::cos(primitive.image_orientation) * stroke_px * scale;
      const cv::Point offset(static_cast<int>(std::lround(dx)), static_cast<int>(std::lround(dy)));
      cv::line(canvas, centre - offset, centre + offset, blue, 2, cv::LINE_AA, kShift);
    } else {
      cv::circle(canvas, centre, static_cast<int>(1.5 * scale), green, cv::FILLED, cv::LINE_AA, kShift);
    }
  }
  return canvas;
}

}  // namespace ecv
