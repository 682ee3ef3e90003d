#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "colorcal/color_matrix.h"

namespace ecv {

/// How colour pairs are sampled where a model rendered at a pose lies on the real object.
struct PosePairOptions {
  int max_pairs = 2000;      ///< random subsample (seeded) of the usable pixels; 0 = every usable pixel
  int window_radius_px = 1;  ///< colour = mean over the (2r+1)^2 pixels around the pixel, all of them in the mask
  double min_value = 0.04;   ///< dark: skipped when the brightest channel of either mean is below this, [0, 1]
  double max_value = 0.98;   ///< saturated: skipped when any channel of any window pixel of either image is above
  uint64_t seed = 1;         ///< same seed, same pairs

  /// Throws InputError naming the field on values outside their ranges.
  void Check() const;
};

/// Pairs sampled from one view, with what was skipped. No usable pixel is a result (no pairs), not an error.
struct PosePairs {
  std::vector<ColorPair> pairs;   ///< model colour = rendered image, scene colour = real image
  std::vector<cv::Point> pixels;  ///< (x, y) of each pair
  int mask_pixels = 0;            ///< non-zero mask pixels
  int window_outside = 0;         ///< skipped: the window leaves the mask or the image
  int dark = 0;                   ///< skipped: too dark
  int saturated = 0;              ///< skipped: saturated
};

/// Automatic colour pairs (beyond the paper): `model_rgb` is the model rendered at a pose (ground truth or an accepted
/// pose), `scene_rgb` the real image, both CV_8UC3 RGB of one size; `mask` (CV_8UC1) marks the pixels where the
/// rendered model lies on the real object (e.g. DepthAgreementMask). Throws InputError for mismatched images.
PosePairs ColorPairsFromPose(const cv::Mat& model_rgb, const cv::Mat& scene_rgb, const cv::Mat& mask,
                             const PosePairOptions& options = {});

/// 255 where both depths (CV_32FC1 metres, 0 = missing) are valid and differ by at most `max_difference_m`, else 0:
/// the pixels where a rendered model (`model_depth`) lies on the real surface (`scene_depth`), not occluded.
cv::Mat DepthAgreementMask(const cv::Mat& model_depth, const cv::Mat& scene_depth, double max_difference_m = 0.01);

}  // namespace ecv
