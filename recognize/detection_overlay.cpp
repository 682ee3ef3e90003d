#include "recognize/detection_overlay.h"

#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "render/overlay.h"

namespace ecv {

cv::Mat DrawDetectionOverlay(Renderer& renderer, const std::vector<SceneObject>& objects,
                             const std::vector<Detection>& detections, const RgbdFrame& frame,
                             double depth_tolerance_m) {
  if (objects.size() != detections.size()) {
    ThrowInputError("detection overlay", "objects", "one per detection");
  }
  const OverlayOptions overlay;
  RenderResult rendered = renderer.RenderScene(objects, frame.camera, OverlayRenderOptions(overlay));
  // Scene surfaces in front of a model hide it; so do pixels without a scene depth next to hidden ones (holes in the
  // depth of a shiny surface in front would otherwise let specks of the model show through).
  const auto tolerance = static_cast<float>(depth_tolerance_m);
  cv::Mat hidden = cv::Mat::zeros(rendered.depth.size(), CV_8UC1);
  for (int v = 0; v < rendered.depth.rows; ++v) {
    for (int u = 0; u < rendered.depth.cols; ++u) {
      const float scene_z = frame.depth.at<float>(v, u), model_z = rendered.depth.at<float>(v, u);
      if (model_z > 0.0F && scene_z > 0.0F && scene_z < model_z - tolerance) hidden.at<uchar>(v, u) = 1;
    }
  }
  cv::Mat near_hidden;
  cv::dilate(hidden, near_hidden, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(21, 21)));
  for (int v = 0; v < rendered.depth.rows; ++v) {
    for (int u = 0; u < rendered.depth.cols; ++u) {
      if (hidden.at<uchar>(v, u) != 0 || (frame.depth.at<float>(v, u) <= 0.0F && near_hidden.at<uchar>(v, u) != 0)) {
        rendered.mask.at<uchar>(v, u) = 0;
        rendered.labels.at<uint16_t>(v, u) = 0;
      }
    }
  }
  cv::Mat picture = DrawOverlay(frame.color, rendered, overlay);
  for (const Detection& detection : detections) {
    const Eigen::Vector3d centre = detection.camera_from_object.translation();
    if (centre.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = frame.camera.Project(centre);
    const cv::Point at(static_cast<int>(pixel.x()) - 40, static_cast<int>(pixel.y()));
    char label[160];
    // Point pair poses are marked: they come from shape alone.
    std::snprintf(label, sizeof(label), "%s %.2f%s", detection.model.c_str(), detection.score,
                  detection.hypothesis_source == HypothesisSource::kPpf ? " (ppf)" : "");
    cv::putText(picture, label, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(picture, label, at, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return picture;
}

}  // namespace ecv
