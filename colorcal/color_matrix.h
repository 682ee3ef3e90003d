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

/// The shape of A (beyond the paper, which fits a full matrix).
enum class ColorMatrixForm {
  kFull,      ///< any 3x3 matrix (the paper): channel cross-talk too; needs model colours that span RGB
  kDiagonal,  ///< per-channel gains only (von Kries): 3 unknowns, determined by pairs of a single hue
  /// kFull, or kDiagonal when the model colours' condition number exceeds ColorFitOptions::diagonal_above_condition
  /// (pairs of one hue, e.g. the yellow mustard bottle: a full fit there extrapolates to other hues, even with
  /// negative diagonal entries). Above max_condition_number (all grey) still an error, as for kFull.
  kAuto,
};

const char* ToString(ColorMatrixForm form);

/// Options of the colour-matrix fit (paper Sect. IV-C). Defaults measured by
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
  /// kAuto by bench/colorcal_bench --effect: as good as kFull where the colours span RGB, and no negative gains on
  /// one-hue objects (correspondence score with the matrix applied and brightness kept: 12.7 % against 12.1-12.4 %).
  ColorMatrixForm form = ColorMatrixForm::kAuto;
  /// kAuto: the diagonal form is fitted when the condition number of the model colours (all pairs, or the inliers of
  /// the full fit) is above this. On YCB-Video, cracker box and potted meat can (colours that span RGB): 6-17;
  /// mustard, sugar box, gelatin box, banana (one or two hues): 30-650 (automatic pairs), 4265 (sugar, hand pairs).
  double diagonal_above_condition = 30.0;
  /// Scale A so that the fitted colours keep the model's brightness (sum over the inliers of the channel sums of
  /// A c_model equals that of c_model): only the colour balance is corrected, not the exposure, so colour
  /// differences between neighbouring primitives do not shrink with a gain below 1. rms is of the scaled A. Off here
  /// (A keeps the paper's meaning); `ecvpose colorcal` turns it on: recognize_bench found 30 of 70 YCB-Video objects
  /// with such diagonal matrices, 25 without matrices, 17-23 with matrices as fitted.
  bool keep_brightness = false;
  /// Fit c_scene = A c_model + b: A is then the slope of the colours, free of an offset b (black level, ambient
  /// light, a camera's contrast curve), and maps colour differences c_b - c_a (what the context descriptor
  /// histograms, paper Sect. II-B) by what they are in the scene; b cancels in them, so only A is stored and applied.
  /// kRansac's 3-pair samples stay linear (they pick the inliers); the refit and the polish add b. Measured: the
  /// slopes are smaller than the gains, and the correspondence score drops further (5-12 % against 13.5 % without).
  bool fit_offset = false;

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
  ColorMatrixForm form = ColorMatrixForm::kFull;     ///< what was fitted: kFull or kDiagonal (never kAuto)
  double brightness_scale = 1.0;                     ///< keep_brightness: the factor A was scaled by; else 1
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< fit_offset: b of c_scene = A c_model + b; else 0
};

/// Fits A with A c_model = c_scene from >= 3 pairs (paper Sect. IV-C, linear least squares; robust variants in
/// ColorFitMethod; diagonal form in ColorMatrixForm). Throws InputError for fewer than 3 pairs, a non-finite colour
/// (naming the pair), and, for the full form, model colours whose condition number exceeds
/// options.max_condition_number (naming both numbers); for the diagonal form, a channel that is zero in every pair.
ColorFit FitColorMatrix(const std::vector<ColorPair>& pairs, const ColorFitOptions& options = {});

/// A scaled so that it keeps the brightness of grey: the channel sum of A (1, 1, 1) is 3 (A itself when that sum is
/// not positive). For matching: the context descriptor histograms colour differences between neighbouring
/// primitives, which in real frames are as large as in the rendered views or larger (camera contrast, noise) although
/// the frames are darker, so a gain below 1 moves the views' descriptors away from the scene's (bench/RESULTS.md,
/// "Colour calibration: hand pairs and the effect on matching"); this keeps only A's colour balance.
Eigen::Matrix3d BrightnessPreserving(const Eigen::Matrix3d& A);

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
