// PCL's organized Kinect cloud of the milk scene as an RGB-D frame.

#include <cmath>

#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

TEST(PcdFrame, ReadsDepthColourAndFitsIntrinsics) {
  const std::string path = test::DataPath("pcl_milk_scene/test/milk_cartoon_all_small_clorox.pcd");
  FrameSpec spec;
  spec.positional = path;
  const LoadedFrame loaded = LoadFrame(spec);
  const RgbdFrame& frame = loaded.rgbd;
  ASSERT_EQ(frame.depth.size(), cv::Size(640, 480));
  EXPECT_EQ(cv::countNonZero(frame.depth > 0.0F), 241407);
  EXPECT_TRUE(loaded.ground_truth.empty());
  // Not a grey image: the table scene has coloured boxes.
  cv::Scalar mean, deviation;
  cv::meanStdDev(frame.color, mean, deviation, frame.depth > 0.0F);
  EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 30.0);

  // The fitted camera re-projects every organized point to its own pixel within 0.5 px.
  cv::Mat points, color;
  ReadOrganizedPcd(path, &points, &color);
  double worst = 0.0;
  int valid = 0, mismatched = 0;
  for (int v = 0; v < points.rows; ++v) {
    for (int u = 0; u < points.cols; ++u) {
      const cv::Vec3f& p = points.at<cv::Vec3f>(v, u);
      if (!std::isfinite(p[2])) continue;
      ++valid;
      mismatched += frame.depth.at<float>(v, u) != p[2] ? 1 : 0;
      const Eigen::Vector2d pixel = frame.camera.Project({p[0], p[1], p[2]});
      worst = std::max(worst, (pixel - Eigen::Vector2d(u, v)).norm());
    }
  }
  EXPECT_EQ(valid, 241407);
  EXPECT_EQ(mismatched, 0);
  EXPECT_LT(worst, 0.5);

  // The points and colours PCL 1.13's reader gives for this file: three pixels and the sums of each channel.
  EXPECT_NEAR(points.at<cv::Vec3f>(240, 320)[2], 0.812F, 1e-6F);
  EXPECT_NEAR(points.at<cv::Vec3f>(300, 100)[0], -0.291412F, 1e-6F);
  EXPECT_EQ(color.at<cv::Vec3b>(240, 320), cv::Vec3b(78, 73, 47));
  EXPECT_EQ(color.at<cv::Vec3b>(300, 100), cv::Vec3b(37, 39, 25));
  EXPECT_EQ(color.at<cv::Vec3b>(200, 500), cv::Vec3b(101, 86, 78));
  const cv::Scalar sums = cv::sum(color);
  EXPECT_EQ(sums, cv::Scalar(24001028, 21760851, 19743536, 0));
}

}  // namespace
}  // namespace ecv
