#include <gtest/gtest.h>

#include "io/frame_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

TEST(PoseIo, WriteThenReadIsExact) {
  test::TemporaryDirectory temporary;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  camera_from_object.linear() =
      Eigen::AngleAxisd(0.123456789, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  camera_from_object.translation() = Eigen::Vector3d(0.1, -0.0273, 1.0801);
  Eigen::Isometry3d b_from_a = Eigen::Isometry3d::Identity();
  b_from_a.translation() = Eigen::Vector3d(0.02, 0, 0);
  const std::string path = temporary.File("pose.json");
  WritePoseFile(path, {{"camera_from_object", camera_from_object}, {"b_from_a", b_from_a}});
  const Eigen::Isometry3d read = ReadPoseFile(path);
  EXPECT_LT((read.matrix() - camera_from_object.matrix()).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(read.translation(), camera_from_object.translation());  // doubles survive JSON exactly
  EXPECT_EQ(ReadPoseFile(path, "b_from_a").translation(), b_from_a.translation());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
}

TEST(PoseIo, FrameJsonWithRelativePathsLoadsAsTheFlags) {
  test::TemporaryDirectory temporary;
  const std::string prefix = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const std::string json_path = temporary.File("frame.json");
  WriteJsonFile(json_path, {{"color", std::filesystem::relative(prefix + "-color.png", temporary.path()).string()},
                            {"depth", prefix + "-depth.png"},  // absolute paths work too
                            {"depth_scale", 10000},
                            {"camera", {1066.778, 1067.487, 312.9869, 241.3109}}});
  FrameSpec from_json;
  from_json.positional = json_path;
  const RgbdFrame frame = LoadFrame(from_json).rgbd;
  const RgbdFrame reference = LoadYcbvFrame(prefix).rgbd;
  EXPECT_EQ(cv::norm(frame.color, reference.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(frame.depth, reference.depth, cv::NORM_INF), 0.0);
  EXPECT_NEAR(frame.camera.cx, reference.camera.cx, 1e-9);
}

}  // namespace
}  // namespace ecv
