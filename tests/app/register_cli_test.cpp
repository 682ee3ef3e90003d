// `ecvpose register`: two YCB-Video frames of one video, checked against the ground-truth camera motion.

#include <filesystem>

#include <gtest/gtest.h>

#include "core/pose.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

TEST(RegisterCli, WritesTheCameraMotionAndAnOverlay) {
  const std::string first = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const std::string last = test::DataPath("ycbv_subset/Example-Scenes/0001/000019");
  const test::TemporaryDirectory directory;
  const test::CommandResult run =
      test::RunCli("register " + first + " " + last + " --out-json " + directory.File("pose.json") + " --overlay " +
                   directory.File("a_on_b.png") + " --threads 2");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("b_from_a"), std::string::npos) << run.output;

  const LoadedFrame a = LoadYcbvFrame(first), b = LoadYcbvFrame(last);
  const GroundTruth& object = a.ground_truth.front();
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  for (const GroundTruth& other : b.ground_truth) {
    if (other.object_id == object.object_id) truth = other.camera_from_object * object.camera_from_object.inverse();
  }
  const Eigen::Isometry3d found = ReadPoseFile(directory.File("pose.json"), "b_from_a");
  EXPECT_LT(TranslationDistance(found, truth), 0.005);
  EXPECT_LT(RotationAngle(found, truth), M_PI / 180.0);
  const nlohmann::json json = ReadJsonFile(directory.File("pose.json"));
  EXPECT_TRUE(json.at("success").get<bool>());
  EXPECT_GT(json.at("inlier_fraction").get<double>(), 0.1);
  const cv::Mat overlay = ReadColorImage(directory.File("a_on_b.png"));
  EXPECT_EQ(overlay.size(), b.rgbd.color.size());
}

TEST(RegisterCli, BadFramesAndUsageAreReported) {
  const std::string frame = test::DataPath("ycbv_subset/Example-Scenes/0000/000001");
  const test::CommandResult one = test::RunCli("register " + frame);
  EXPECT_EQ(one.exit_code, 2) << one.output;
  EXPECT_NE(one.output.find("FRAME_B"), std::string::npos) << one.output;
  const test::CommandResult missing = test::RunCli("register " + frame + " /nonexistent/000001");
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent/000001"), std::string::npos) << missing.output;
  const test::CommandResult bad_option = test::RunCli("register " + frame + " " + frame + " --inlier-fraction 2");
  EXPECT_EQ(bad_option.exit_code, 1) << bad_option.output;
  EXPECT_NE(bad_option.output.find("required_inlier_fraction"), std::string::npos) << bad_option.output;
}

}  // namespace
}  // namespace ecv
