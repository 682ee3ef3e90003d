#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "ecv/primitives.h"

namespace ecv {

/// One colour seen twice: on the stored model (its texture, captured under other light) and in the scene camera.
struct ColorPair {
  Eigen::Vector3d model = Eigen::Vector3d::Zero();  ///< RGB in [0, 1]
  Eigen::Vector3d scene = Eigen::Vector3d::Zero();  ///< RGB in [0, 1]
};

/// How FitColorMatrix treats pairs that do not fit (mislabelled pairs; shadows, highlights and misalignment in
/// automatic pairs).
enum class ColorFitMethod {
  kLeastSquares,  ///< plain linear least squares over every pair (the paper)
  /// Exact fits to 3-pair samples (every sample when few); the one of least truncated squared residual (MSAC) is
  /// refitted on its inliers, then polished by kTukeyIrls's reweighting.
  kRansac,
  kTukeyIrls,  ///< least squares reweighted by Tukey's biweight of the residual, started from the plain fit
};

const char* ToString(ColorFitMethod method);

/// Options of the colour-matrix fit (paper Sect. IV-C; DESIGN.md "Colour calibration"). Defaults measured by
/// bench/colorcal_bench (bench/RESULTS.md, "Colour calibration"): with 10 hand-labelled pairs of which 20-40 % are
/// mislabelled, kRansac is as good as least squares on the correct pairs alone, where kTukeyIrls breaks down from
/// 30 %; on automatic pairs from real frames kRansac ends where kTukeyIrls does (the polish), also for one matrix
/// pooled over several objects, where RANSAC without the polish fits the dominant object's colours only.
struct ColorFitOptions {
  ColorFitMethod method = ColorFitMethod::kRansac;
  /// Largest accepted condition number sigma_max / sigma_min of the N x 3 matrix of model colours (all pairs, then the
  /// inliers; RANSAC also skips 3-pair samples above it). Above it the model colours do not span RGB (all grey, or all
  /// one hue) and A is not determined. Automatic pairs of one YCB object reach 15-770.
  double max_condition_number = 1000.0;
  /// Robust methods: a pair is an inlier when |A c_model - c_scene| (Euclidean, RGB in [0, 1]) is below this; also
  /// RANSAC's truncation and the smallest cut-off of the biweight (which otherwise is 4.685 robust sigmas).
  double inlier_threshold = 0.1;
  /// kRansac: 3-pair samples drawn (every sample when fewer exist); both robust methods: at most this many reweightings
  int max_iterations = 2000;
  bool polish = true;  ///< kRansac: the Tukey reweighting after the refit on the inliers (off: the refit is the result)
  uint64_t seed = 1;   ///< kRansac: same seed, same result

  /// Throws InputError naming the field on values outside their ranges.
  void Check() const;
};

/// A fitted colour matrix and how well it fits.
struct ColorFit {
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();  ///< c_scene = A c_model, RGB in [0, 1]
  double rms = 0.0;               ///< RMS of |A c_model - c_scene| over the inliers, RGB units in [0, 1]
  double condition_number = 0.0;  ///< of the inliers' N x 3 model-colour matrix, sigma_max / sigma_min
  std::vector<bool> inliers;      ///< per pair; all true for kLeastSquares
  int num_inliers = 0;
  int iterations = 0;  ///< kRansac: samples drawn; kTukeyIrls: reweightings; kLeastSquares: 0
};

/// Fits A with A c_model = c_scene from >= 3 pairs (paper Sect. IV-C, linear least squares; robust variants in
/// ColorFitMethod). Throws InputError for fewer than 3 pairs, a non-finite colour (naming the pair), and model colours
/// whose condition number exceeds options.max_condition_number (naming both numbers).
ColorFit FitColorMatrix(const std::vector<ColorPair>& pairs, const ColorFitOptions& options = {});

/// A c, clamped to [0, 1].
Eigen::Vector3d ApplyColorMatrix(const Eigen::Matrix3d& A, const Eigen::Vector3d& color);

/// A applied to every pixel of a CV_8UC3 RGB image (colours / 255), clamped and rounded back to 8 bits.
/// Throws InputError for another image type.
cv::Mat ApplyColorMatrix(const Eigen::Matrix3d& A, const cv::Mat& rgb);

/// A applied to the colour of every primitive (model colours mapped into the scene camera's colours, clamped).
void ApplyColorMatrix(const Eigen::Matrix3d& A, std::vector<Primitive>* primitives);

/// Mean over the pairs of |ApplyColorMatrix(A, c_model) - c_scene| (Euclidean, RGB in [0, 1]); 0 for no pairs.
double MeanColorError(const std::vector<ColorPair>& pairs, const Eigen::Matrix3d& A = Eigen::Matrix3d::Identity());

}  // namespace ecv
