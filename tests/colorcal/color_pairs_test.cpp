// Automatic colour pairs (issue 8, beyond the paper): sampling where a rendered model lies on the object, skipping
// dark and saturated pixels and windows that leave the mask; the depth-agreement mask.

#include <random>
#include <set>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "colorcal/color_pairs.h"
#include "core/error.h"

namespace ecv {
namespace {

Eigen::Matrix3d KnownMatrix() {
  Eigen::Matrix3d A;
  A << 0.92, 0.08, -0.03,  //
      0.05, 0.81, 0.07,    //
      -0.04, 0.12, 1.10;
  return A;
}

// A "rendered" model image of random colours in [60, 200], a dark 6x6 block, one saturated pixel, and the "real"
// image = A applied to it; the mask is a 40x30 rectangle.
struct Views {
  cv::Mat model, scene, mask;
};

Views MakeViews() {
  Views views;
  views.model.create(60, 80, CV_8UC3);
  std::mt19937 random(5);
  std::uniform_int_distribution<int> value(60, 200);
  for (int v = 0; v < 60; ++v) {
    for (int u = 0; u < 80; ++u)
      views.model.at<cv::Vec3b>(v, u) = cv::Vec3b(value(random), value(random), value(random));
  }
  views.model(cv::Rect(20, 20, 6, 6)).setTo(cv::Scalar(3, 4, 2));
  views.model.at<cv::Vec3b>(30, 40) = {255, 100, 100};
  views.scene = ApplyColorMatrix(KnownMatrix(), views.model);
  views.mask = cv::Mat::zeros(60, 80, CV_8UC1);
  views.mask(cv::Rect(10, 10, 40, 30)).setTo(255);
  return views;
}

TEST(ColorPairsTest, SamplesUsablePixelsAndCountsTheSkippedOnes) {
  const Views views = MakeViews();
  PosePairOptions options;
  options.max_pairs = 0;
  const PosePairs result = ColorPairsFromPose(views.model, views.scene, views.mask, options);
  EXPECT_EQ(result.mask_pixels, 40 * 30);
  EXPECT_EQ(result.window_outside, 40 * 30 - 38 * 28);  // the mask's border ring (radius 1)
  EXPECT_EQ(result.saturated, 9);                       // windows holding pixel (40, 30)
  EXPECT_EQ(result.dark, 4 * 4);                        // windows wholly inside the dark block
  ASSERT_EQ(result.pairs.size(), size_t(38 * 28 - 9 - 16));
  ASSERT_EQ(result.pixels.size(), result.pairs.size());
  const cv::Point pixel = result.pixels[123];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int y = -1; y <= 1; ++y) {
    for (int x = -1; x <= 1; ++x) {
      const cv::Vec3b& color = views.model.at<cv::Vec3b>(pixel.y + y, pixel.x + x);
      mean += Eigen::Vector3d(color[0], color[1], color[2]) / (9 * 255.0);
    }
  }
  EXPECT_LT((result.pairs[123].model - mean).norm(), 1e-12);

  // The pairs give back A up to the 8-bit rounding of the scene image.
  const ColorFit fit = FitColorMatrix(result.pairs);
  EXPECT_LT((fit.A - KnownMatrix()).norm(), 0.01);
  EXPECT_EQ(fit.num_inliers, int(result.pairs.size()));
}

TEST(ColorPairsTest, SubsampleIsSeeded) {
  const Views views = MakeViews();
  PosePairOptions options;
  options.max_pairs = 0;
  const PosePairs all = ColorPairsFromPose(views.model, views.scene, views.mask, options);
  options.max_pairs = 100;
  const PosePairs first = ColorPairsFromPose(views.model, views.scene, views.mask, options);
  const PosePairs again = ColorPairsFromPose(views.model, views.scene, views.mask, options);
  options.seed = 2;
  const PosePairs other = ColorPairsFromPose(views.model, views.scene, views.mask, options);
  ASSERT_EQ(first.pixels.size(), 100U);
  EXPECT_EQ(first.pixels, again.pixels);
  EXPECT_NE(first.pixels, other.pixels);
  auto key = [](const cv::Point& p) { return std::make_pair(p.x, p.y); };
  std::set<std::pair<int, int>> usable, picked;
  for (const cv::Point& p : all.pixels) usable.insert(key(p));
  for (const cv::Point& p : first.pixels) picked.insert(key(p));
  EXPECT_EQ(picked.size(), 100U);  // no pixel twice
  for (const auto& p : picked) EXPECT_TRUE(usable.count(p));
}

TEST(ColorPairsTest, EmptyMaskIsAResultAndBadImagesAreErrors) {
  const Views views = MakeViews();
  const PosePairs none = ColorPairsFromPose(views.model, views.scene, cv::Mat::zeros(60, 80, CV_8UC1));
  EXPECT_TRUE(none.pairs.empty());
  EXPECT_EQ(none.mask_pixels, 0);
  try {
    ColorPairsFromPose(views.model, views.scene(cv::Rect(0, 0, 40, 30)).clone(), views.mask);
    ADD_FAILURE() << "no error for a smaller scene image";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), ::testing::AllOf(::testing::HasSubstr("scene image"), ::testing::HasSubstr("80x60"),
                                               ::testing::HasSubstr("40x30")));
  }
  EXPECT_THROW(ColorPairsFromPose(views.model, views.scene, cv::Mat(views.mask.size(), CV_32FC1)), InputError);
  PosePairOptions options;
  options.max_value = options.min_value;
  EXPECT_THROW(ColorPairsFromPose(views.model, views.scene, views.mask, options), InputError);
}

TEST(ColorPairsTest, DepthAgreementMaskKeepsPixelsWithinTolerance) {
  cv::Mat model(1, 5, CV_32FC1), scene(1, 5, CV_32FC1);
  model.at<float>(0, 0) = 1.0F, scene.at<float>(0, 0) = 1.005F;  // agrees
  model.at<float>(0, 1) = 1.0F,
                     scene.at<float>(0, 1) = 1.02F;            // the real surface is elsewhere (occluded, other object)
  model.at<float>(0, 2) = 0.0F, scene.at<float>(0, 2) = 1.0F;  // the model is not seen there
  model.at<float>(0, 3) = 1.0F, scene.at<float>(0, 3) = 0.0F;  // no real depth
  model.at<float>(0, 4) = 0.5F, scene.at<float>(0, 4) = 0.492F;  // agrees from the other side
  const cv::Mat mask = DepthAgreementMask(model, scene, 0.01);
  ASSERT_EQ(mask.type(), CV_8UC1);
  EXPECT_EQ(std::vector<uint8_t>(mask.begin<uint8_t>(), mask.end<uint8_t>()),
            (std::vector<uint8_t>{255, 0, 0, 0, 255}));
  EXPECT_THROW(DepthAgreementMask(model, scene, 0.0), InputError);
  EXPECT_THROW(DepthAgreementMask(model, cv::Mat(1, 4, CV_32FC1), 0.01), InputError);
}

}  // namespace
}  // namespace ecv
