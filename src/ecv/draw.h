#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "ecv/primitives.h"

namespace ecv {

/// The image (CV_8UC3 RGB) with segments drawn as short blue strokes along their edges and texlets as
/// green dots, as in the paper's Fig. 2. The input is dimmed so that the primitives stand out.
cv::Mat DrawPrimitives(const cv::Mat& rgb, const std::vector<Primitive>& primitives, double stroke_px = 3.0);

}  // namespace ecv
