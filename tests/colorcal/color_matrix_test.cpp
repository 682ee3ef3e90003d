// Colour-matrix fit (issue 8): a known A recovered from exact, noisy and mislabelled pairs; clear errors for too few,
// all-grey and non-finite pairs; applying A to colours, images and primitives.

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "colorcal/color_matrix.h"
#include "core/error.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A plausible change of light and camera: channel gains and some cross-talk.
Eigen::Matrix3d KnownMatrix() {
  Eigen::Matrix3d A;
  A << 0.92, 0.08, -0.03,  //
      0.05, 0.81, 0.07,    //
      -0.04, 0.12, 1.10;
  return A;
}

// `count` pairs with model colours uniform in [0.05, 0.95]^3 and scene = A model + N(0, noise^2) per channel.
std::vector<ColorPair> MakePairs(int count, double noise, uint64_t seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> uniform(0.05, 0.95);
  std::normal_distribution<double> gaussian(0.0, noise > 0.0 ? noise : 1.0);
  std::vector<ColorPair> pairs(count);
  for (ColorPair& pair : pairs) {
    pair.model = {uniform(random), uniform(random), uniform(random)};
    pair.scene = KnownMatrix() * pair.model;
    if (noise > 0.0) pair.scene += Eigen::Vector3d(gaussian(random), gaussian(random), gaussian(random));
  }
  return pairs;
}

// Mislabels every fifth pair (20 %): its scene colour is the one of the next pair, as if the wrong spot was clicked.
void Mislabel(std::vector<ColorPair>* pairs) {
  std::vector<ColorPair> original = *pairs;
  for (size_t i = 0; i < pairs->size(); i += 5) (*pairs)[i].scene = original[(i + 1) % original.size()].scene;
}

double FrobeniusError(const ColorFit& fit) {
  return (fit.A - KnownMatrix()).norm();
}

ColorFitOptions Method(ColorFitMethod method) {
  ColorFitOptions options;
  options.method = method;
  return options;
}

const ColorFitMethod kAllMethods[] = {ColorFitMethod::kLeastSquares, ColorFitMethod::kRansac,
                                      ColorFitMethod::kTukeyIrls};

TEST(ColorMatrixTest, KnownMatrixFromTenNoiseFreePairs) {
  const std::vector<ColorPair> pairs = MakePairs(10, 0.0, 1);
  for (ColorFitMethod method : kAllMethods) {
    SCOPED_TRACE(ToString(method));
    const ColorFit fit = FitColorMatrix(pairs, Method(method));
    EXPECT_LT(FrobeniusError(fit), 1e-6);
    EXPECT_LT(fit.rms, 1e-9);
    EXPECT_EQ(fit.num_inliers, 10);
    EXPECT_GT(fit.condition_number, 1.0);
    EXPECT_LT(fit.condition_number, 20.0);
  }
}

TEST(ColorMatrixTest, TenPairsWithNoiseWithinToleranceInEachOfTwentyTrials) {
  for (uint64_t trial = 0; trial < 20; ++trial) {
    const std::vector<ColorPair> pairs = MakePairs(10, 0.01, 100 + trial);
    for (ColorFitMethod method : kAllMethods) {
      SCOPED_TRACE(std::string(ToString(method)) + ", trial " + std::to_string(trial));
      const ColorFit fit = FitColorMatrix(pairs, Method(method));
      EXPECT_LT(FrobeniusError(fit), 0.08);
      EXPECT_GT(fit.rms, 0.0);
      EXPECT_LT(fit.rms, 0.05);  // the noise's own size: about sqrt(3) * 0.01
    }
  }
}

TEST(ColorMatrixTest, RobustFitsSurviveTwentyPercentMislabelledPairsWherePlainFitFails) {
  int plain_failures = 0;
  for (uint64_t trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    std::vector<ColorPair> pairs = MakePairs(10, 0.01, 200 + trial);
    Mislabel(&pairs);
    const ColorFit plain = FitColorMatrix(pairs, Method(ColorFitMethod::kLeastSquares));
    plain_failures += FrobeniusError(plain) > 0.08;
    const ColorFit ransac = FitColorMatrix(pairs, Method(ColorFitMethod::kRansac));
    EXPECT_LT(FrobeniusError(ransac), 0.08);
    EXPECT_EQ(ransac.num_inliers, 8);
    EXPECT_FALSE(ransac.inliers[0]);
    EXPECT_FALSE(ransac.inliers[5]);
    EXPECT_EQ(ransac.iterations, 120);  // every 3-pair sample of 10 pairs
  }
  EXPECT_EQ(plain_failures, 20);
}

TEST(ColorMatrixTest, RansacWithRandomSamplesRepeatsForOneSeed) {
  std::vector<ColorPair> pairs = MakePairs(200, 0.01, 7);
  Mislabel(&pairs);
  ColorFitOptions options;
  options.max_iterations = 50;  // fewer than the C(200, 3) samples: random ones
  const ColorFit first = FitColorMatrix(pairs, options);
  const ColorFit second = FitColorMatrix(pairs, options);
  EXPECT_EQ(first.A, second.A);
  EXPECT_EQ(first.inliers, second.inliers);
  EXPECT_EQ(first.iterations, 50);
  EXPECT_LT(FrobeniusError(first), 0.03);
  EXPECT_NEAR(first.num_inliers, 160, 4);
}

TEST(ColorMatrixTest, FewerThanThreePairsIsAClearError) {
  const std::vector<ColorPair> pairs = MakePairs(2, 0.0, 1);
  for (ColorFitMethod method : kAllMethods) {
    try {
      FitColorMatrix(pairs, Method(method));
      ADD_FAILURE() << "no error for 2 pairs";
    } catch (const InputError& error) {
      EXPECT_THAT(error.what(), AllOf(HasSubstr("at least 3 pairs"), HasSubstr("got 2")));
    }
  }
}

TEST(ColorMatrixTest, AllGreyPairsAreRankDeficient) {
  std::vector<ColorPair> pairs;
  for (double grey : {0.1, 0.3, 0.5, 0.7, 0.9})
    pairs.push_back({Eigen::Vector3d::Constant(grey), {grey, 0.9 * grey, grey}});
  for (ColorFitMethod method : kAllMethods) {
    try {
      FitColorMatrix(pairs, Method(method));
      ADD_FAILURE() << "no error for all-grey pairs";
    } catch (const InputError& error) {
      EXPECT_THAT(error.what(), AllOf(HasSubstr("condition number"), HasSubstr("max_condition_number"),
                                      HasSubstr("at most 1000"), HasSubstr("all grey"), HasSubstr("got inf")));
    }
  }
  // Nearly grey (colours 0.001 off the grey axis): conditioned in theory, not in practice.
  pairs[1].model[0] += 0.001, pairs[3].model[2] -= 0.001;
  EXPECT_THROW(FitColorMatrix(pairs), InputError);
}

TEST(ColorMatrixTest, NonFiniteColourNamesThePair) {
  std::vector<ColorPair> pairs = MakePairs(5, 0.0, 1);
  pairs[3].scene[1] = NAN;
  try {
    FitColorMatrix(pairs);
    ADD_FAILURE() << "no error for NaN";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), AllOf(HasSubstr("pair 4 scene colour"), HasSubstr("finite")));
  }
}

TEST(ColorMatrixTest, OptionsAreChecked) {
  ColorFitOptions options;
  options.inlier_threshold = 0.0;
  EXPECT_THROW(options.Check(), InputError);
  options = {};
  options.max_condition_number = 0.5;
  EXPECT_THROW(FitColorMatrix(MakePairs(10, 0.0, 1), options), InputError);
}

TEST(ColorMatrixTest, ApplyClampsColoursImagesAndPrimitives) {
  const Eigen::Matrix3d A = KnownMatrix();
  const Eigen::Vector3d color(0.2, 0.5, 0.9);
  EXPECT_LT((ApplyColorMatrix(A, color) - (A * color).cwiseMin(1.0)).norm(), 1e-12);
  EXPECT_EQ(ApplyColorMatrix(A, Eigen::Vector3d(1.0, 0.0, 0.0)), Eigen::Vector3d(0.92, 0.05, 0.0));  // -0.04 -> 0
  EXPECT_EQ(ApplyColorMatrix(2.0 * Eigen::Matrix3d::Identity(), color), Eigen::Vector3d(0.4, 1.0, 1.0));

  cv::Mat image(2, 3, CV_8UC3, cv::Scalar(51, 128, 230));
  image.at<cv::Vec3b>(1, 2) = {255, 0, 0};
  const cv::Mat mapped = ApplyColorMatrix(A, image);
  ASSERT_EQ(mapped.type(), CV_8UC3);
  const Eigen::Vector3d expected = 255.0 * ApplyColorMatrix(A, Eigen::Vector3d(51, 128, 230) / 255.0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(mapped.at<cv::Vec3b>(0, 0)[k], expected[k], 0.5 + 1e-4);
  EXPECT_EQ(mapped.at<cv::Vec3b>(1, 2), cv::Vec3b(235, 13, 0));  // 0.92 * 255 = 234.6, 0.05 * 255 = 12.75
  EXPECT_THROW(ApplyColorMatrix(A, cv::Mat(2, 2, CV_8UC1)), InputError);

  std::vector<Primitive> primitives(2);
  primitives[0].color = {0.2F, 0.5F, 0.9F};
  primitives[1].color = {1.0F, 1.0F, 1.0F};
  ApplyColorMatrix(A, &primitives);
  EXPECT_LT((primitives[0].color.cast<double>() - ApplyColorMatrix(A, color)).norm(), 1e-6);
  EXPECT_FLOAT_EQ(primitives[1].color[0], 0.97F);
  EXPECT_FLOAT_EQ(primitives[1].color[2], 1.0F);  // 1.18 clamped
}

TEST(ColorMatrixTest, MeanColourErrorDropsWithTheFittedMatrix) {
  const std::vector<ColorPair> pairs = MakePairs(50, 0.01, 3);
  const double before = MeanColorError(pairs);
  const double after = MeanColorError(pairs, FitColorMatrix(pairs).A);
  EXPECT_GT(before, 0.05);
  EXPECT_LT(after, 0.025);
  EXPECT_EQ(MeanColorError({}), 0.0);
}

}  // namespace
}  // namespace ecv
