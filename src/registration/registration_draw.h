#pragma once

#include <opencv2/core.hpp>

#include <Eigen/Geometry>

#include "core/frame.h"

namespace ecv {

/// Frame B's colour image with frame A's surface, moved by `b_from_a`, drawn over it tinted red (the paper's
/// Fig. 8): each pixel of A is projected into B, and where it lands in front of or on B's surface (within
/// `tolerance_m`) its colour, blended with red at `opacity`, replaces B's in every other square of a
/// `square_px` checkerboard. A good alignment continues B's edges across the squares.
cv::Mat DrawAlignedFrame(const RgbdFrame& a, const RgbdFrame& b, const Eigen::Isometry3d& b_from_a,
                         double opacity = 0.35, double tolerance_m = 0.01, int square_px = 48);

}  // namespace ecv
