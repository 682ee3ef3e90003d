#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "render/renderer.h"

namespace ecv {

/// How a model is drawn over a real image (as in the figures of Buch et al. 2013).
struct OverlayOptions {
  Eigen::Vector3f fill_color{1.0F, 0.0F, 0.0F};     ///< RGB in [0, 1] of the shaded model
  double fill_opacity = 0.55;                       ///< weight of the model over the image, 0..1
  Eigen::Vector3f outline_color{1.0F, 0.0F, 0.0F};  ///< RGB in [0, 1] of the silhouette outline
  int outline_width_px = 2;                         ///< outline thickness, pixels; 0 = no outline
  double ambient = 0.35;                            ///< brightness of the model where seen edge-on, 0..1

  /// Throws InputError for colours outside [0, 1], an opacity or ambient outside [0, 1] or a negative width.
  void Check() const;
};

/// Render options that paint every model in `options.fill_color` with headlight shading.
RenderOptions OverlayRenderOptions(const OverlayOptions& options);

/// `frame_color` (CV_8UC3 RGB) with `rendered` (from Renderer with OverlayRenderOptions, same size)
/// blended in where its mask is set, and the outline of each object (every label's boundary) drawn
/// on top. Throws InputError when the sizes or types differ.
cv::Mat DrawOverlay(const cv::Mat& frame_color, const RenderResult& rendered, const OverlayOptions& options = {});

/// Renders `objects` for `camera` and draws them over `frame_color` (CV_8UC3 RGB of the camera's size).
cv::Mat RenderOverlay(Renderer& renderer, const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                      const cv::Mat& frame_color, const OverlayOptions& options = {});

}  // namespace ecv
