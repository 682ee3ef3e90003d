// Verification's measure and score steps without a renderer: a box standing 10 cm in front of a wall, its printed
// face in the colour image, compared with "renders" made by hand (the box's own depth and colours, moved off the
// surface, hidden behind something, or a wrong size).

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/recognizer.h"
#include "recognize/verification.h"

namespace ecv {
namespace {

constexpr int kWidth = 160, kHeight = 120, kStride = 2;
const cv::Rect kBox(30, 20, 100, 80);  // frame pixels

// A checked print of 10 x 12 px fields in two colours: texture edges and colours to correlate.
cv::Vec3b Print(int u, int v) {
  return ((u / 10 + v / 12) % 2 == 0) ? cv::Vec3b(230, 200, 60) : cv::Vec3b(20, 40, 120);
}

RgbdFrame BoxFrame() {
  RgbdFrame frame;
  frame.camera = PinholeCamera{500.0, 500.0, 80.0, 60.0, kWidth, kHeight};
  frame.depth = cv::Mat(kHeight, kWidth, CV_32FC1, cv::Scalar(1.0F));
  frame.color = cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(120, 120, 120));
  frame.depth(kBox).setTo(0.9F);
  for (int v = kBox.y; v < kBox.y + kBox.height; ++v) {
    for (int u = kBox.x; u < kBox.x + kBox.width; ++u) frame.color.at<cv::Vec3b>(v, u) = Print(u, v);
  }
  return frame;
}

// The box as a render at the stride would show it, `offset_m` further away than the scene's surface.
RenderedPose BoxRender(float offset_m) {
  RenderedPose rendered;
  rendered.depth = cv::Mat::zeros(kHeight / kStride, kWidth / kStride, CV_32FC1);
  rendered.color = cv::Mat::zeros(kHeight / kStride, kWidth / kStride, CV_8UC3);
  for (int v = 0; v < rendered.depth.rows; ++v) {
    for (int u = 0; u < rendered.depth.cols; ++u) {
      if (!kBox.contains(cv::Point(u * kStride, v * kStride))) continue;
      rendered.depth.at<float>(v, u) = 0.9F + offset_m;
      rendered.color.at<cv::Vec3b>(v, u) = Print(u * kStride, v * kStride);
    }
  }
  return rendered;
}

TEST(MeasurePose, TheRightPoseLiesOnTheSurfaceCorrelatesAndHasItsOutlineOnTheBoxsSteps) {
  const RgbdFrame frame = BoxFrame();
  const VerifyOptions options;
  const VerificationFrame verification = MakeVerificationFrame(frame, options, kStride);
  const PoseEvidence evidence = MeasurePose(BoxRender(0.0F), verification, Eigen::Matrix3f::Identity(), options);
  const int box_samples = (kBox.width / kStride) * (kBox.height / kStride);
  EXPECT_EQ(evidence.rendered_pixels, box_samples);
  EXPECT_EQ(evidence.visible, box_samples);
  EXPECT_EQ(static_cast<int>(evidence.surface.size()), box_samples);
  EXPECT_NEAR(evidence.surface_error_m, 0.0, 1e-7);
  EXPECT_GT(evidence.color_agreement, 0.9);
  EXPECT_GT(evidence.edges.predicted, 50);
  EXPECT_GT(evidence.edges.Share(), 0.8);
  EXPECT_GT(evidence.outline.seen, 20);
  EXPECT_EQ(evidence.outline.on_step, evidence.outline.seen);

  Detection detection;
  ScorePose(evidence, options, false, &detection);
  EXPECT_DOUBLE_EQ(detection.depth_agreement, 1.0);
  EXPECT_DOUBLE_EQ(detection.visible_fraction, 1.0);
  EXPECT_DOUBLE_EQ(detection.contour_agreement, 1.0);
  EXPECT_GT(detection.score, 0.8);
}

// The same surface with its print one field over (a box turned, a neighbour's label): the depth agrees, the
// colours do not.
TEST(MeasurePose, TheRightSurfaceWithTheWrongPrintScoresLow) {
  const RgbdFrame frame = BoxFrame();
  const VerifyOptions options;
  RenderedPose rendered = BoxRender(0.0F);
  for (int v = 0; v < rendered.color.rows; ++v) {
    for (int u = 0; u < rendered.color.cols; ++u) {
      if (rendered.depth.at<float>(v, u) > 0.0F)
        rendered.color.at<cv::Vec3b>(v, u) = Print(u * kStride + 10, v * kStride);
    }
  }
  Detection detection;
  ScorePose(MeasurePose(rendered, MakeVerificationFrame(frame, options, kStride), Eigen::Matrix3f::Identity(), options),
            options, false, &detection);
  EXPECT_DOUBLE_EQ(detection.depth_agreement, 1.0);
  EXPECT_LT(detection.color_agreement, 0.1);
  EXPECT_LT(detection.score, 0.1);
}

// 5 mm behind the surface: within the depth tolerance, so the same pixels count, but the fit factor is
// 1 - (5 - 3.5) / 3 = 0.5 and the score halves.
TEST(MeasurePose, APoseFiveMillimetresOffScoresHalfThroughTheFitFactor) {
  const RgbdFrame frame = BoxFrame();
  const VerifyOptions options;
  const VerificationFrame verification = MakeVerificationFrame(frame, options, kStride);
  Detection right, off;
  ScorePose(MeasurePose(BoxRender(0.0F), verification, Eigen::Matrix3f::Identity(), options), options, false, &right);
  const PoseEvidence evidence = MeasurePose(BoxRender(0.005F), verification, Eigen::Matrix3f::Identity(), options);
  ScorePose(evidence, options, false, &off);
  EXPECT_NEAR(evidence.surface_error_m, 0.005, 1e-6);
  EXPECT_DOUBLE_EQ(off.depth_agreement, right.depth_agreement);
  EXPECT_NEAR(off.score, 0.5 * right.score, 1e-5);
}

// A scene surface 20 cm in front of the left half of the box hides that half: the pixels count as rendered, not
// as visible, and do not lower the depth agreement.
TEST(MeasurePose, ASurfaceInFrontHidesPixelsWithoutCountingAgainstThePose) {
  RgbdFrame frame = BoxFrame();
  const cv::Rect left(kBox.x, kBox.y, kBox.width / 2, kBox.height);
  frame.depth(left).setTo(0.7F);
  const VerifyOptions options;
  const PoseEvidence evidence = MeasurePose(BoxRender(0.0F), MakeVerificationFrame(frame, options, kStride),
                                            Eigen::Matrix3f::Identity(), options);
  EXPECT_EQ(evidence.visible, evidence.rendered_pixels / 2);
  Detection detection;
  ScorePose(evidence, options, false, &detection);
  EXPECT_DOUBLE_EQ(detection.visible_fraction, 0.5);
  EXPECT_DOUBLE_EQ(detection.depth_agreement, 1.0);
}

TEST(MeasurePose, ARenderOfAnotherSizeIsRefused) {
  const VerifyOptions options;
  const VerificationFrame verification = MakeVerificationFrame(BoxFrame(), options, kStride);
  RenderedPose rendered = BoxRender(0.0F);
  rendered.depth = rendered.depth(cv::Rect(0, 0, 40, 30)).clone();
  EXPECT_THROW(MeasurePose(rendered, verification, Eigen::Matrix3f::Identity(), options), InputError);
}

// The score of given evidence: depth agreement x colour^(1-w) x edges^w x fit factor x contour factor.
TEST(ScorePose, MultipliesTheTermsAsDocumented) {
  VerifyOptions options;
  PoseEvidence evidence;
  evidence.rendered_pixels = 100;
  evidence.visible = 80;
  evidence.surface.assign(60, cv::Point(0, 0));
  evidence.surface_error_m = 0.002;  // under residual_free_m: fit factor 1
  evidence.color_agreement = 0.64;
  evidence.edges = {100, 36};    // predicted, shown: 0.64^0.5 x 0.36^0.5 = 0.48
  evidence.outline = {100, 50};  // seen, on a step: 0.5 >= contour_free, factor 1
  Detection detection;
  ScorePose(evidence, options, false, &detection);
  EXPECT_DOUBLE_EQ(detection.visible_fraction, 0.8);
  EXPECT_DOUBLE_EQ(detection.depth_agreement, 0.75);
  EXPECT_DOUBLE_EQ(detection.edge_agreement, 0.36);
  EXPECT_EQ(detection.edge_pixels, 100);
  EXPECT_NEAR(detection.score, 0.75 * 0.48, 1e-12);

  evidence.outline = {100, 20};  // 0.2 on a step: 1 - (0.3 - 0.2) / 0.2 = 0.5
  ScorePose(evidence, options, false, &detection);
  EXPECT_NEAR(detection.score, 0.75 * 0.48 * 0.5, 1e-12);

  options.edge_weight = 0.0;  // colour alone
  ScorePose(evidence, options, false, &detection);
  EXPECT_NEAR(detection.score, 0.75 * 0.64 * 0.5, 1e-12);

  evidence.edges = {10, 1};  // under min_edge_pixels: colour alone whatever the weight
  options.edge_weight = 0.5;
  ScorePose(evidence, options, false, &detection);
  EXPECT_NEAR(detection.score, 0.75 * 0.64 * 0.5, 1e-12);
}

TEST(FitFactor, OneUpToTheFreeResidualThenLinearToZero) {
  VerifyOptions options;  // 3.5 mm free, 3 mm falloff
  EXPECT_DOUBLE_EQ(FitFactor(0.0, options), 1.0);
  EXPECT_DOUBLE_EQ(FitFactor(0.0035, options), 1.0);
  EXPECT_NEAR(FitFactor(0.0050, options), 0.5, 1e-12);
  EXPECT_NEAR(FitFactor(0.0065, options), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(FitFactor(0.02, options), 0.0);
  options.residual_falloff_m = 0.0;
  EXPECT_DOUBLE_EQ(FitFactor(0.02, options), 1.0);
}

TEST(VerifyOptions, OutOfRangeValuesAreReportedByName) {
  auto message = [](const VerifyOptions& options) {
    try {
      options.Check();
    } catch (const InputError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message(VerifyOptions()), "no error");
  VerifyOptions options;
  options.depth_tolerance_m = 0.0;
  EXPECT_NE(message(options).find("depth_tolerance_m"), std::string::npos) << message(options);
  options = VerifyOptions();
  options.contour_free = 1.5;
  EXPECT_NE(message(options).find("contour_free"), std::string::npos) << message(options);
  options = VerifyOptions();
  options.min_visible_fraction = -0.1;
  EXPECT_NE(message(options).find("min_visible_fraction"), std::string::npos) << message(options);
  options = VerifyOptions();
  options.plane_patch.min_share = 2.0;
  EXPECT_NE(message(options).find("min_share"), std::string::npos) << message(options);
}

}  // namespace
}  // namespace ecv
