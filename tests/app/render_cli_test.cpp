// `ecvpose render` as a user runs it: views to a folder, an overlay on a real LM-O frame, a scene file,
// and the errors (bad input, a GL context that cannot be created).

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "render/overlay.h"
#include "render/renderer.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

const char* const kCan = "lmo_subset/data/bop/lmo/models/obj_000005.ply";
const char* const kApe = "lmo_subset/data/bop/lmo/models/obj_000001.ply";

TriangleMesh LoadMillimetreMesh(const char* relative) {
  MeshLoadOptions options;
  options.metres_per_unit = 0.001;
  return LoadMesh(test::DataPath(relative), options);
}

cv::Mat ReadImage(const std::string& path) {
  return cv::imread(path, cv::IMREAD_UNCHANGED);
}

TEST(RenderCli, ViewsAreWrittenAsFramesWithCameraAndPose) {
  test::TemporaryDirectory out;
  const test::CommandResult result = test::RunCli(
      "render " + test::DataPath(kCan) + " --unit mm --views 3 --width 160 --height 120 --out " + out.path().string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("3/3 views"));
  const nlohmann::json index = ReadJsonFile(out.File("views.json"));
  ASSERT_EQ(index["views"].size(), 3U);
  EXPECT_EQ(index["depth_scale"].get<double>(), 10000.0);

  Renderer renderer;
  const MeshId can = renderer.AddMesh(LoadMillimetreMesh(kCan));
  for (const nlohmann::json& view : index["views"]) {
    const std::string json_path = out.File(view["frame"].get<std::string>());
    const nlohmann::json json = ReadJsonFile(json_path);
    for (const char* key : {"color", "depth", "mask", "camera", "camera_from_object", "depth_scale"}) {
      EXPECT_TRUE(json.contains(key)) << key << " missing in " << json_path;
    }
    // The view's JSON is a frame JSON (DESIGN.md) and a pose file.
    const LoadedFrame frame = LoadFrame(FrameSpec{json_path, "", "", std::nullopt, std::nullopt});
    const Eigen::Isometry3d camera_from_object = ReadPoseFile(json_path);
    EXPECT_EQ(frame.rgbd.camera.width, 160);
    EXPECT_EQ(frame.rgbd.camera.height, 120);
    // The files hold what the library renders for that camera and pose (depth to 0.1 mm).
    const RenderResult expected = renderer.Render(can, frame.rgbd.camera, camera_from_object);
    const cv::Mat mask = ReadImage(out.File(json["mask"].get<std::string>()));
    EXPECT_GT(cv::countNonZero(mask), 500);
    EXPECT_EQ(cv::norm(mask, expected.mask, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(frame.rgbd.color, expected.color, cv::NORM_INF), 0.0);
    EXPECT_LE(cv::norm(frame.rgbd.depth, expected.depth, cv::NORM_INF), 0.5 / 10000 + 1e-7);
  }
}

TEST(RenderCli, OverlayDrawsTheModelOverARealFrame) {
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const std::string depth = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");
  const LoadedFrame frame = LoadBopFrame(scene, 3, depth);
  Eigen::Isometry3d camera_from_can = Eigen::Isometry3d::Identity();
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_id == 5) camera_from_can = truth.camera_from_object;
  }
  ASSERT_FALSE(camera_from_can.matrix().isIdentity());
  test::TemporaryDirectory out;
  WritePoseFile(out.File("pose.json"), {{"camera_from_object", camera_from_can}});
  const test::CommandResult result =
      test::RunCli("render " + test::DataPath(kCan) + " --unit mm " + scene + ":3 --depth " + depth + " --pose " +
                   out.File("pose.json") + " --overlay " + out.File("overlay.png"));
  ASSERT_EQ(result.exit_code, 0) << result.output;

  cv::Mat overlay = ReadImage(out.File("overlay.png"));
  ASSERT_EQ(overlay.size(), frame.rgbd.color.size());
  cv::cvtColor(overlay, overlay, cv::COLOR_BGR2RGB);
  Renderer renderer;
  const RenderResult rendered =
      renderer.Render(renderer.AddMesh(LoadMillimetreMesh(kCan)), frame.rgbd.camera, camera_from_can);
  cv::Mat near_model;
  cv::dilate(rendered.mask, near_model, cv::Mat::ones(9, 9, CV_8U));
  cv::Mat difference, changed;
  cv::absdiff(overlay, frame.rgbd.color, difference);
  cv::cvtColor(difference, changed, cv::COLOR_RGB2GRAY);
  changed = changed > 0;
  EXPECT_EQ(cv::countNonZero(changed & ~near_model), 0) << "pixels changed away from the model";
  int redder = 0;
  for (int v = 0; v < overlay.rows; ++v) {
    for (int u = 0; u < overlay.cols; ++u) {
      if (!rendered.mask.at<uint8_t>(v, u)) continue;
      const cv::Vec3b now = overlay.at<cv::Vec3b>(v, u), before = frame.rgbd.color.at<cv::Vec3b>(v, u);
      redder += (now[0] - now[1]) > (before[0] - before[1]) + 40;
    }
  }
  EXPECT_GT(redder, 0.9 * cv::countNonZero(rendered.mask)) << "the model is drawn in red";
}

TEST(RenderCli, SceneWithOcclusionAndNoiseRepeats) {
  test::TemporaryDirectory out;
  const std::string scene_path = out.File("scene.json");
  const nlohmann::json scene = {
      {"camera", {572.4, 573.6, 159.5, 119.5}},
      {"width", 320},
      {"height", 240},
      {"objects",
       {{{"mesh", test::DataPath(kCan)},
         {"unit", "mm"},
         {"camera_from_object", PoseToJson(Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.9)))}},
        {{"mesh", test::DataPath(kApe)},
         {"unit", "mm"},
         {"camera_from_object", PoseToJson(Eigen::Isometry3d(Eigen::Translation3d(0.03, 0.0, 0.6)))}}}},
      {"noise", {{"seed", 5}, {"random_dropout", 0.02}}}};
  WriteJsonFile(scene_path, scene);
  for (const char* run : {"a", "b"}) {
    const test::CommandResult result = test::RunCli("render --scene " + scene_path + " --out " + out.File(run));
    ASSERT_EQ(result.exit_code, 0) << result.output;
  }
  const nlohmann::json view = ReadJsonFile(out.File("a/000000.json"));
  const cv::Mat labels = ReadImage(out.File("a/" + view["labels"].get<std::string>()));
  ASSERT_EQ(labels.type(), CV_8UC1);
  const int can_pixels = cv::countNonZero(labels == 1), ape_pixels = cv::countNonZero(labels == 2);
  EXPECT_EQ(view["objects"][0]["visible_pixels"].get<int>(), can_pixels);
  EXPECT_EQ(view["objects"][1]["visible_pixels"].get<int>(), ape_pixels);
  EXPECT_GT(ape_pixels, 1000);
  // The ape, in front, hides part of the can: fewer can pixels than with the can alone.
  Renderer renderer;
  const PinholeCamera camera{572.4, 573.6, 159.5, 119.5, 320, 240};
  const RenderResult can_alone = renderer.Render(renderer.AddMesh(LoadMillimetreMesh(kCan)), camera,
                                                 Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, 0.9)));
  EXPECT_LT(can_pixels, cv::countNonZero(can_alone.mask) - 500);
  // The noise model drops pixels and changes depths; the same seed gives the same image.
  const cv::Mat depth_a = ReadImage(out.File("a/000000-depth.png"));
  EXPECT_LT(cv::countNonZero(depth_a), can_pixels + ape_pixels);
  EXPECT_EQ(cv::norm(depth_a, ReadImage(out.File("b/000000-depth.png")), cv::NORM_INF), 0.0);
}

TEST(RenderCli, BadInputsAndContextFailureAreClearErrors) {
  test::TemporaryDirectory out;
  const test::CommandResult missing =
      test::RunCli("render " + out.File("nothing.obj") + " --views 2 --out " + out.File("v"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("nothing.obj"));
  EXPECT_EQ(test::RunCli("render " + test::DataPath(kCan) + " --out " + out.File("v")).exit_code, 2) << "no --views";

  // Mesa refuses a GL 3.3 context when told GL 2.1 is the most it has.
  setenv("MESA_GL_VERSION_OVERRIDE", "2.1", 1);
  const test::CommandResult refused =
      test::RunCli("render " + test::DataPath(kCan) + " --unit mm --views 1 --out " + out.File("v"));
  unsetenv("MESA_GL_VERSION_OVERRIDE");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.output, AllOf(HasSubstr("OSMesa"), HasSubstr("context"), HasSubstr("MESA_GL_VERSION_OVERRIDE")));
  EXPECT_FALSE(std::filesystem::exists(out.File("v/views.json"))) << "nothing written after a failure";
}

// The stated largest image renders (render_test); beyond it is a usage error before the mesh is read.
TEST(RenderCli, ImageSizesBeyondWhatRendersAreUsageErrors) {
  test::TemporaryDirectory out;
  const test::CommandResult huge = test::RunCli(
      "render " + test::DataPath(kCan) + " --unit mm --views 1 --width 16384 --height 16384 --out " + out.File("v"));
  EXPECT_EQ(huge.exit_code, 2) << huge.output;
  EXPECT_THAT(huge.output, HasSubstr("--width: expected a whole number from 1 to 8192, got 16384"));
  EXPECT_FALSE(std::filesystem::exists(out.File("v")));
}

}  // namespace
}  // namespace ecv
