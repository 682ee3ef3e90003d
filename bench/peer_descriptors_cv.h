#pragma once

#include <vector>

#include "ecv/primitives.h"
#include "peer_descriptors.h"

namespace ecv::bench {

enum class ImageDescriptor { kSift, kOrb };
const char* ToString(ImageDescriptor descriptor);

/// SIFT or ORB descriptors at the primitives' pixels (size `size_px`, angle = monogenic orientation);
/// positions are the primitives'. Keypoints the descriptor cannot take (image border) are invalid.
KeypointDescriptors ComputeImageDescriptorsAt(const RgbdFrame& frame, const std::vector<Primitive>& primitives,
                                              ImageDescriptor descriptor, float size_px);

/// SIFT or ORB at their own keypoints inside `mask`, lifted to 3D with the depth image.
KeypointDescriptors ComputeImageDescriptorsOwn(const RgbdFrame& frame, const cv::Mat& mask, ImageDescriptor descriptor);

}  // namespace ecv::bench
