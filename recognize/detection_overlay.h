#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"
#include "recognize/detection.h"
#include "render/renderer.h"

namespace ecv {

/// `frame`'s colour image with each of `objects` (the detections' meshes at their poses, in the same order as
/// `detections`) drawn in red and outlined, labelled with its model's name and score. Scene surfaces more than
/// `depth_tolerance_m` in front of a model hide it, and so do depth holes next to hidden pixels.
cv::Mat DrawDetectionOverlay(Renderer& renderer, const std::vector<SceneObject>& objects,
                             const std::vector<Detection>& detections, const RgbdFrame& frame,
                             double depth_tolerance_m);

}  // namespace ecv
