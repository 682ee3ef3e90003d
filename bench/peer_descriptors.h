#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/frame.h"

namespace ecv::bench {

/// Descriptors of some 3D keypoints of one view: row i describes keypoint i; rows that could not be
/// computed (too little support) are marked invalid.
struct KeypointDescriptors {
  std::vector<Eigen::Vector3f> positions;  ///< camera frame, metres
  cv::Mat values;                          ///< one row per keypoint (CV_32F, or CV_8U for binary)
  std::vector<bool> valid;
  bool binary = false;  ///< Hamming distance (ORB) instead of L2
};

/// PCL descriptors computed at `keypoints` (camera frame) with the masked depth pixels as support.
enum class PclDescriptor { kFpfh, kShot, kShotColor, kSpinImage };
const char* ToString(PclDescriptor descriptor);

/// `radius_m` is the descriptor's support radius; the support is voxelised at 4 mm and its normals are
/// estimated over 1 cm.
KeypointDescriptors ComputePclDescriptors(const RgbdFrame& frame, const cv::Mat& support_mask,
                                          const std::vector<Eigen::Vector3f>& keypoints, PclDescriptor descriptor,
                                          double radius_m);

}  // namespace ecv::bench
