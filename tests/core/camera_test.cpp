#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "core/camera.h"
#include "core/error.h"
#include "core/frame.h"

namespace ecv {
namespace {

const PinholeCamera kYcbvCamera{1066.778, 1067.487, 312.9869, 241.3109, 640, 480};

TEST(PinholeCamera, ProjectInvertsBackProject) {
  for (const Eigen::Vector2d& pixel :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(639, 479), Eigen::Vector2d(100.25, 300.5)}) {
    const Eigen::Vector3d point = kYcbvCamera.BackProject(pixel, 1.234);
    EXPECT_DOUBLE_EQ(point.z(), 1.234);
    EXPECT_LT((kYcbvCamera.Project(point) - pixel).norm(), 1e-9);
  }
}

TEST(PinholeCamera, PrincipalPointProjectsTheOpticalAxis) {
  const Eigen::Vector2d pixel = kYcbvCamera.Project({0.0, 0.0, 2.0});
  EXPECT_DOUBLE_EQ(pixel.x(), kYcbvCamera.cx);
  EXPECT_DOUBLE_EQ(pixel.y(), kYcbvCamera.cy);
  // x right, y down: a point right of and below the axis lands right of and below the centre.
  const Eigen::Vector2d right_below = kYcbvCamera.Project({0.1, 0.1, 1.0});
  EXPECT_NEAR(right_below.x(), kYcbvCamera.cx + 106.6778, 1e-9);
  EXPECT_NEAR(right_below.y(), kYcbvCamera.cy + 106.7487, 1e-9);
}

TEST(PinholeCamera, ContainsUsesPixelCentres) {
  EXPECT_TRUE(kYcbvCamera.Contains({-0.49, -0.49}));
  EXPECT_TRUE(kYcbvCamera.Contains({639.49, 479.49}));
  EXPECT_FALSE(kYcbvCamera.Contains({639.5, 10}));
  EXPECT_FALSE(kYcbvCamera.Contains({10, -0.6}));
}

TEST(PinholeCamera, SampledPixelsSeeAlongTheRaysOfEveryStrideThPixel) {
  for (const int stride : {1, 2, 3}) {
    const PinholeCamera sampled = kYcbvCamera.Sampled(stride);
    EXPECT_EQ(sampled.width, (640 + stride - 1) / stride);
    EXPECT_EQ(sampled.height, (480 + stride - 1) / stride);
    for (const Eigen::Vector2d& pixel : {Eigen::Vector2d(0, 0), Eigen::Vector2d(17, 101), Eigen::Vector2d(200, 159)}) {
      const Eigen::Vector3d ray = sampled.BackProject(pixel, 1.0);
      EXPECT_LT((kYcbvCamera.BackProject(stride * pixel, 1.0) - ray).norm(), 1e-12) << "stride " << stride;
    }
  }
  // The last sample of a row is the last full pixel it covers: 639 for stride 2 (320 samples), 639 for 3.
  EXPECT_EQ(kYcbvCamera.Sampled(3).width * 3 - 3, 639);
  EXPECT_THROW(kYcbvCamera.Sampled(0), InputError);
}

TEST(PinholeCamera, CheckRejectsNonsense) {
  EXPECT_NO_THROW(kYcbvCamera.Check());
  PinholeCamera nan_focal = kYcbvCamera;
  nan_focal.fx = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(nan_focal.Check(), InputError);
  PinholeCamera negative = kYcbvCamera;
  negative.fy = -5.0;
  EXPECT_THROW(negative.Check(), InputError);
  PinholeCamera no_size = kYcbvCamera;
  no_size.width = 0;
  EXPECT_THROW(no_size.Check(), InputError);
}

TEST(FitPinholeCamera, RecoversIntrinsicsOfASyntheticCloud) {
  const PinholeCamera truth{570.0, 575.0, 321.5, 239.25, 64, 48};
  cv::Mat points(truth.height, truth.width, CV_32FC3, cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
  for (int v = 0; v < truth.height; ++v) {
    for (int u = 0; u < truth.width; ++u) {
      if ((u + v) % 3 == 0) continue;  // leave holes
      const Eigen::Vector3d p = truth.BackProject({u, v}, 0.8 + 0.01 * u);
      points.at<cv::Vec3f>(v, u) =
          cv::Vec3f(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
  }
  const CameraFit fit = FitPinholeCamera(points);
  EXPECT_NEAR(fit.camera.fx, truth.fx, 0.05);
  EXPECT_NEAR(fit.camera.fy, truth.fy, 0.05);
  EXPECT_NEAR(fit.camera.cx, truth.cx, 0.05);
  EXPECT_NEAR(fit.camera.cy, truth.cy, 0.05);
  EXPECT_LT(fit.max_reprojection_px, 0.01);
  EXPECT_EQ(fit.num_points, truth.width * truth.height - (truth.width * truth.height + 2) / 3);
}

TEST(FitPinholeCamera, RejectsCloudsWithoutEnoughPoints) {
  cv::Mat points(4, 4, CV_32FC3, cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
  EXPECT_THROW(FitPinholeCamera(points), InputError);
  points.setTo(cv::Scalar(0.0, 0.0, 1.0));  // all on the axis: no spread to fit a focal length
  EXPECT_THROW(FitPinholeCamera(points), InputError);
}

// A frame whose pixels all differ: colour (u, v, u + v) and depth 1 + u / 1000 + v / 100000 metres.
RgbdFrame GradientFrame() {
  RgbdFrame frame;
  frame.camera = kYcbvCamera;
  frame.color.create(kYcbvCamera.height, kYcbvCamera.width, CV_8UC3);
  frame.depth.create(kYcbvCamera.height, kYcbvCamera.width, CV_32FC1);
  for (int v = 0; v < frame.depth.rows; ++v) {
    for (int u = 0; u < frame.depth.cols; ++u) {
      frame.color.at<cv::Vec3b>(v, u) =
          cv::Vec3b(static_cast<uchar>(u), static_cast<uchar>(v), static_cast<uchar>(u + v));
      frame.depth.at<float>(v, u) = 1.0F + static_cast<float>(u) / 1e3F + static_cast<float>(v) / 1e5F;
    }
  }
  return frame;
}

// Each pixel's 3D point, seen by the turned camera, is the original point moved by TurnedFromCamera(), with the same
// colour; turning twice gives the frame back.
TEST(TurnUpsideDown, SeesEveryPointWhereTheRolledCameraSeesIt) {
  const RgbdFrame frame = GradientFrame();
  const RgbdFrame turned = TurnUpsideDown(frame);
  turned.Check();
  for (const cv::Point pixel : {cv::Point(0, 0), cv::Point(639, 479), cv::Point(100, 300), cv::Point(313, 241)}) {
    const Eigen::Vector3d point =
        frame.camera.BackProject(Eigen::Vector2d(pixel.x, pixel.y), frame.depth.at<float>(pixel));
    const Eigen::Vector3d moved = TurnedFromCamera() * point;
    const Eigen::Vector2d seen = turned.camera.Project(moved);
    const cv::Point turned_pixel(static_cast<int>(std::lround(seen.x())), static_cast<int>(std::lround(seen.y())));
    EXPECT_LT((seen - Eigen::Vector2d(turned_pixel.x, turned_pixel.y)).norm(), 1e-9) << pixel;
    EXPECT_EQ(turned_pixel, cv::Point(639 - pixel.x, 479 - pixel.y));
    EXPECT_FLOAT_EQ(turned.depth.at<float>(turned_pixel), static_cast<float>(moved.z()));
    EXPECT_EQ(turned.color.at<cv::Vec3b>(turned_pixel), frame.color.at<cv::Vec3b>(pixel));
  }
  const RgbdFrame back = TurnUpsideDown(turned);
  EXPECT_EQ(cv::norm(back.color, frame.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(back.depth, frame.depth, cv::NORM_INF), 0.0);
  EXPECT_DOUBLE_EQ(back.camera.cx, frame.camera.cx);
  EXPECT_DOUBLE_EQ(back.camera.cy, frame.camera.cy);
  EXPECT_TRUE((TurnedFromCamera() * TurnedFromCamera()).isApprox(Eigen::Isometry3d::Identity()));
}

// A colour cast scales each channel by its gain and then applies the gamma to 0..1 intensities, clipped; depth and
// the caller's image stay as they were; a negative gain or a gamma of 0 is refused.
TEST(WithColorCast, ScalesEachChannelThenAppliesTheGammaAndLeavesTheOriginal) {
  const RgbdFrame frame = GradientFrame();
  const cv::Mat original = frame.color.clone();
  ColorCast cast;
  cast.rgb_gain = Eigen::Vector3d(1.15, 1.0, 0.5);
  cast.gamma = 2.0;
  const RgbdFrame changed = WithColorCast(frame, cast);
  changed.Check();
  for (const cv::Point pixel : {cv::Point(0, 0), cv::Point(639, 479), cv::Point(100, 300), cv::Point(313, 241)}) {
    const cv::Vec3b in = frame.color.at<cv::Vec3b>(pixel), out = changed.color.at<cv::Vec3b>(pixel);
    for (int channel = 0; channel < 3; ++channel) {
      const double expected = 255.0 * std::pow(std::min(1.0, cast.rgb_gain[channel] * in[channel] / 255.0), 2.0);
      EXPECT_NEAR(out[channel], expected, 0.5) << pixel << " channel " << channel;
    }
  }
  EXPECT_EQ(cv::norm(frame.color, original, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(changed.depth, frame.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(WithColorCast(frame, ColorCast()).color, frame.color, cv::NORM_INF), 0.0);
  cast.gamma = 0.0;
  EXPECT_THROW(WithColorCast(frame, cast), InputError);
  cast.gamma = 1.0;
  cast.rgb_gain.z() = -1.0;
  EXPECT_THROW(WithColorCast(frame, cast), InputError);
}

}  // namespace
}  // namespace ecv
