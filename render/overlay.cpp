#include "render/overlay.h"

#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace ecv {
namespace {

const char* const kSource = "overlay options";

void RequireColor(const Eigen::Vector3f& color, const char* field) {
  if (!color.allFinite() || color.minCoeff() < 0.0F || color.maxCoeff() > 1.0F) {
    ThrowInputError(kSource, field, "RGB in [0, 1]");
  }
}

cv::Scalar ToPixel(const Eigen::Vector3f& color) {
  return {std::round(255.0 * color.x()), std::round(255.0 * color.y()), std::round(255.0 * color.z())};
}

// Pixels of an object whose 4-neighbour shows another label (or the image border), widened to `width`.
cv::Mat Outline(const cv::Mat& labels, int width) {
  cv::Mat outline = cv::Mat::zeros(labels.size(), CV_8UC1);
  for (int v = 0; v < labels.rows; ++v) {
    for (int u = 0; u < labels.cols; ++u) {
      const uint16_t label = labels.at<uint16_t>(v, u);
      if (label == 0) continue;
      const bool border = u == 0 || v == 0 || u + 1 == labels.cols || v + 1 == labels.rows;
      if (border || labels.at<uint16_t>(v - 1, u) != label || labels.at<uint16_t>(v + 1, u) != label ||
          labels.at<uint16_t>(v, u - 1) != label || labels.at<uint16_t>(v, u + 1) != label) {
        outline.at<uint8_t>(v, u) = 255;
      }
    }
  }
  if (width > 1) {
    cv::dilate(outline, outline, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * width - 1, 2 * width - 1)));
  }
  return outline;
}

}  // namespace

void OverlayOptions::Check() const {
  RequireColor(fill_color, "fill_color");
  RequireColor(outline_color, "outline_color");
  if (!(fill_opacity >= 0.0 && fill_opacity <= 1.0)) {
    ThrowInputError(kSource, "fill_opacity", "a value in [0, 1]", std::to_string(fill_opacity));
  }
  if (!(ambient >= 0.0 && ambient <= 1.0))
    ThrowInputError(kSource, "ambient", "a value in [0, 1]", std::to_string(ambient));
  if (outline_width_px < 0) {
    ThrowInputError(kSource, "outline_width_px", "a width >= 0 pixels", std::to_string(outline_width_px));
  }
}

RenderOptions OverlayRenderOptions(const OverlayOptions& options) {
  RenderOptions render;
  render.shading = Shading::kHeadlight;
  render.ambient = options.ambient;
  render.use_uniform_color = true;
  render.uniform_color = options.fill_color;
  return render;
}

cv::Mat DrawOverlay(const cv::Mat& frame_color, const RenderResult& rendered, const OverlayOptions& options) {
  options.Check();
  if (frame_color.type() != CV_8UC3 || rendered.color.type() != CV_8UC3 || rendered.labels.type() != CV_16UC1 ||
      frame_color.size() != rendered.color.size() || frame_color.size() != rendered.labels.size()) {
    ThrowInputError("overlay", "images", "an RGB frame and a render of the same size");
  }
  cv::Mat overlay = frame_color.clone();
  const float opacity = static_cast<float>(options.fill_opacity);
  for (int v = 0; v < overlay.rows; ++v) {
    for (int u = 0; u < overlay.cols; ++u) {
      if (rendered.labels.at<uint16_t>(v, u) == 0) continue;
      cv::Vec3b& pixel = overlay.at<cv::Vec3b>(v, u);
      const cv::Vec3b& model = rendered.color.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c)
        pixel[c] = cv::saturate_cast<uint8_t>((1.0F - opacity) * pixel[c] + opacity * model[c]);
    }
  }
  if (options.outline_width_px > 0)
    overlay.setTo(ToPixel(options.outline_color), Outline(rendered.labels, options.outline_width_px));
  return overlay;
}

cv::Mat RenderOverlay(Renderer& renderer, const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                      const cv::Mat& frame_color, const OverlayOptions& options) {
  options.Check();
  return DrawOverlay(frame_color, renderer.RenderScene(objects, camera, OverlayRenderOptions(options)), options);
}

}  // namespace ecv
