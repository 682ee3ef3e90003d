// Colour-matrix forms beyond the paper (issue 8): the diagonal (per-channel gain) fit, the automatic fallback to it on
// pairs of one hue, the brightness-keeping scale and the fit with an offset.

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "colorcal/color_matrix.h"
#include "core/error.h"

namespace ecv {
namespace {

const Eigen::Vector3d kGains(0.8, 0.65, 0.55);

// `count` pairs with model colours uniform in [0.05, 0.95]^3 and scene = `A` model + `b` + N(0, noise^2).
std::vector<ColorPair> SpreadPairs(const Eigen::Matrix3d& A, const Eigen::Vector3d& b, int count, double noise,
                                   uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.05, 0.95);
  std::normal_distribution<double> gaussian(0.0, 1.0);
  std::vector<ColorPair> pairs(count);
  for (ColorPair& pair : pairs) {
    pair.model = {uniform(random), uniform(random), uniform(random)};
    pair.scene = A * pair.model + b + noise * Eigen::Vector3d(gaussian(random), gaussian(random), gaussian(random));
  }
  return pairs;
}

// Pairs of one hue, as on the yellow mustard bottle: model colours = brightness x yellow (+ 0.01 noise), scene colours
// = the gains of kGains (+ 0.01 noise).
std::vector<ColorPair> OneHuePairs(int count, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> brightness(0.4, 1.0);
  std::normal_distribution<double> gaussian(0.0, 0.01);
  std::vector<ColorPair> pairs(count);
  for (ColorPair& pair : pairs) {
    const Eigen::Vector3d noise(gaussian(random), gaussian(random), gaussian(random));
    pair.model = brightness(random) * Eigen::Vector3d(0.9, 0.75, 0.1) + noise;
    pair.scene =
        kGains.asDiagonal() * pair.model + Eigen::Vector3d(gaussian(random), gaussian(random), gaussian(random));
  }
  return pairs;
}

TEST(ColorMatrixFormTest, DiagonalFormRecoversGainsAndHasNoCrossTalk) {
  const Eigen::Matrix3d A = kGains.asDiagonal();
  const std::vector<ColorPair> pairs = SpreadPairs(A, Eigen::Vector3d::Zero(), 10, 0.0, 3);
  for (ColorFitMethod method : {ColorFitMethod::kLeastSquares, ColorFitMethod::kRansac, ColorFitMethod::kTukeyIrls}) {
    SCOPED_TRACE(ToString(method));
    ColorFitOptions options;
    options.method = method;
    options.form = ColorMatrixForm::kDiagonal;
    const ColorFit fit = FitColorMatrix(pairs, options);
    EXPECT_EQ(fit.form, ColorMatrixForm::kDiagonal);
    EXPECT_LT((fit.A - A).norm(), 1e-9) << fit.A;
    EXPECT_EQ(fit.num_inliers, 10);
  }
}

TEST(ColorMatrixFormTest, AutoFormFallsBackToTheDiagonalOnOneHuePairsOnly) {
  ColorFitOptions automatic;
  automatic.form = ColorMatrixForm::kAuto;
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE(seed);
    const std::vector<ColorPair> one_hue = OneHuePairs(10, seed);
    const ColorFit fallback = FitColorMatrix(one_hue, automatic);
    EXPECT_EQ(fallback.form, ColorMatrixForm::kDiagonal);
    EXPECT_GT(fallback.condition_number, automatic.diagonal_above_condition);
    // Red and green are strong in yellow; blue (0.1 x brightness, noise 0.01) gives a looser gain.
    const Eigen::Vector3d error = (fallback.A.diagonal() - kGains).cwiseAbs();
    EXPECT_LT(error.head<2>().maxCoeff(), 0.03) << fallback.A;
    EXPECT_LT(error[2], 0.15) << fallback.A;
    // The full form on the same pairs is either refused (ill-conditioned) or extrapolates far from the gains.
    ColorFitOptions full_form;
    full_form.form = ColorMatrixForm::kFull;
    try {
      const ColorFit full = FitColorMatrix(one_hue, full_form);
      EXPECT_GT((full.A - Eigen::Matrix3d(kGains.asDiagonal())).norm(), 0.1) << full.A;
    } catch (const InputError&) {
    }
    // Pairs that span RGB keep the full form.
    Eigen::Matrix3d cross;
    cross << 0.8, 0.1, 0.0, 0.05, 0.7, 0.05, 0.0, 0.1, 0.6;
    const ColorFit spread = FitColorMatrix(SpreadPairs(cross, Eigen::Vector3d::Zero(), 10, 0.0, seed), automatic);
    EXPECT_EQ(spread.form, ColorMatrixForm::kFull);
    EXPECT_LT((spread.A - cross).norm(), 1e-6);
  }
}

TEST(ColorMatrixFormTest, DiagonalFormNeedsEveryChannel) {
  std::vector<ColorPair> pairs = SpreadPairs(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 5, 0.0, 4);
  for (ColorPair& pair : pairs) pair.model[2] = 0.0;
  ColorFitOptions options;
  options.form = ColorMatrixForm::kDiagonal;
  options.method = ColorFitMethod::kLeastSquares;
  try {
    FitColorMatrix(pairs, options);
    FAIL() << "no error for a channel that is zero in every pair";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("channel B"), std::string::npos) << error.what();
  }
}

TEST(ColorMatrixFormTest, KeepBrightnessScalesTheFitToTheModelsBrightness) {
  Eigen::Matrix3d A;
  A << 0.7, 0.05, 0.0, 0.02, 0.6, 0.03, 0.0, 0.05, 0.5;
  const std::vector<ColorPair> pairs = SpreadPairs(A, Eigen::Vector3d::Zero(), 20, 0.0, 5);
  ColorFitOptions options;
  const ColorFit plain = FitColorMatrix(pairs, options);
  options.keep_brightness = true;
  const ColorFit kept = FitColorMatrix(pairs, options);
  double model_sum = 0.0, fitted_sum = 0.0;
  for (const ColorPair& pair : pairs) model_sum += pair.model.sum(), fitted_sum += (kept.A * pair.model).sum();
  EXPECT_NEAR(fitted_sum, model_sum, 1e-9 * model_sum);
  EXPECT_GT(kept.brightness_scale, 1.5);  // the scene is about 0.6 as bright
  EXPECT_LT((kept.A - kept.brightness_scale * plain.A).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(plain.brightness_scale, 1.0);
}

TEST(ColorMatrixFormTest, OffsetFitRecoversTheSlopeWhereTheLinearFitDoesNot) {
  Eigen::Matrix3d A;
  A << 0.9, 0.05, 0.0, 0.0, 0.85, 0.05, 0.02, 0.0, 0.8;
  const Eigen::Vector3d b(-0.1, -0.08, -0.12);  // a black level: dark colours are darker still
  for (ColorMatrixForm form : {ColorMatrixForm::kFull, ColorMatrixForm::kDiagonal}) {
    SCOPED_TRACE(ToString(form));
    const Eigen::Matrix3d truth = form == ColorMatrixForm::kFull ? A : Eigen::Matrix3d(A.diagonal().asDiagonal());
    const std::vector<ColorPair> pairs = SpreadPairs(truth, b, 30, 0.0, 6);
    ColorFitOptions options;
    options.form = form;
    const ColorFit linear = FitColorMatrix(pairs, options);
    options.fit_offset = true;
    const ColorFit affine = FitColorMatrix(pairs, options);
    EXPECT_LT((affine.A - truth).norm(), 1e-6) << affine.A;
    EXPECT_LT((affine.offset - b).norm(), 1e-6) << affine.offset.transpose();
    EXPECT_LT(affine.rms, 1e-6);
    EXPECT_GT((linear.A - truth).norm(), 0.05) << linear.A;
    EXPECT_EQ(linear.offset, Eigen::Vector3d::Zero());
  }
}

TEST(ColorMatrixFormTest, BrightnessPreservingKeepsGreyAndTheBalance) {
  Eigen::Matrix3d A;
  A << 0.7, 0.05, 0.0, 0.02, 0.6, 0.03, 0.0, 0.05, 0.5;
  const Eigen::Matrix3d kept = BrightnessPreserving(A);
  EXPECT_NEAR((kept * Eigen::Vector3d::Ones()).sum(), 3.0, 1e-12);
  EXPECT_NEAR(kept(0, 0) / kept(1, 1), A(0, 0) / A(1, 1), 1e-12);  // only scaled
  EXPECT_GT(kept(0, 0), A(0, 0));
  EXPECT_EQ(BrightnessPreserving(-A), -A);  // nothing to keep: unchanged
}

TEST(ColorMatrixFormTest, OptionsAreChecked) {
  ColorFitOptions options;
  options.diagonal_above_condition = 0.5;
  EXPECT_THROW(options.Check(), InputError);
}

}  // namespace
}  // namespace ecv
