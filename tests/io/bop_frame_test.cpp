// Real LM-O image 3 (BOP layout), with its depth image from SAM-6D's example (see lmo_subset/SOURCE.md).

#include <algorithm>
#include <filesystem>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/frame.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

LoadedFrame LoadLmoImage3() {
  FrameSpec spec;
  spec.positional = test::DataPath("lmo_subset/data/bop/lmo/test/000002") + ":3";
  spec.depth_path = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");
  return LoadFrame(spec);
}

std::string ModelPath(int object_id) {
  char name[32];
  std::snprintf(name, sizeof(name), "obj_%06d.ply", object_id);
  return test::DataPath(std::string("lmo_subset/data/bop/lmo/models/") + name);
}

TEST(BopFrame, ReadsLmoImageCameraAndEightPoses) {
  const LoadedFrame loaded = LoadLmoImage3();
  EXPECT_NEAR(loaded.rgbd.camera.fx, 572.4114, 1e-4);
  EXPECT_NEAR(loaded.rgbd.camera.fy, 573.57043, 1e-4);
  EXPECT_NEAR(loaded.rgbd.camera.cx, 325.2611, 1e-4);
  EXPECT_NEAR(loaded.rgbd.camera.cy, 242.04899, 1e-4);
  ASSERT_EQ(loaded.ground_truth.size(), 8U);
  std::vector<int> ids;
  for (const GroundTruth& truth : loaded.ground_truth) ids.push_back(truth.object_id);
  EXPECT_EQ(ids, (std::vector<int>{1, 5, 6, 8, 9, 10, 11, 12}));
  EXPECT_EQ(loaded.ground_truth[1].object_name, "obj_000005");
  EXPECT_NEAR(loaded.ground_truth[0].visible_fraction, 0.1996, 1e-4);
  EXPECT_EQ(loaded.ground_truth[1].object_box, cv::Rect(376, 226, 60, 91));
  // Millimetres in scene_gt.json -> metres.
  EXPECT_NEAR(loaded.ground_truth[1].camera_from_object.translation().z(), 0.96478389285, 1e-9);
  EXPECT_EQ(loaded.scene_id, 2);  // the scene folder's number
  EXPECT_EQ(loaded.image_id, 3);
}

// The message of LoadFrame on a copy of LM-O scene 000002, image 3, in `directory` with each of its JSON files
// changed by `edit` (file name, JSON); "" when it loads.
template <typename Edit>
std::string LoadEditedScene(const test::TemporaryDirectory& directory, Edit edit) {
  const std::filesystem::path scene = directory.path() / "000002";
  const std::filesystem::path source = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  std::filesystem::remove_all(scene);
  std::filesystem::create_directories(scene / "rgb");
  std::filesystem::copy(source / "rgb" / "000003.png", scene / "rgb" / "000003.png");
  for (const char* file : {"scene_camera.json", "scene_gt.json", "scene_gt_info.json"}) {
    nlohmann::json json = ReadJsonFile((source / file).string());
    edit(std::string(file), json);
    WriteJsonFile((scene / file).string(), json);
  }
  FrameSpec spec;
  spec.positional = scene.string() + ":3";
  spec.depth_path = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");
  try {
    LoadFrame(spec);
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

// A box far outside any image (the fuzzer's 1e300) is refused by name, not converted to int.
TEST(BopFrame, ABoxBeyondAnyImageIsRefusedByName) {
  const test::TemporaryDirectory directory;
  const std::string message = LoadEditedScene(directory, [](const std::string& file, nlohmann::json& json) {
    if (file == "scene_gt_info.json") json["3"][0]["bbox_obj"][0] = 1e300;
  });
  EXPECT_NE(message.find("scene_gt_info.json"), std::string::npos) << message;
  EXPECT_NE(message.find("bbox_obj"), std::string::npos) << message;
}

// Fields that hold the wrong kind of value are refused by file and name (a string where nlohmann's value() expected a
// number threw past the reader; an object id beyond int's range was narrowed).
TEST(BopFrame, NumbersOfTheWrongKindOrRangeAreRefusedByName) {
  const test::TemporaryDirectory directory;
  EXPECT_EQ(LoadEditedScene(directory, [](const std::string&, nlohmann::json&) {}), "");
  const std::vector<std::tuple<std::string, std::string, nlohmann::json>> cases = {
      {"scene_camera.json", "depth_scale", "1.0"},
      {"scene_gt_info.json", "visib_fract", "high"},
      {"scene_gt.json", "obj_id", 10000000000LL},
      {"scene_gt.json", "obj_id", -1}};
  for (const auto& [target, field, value] : cases) {
    const std::string message = LoadEditedScene(directory, [&](const std::string& file, nlohmann::json& json) {
      if (file != target) return;
      if (field == "depth_scale")
        json["3"][field] = value;
      else
        json["3"][0][field] = value;
    });
    EXPECT_NE(message.find(target), std::string::npos) << field << ": " << message;
    EXPECT_NE(message.find(field), std::string::npos) << field << ": " << message;
  }
}

TEST(BopFrame, AWrongDepthScaleIsWarnedAboutNamingTheFile) {
  FrameSpec spec;
  spec.color_path = test::DataPath("lmo_subset/data/bop/lmo/test/000002/rgb/000003.png");
  spec.depth_path = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");  // millimetres
  spec.camera = "572.4114,573.57043,325.2611,242.04899";
  for (const double scale : {1000.0, 1.0, 0.001, 10000.0, 100000.0}) {
    spec.depth_scale = scale;
    std::vector<std::string> warnings;
    const LoadedFrame loaded = LoadFrame(spec, &warnings);
    const bool wrong = scale != 1000.0 && scale != 10000.0;  // the scene lies at about 1 m: 0.1 m is still plausible
    ASSERT_EQ(warnings.size(), wrong ? 1U : 0U) << "scale " << scale;
    if (wrong) {
      EXPECT_NE(warnings[0].find(spec.depth_path), std::string::npos) << warnings[0];
      EXPECT_NE(warnings[0].find("depth scale"), std::string::npos) << warnings[0];
    }
    EXPECT_EQ(DepthRangeWarning(loaded.rgbd.depth, "x").has_value(), wrong) << "scale " << scale;
  }
  EXPECT_FALSE(DepthRangeWarning(cv::Mat::zeros(4, 4, CV_32FC1), "no depth").has_value());
}

TEST(BopFrame, ModelCentresProjectIntoTheirBoxes) {
  const LoadedFrame loaded = LoadLmoImage3();
  for (const GroundTruth& truth : loaded.ground_truth) {
    const Eigen::Vector2d pixel = loaded.rgbd.camera.Project(truth.camera_from_object.translation());
    const cv::Rect& box = truth.object_box;
    EXPECT_TRUE(pixel.x() >= box.x && pixel.x() <= box.x + box.width && pixel.y() >= box.y &&
                pixel.y() <= box.y + box.height)
        << truth.object_name << " centre at (" << pixel.x() << ", " << pixel.y() << ")";
  }
}

// Millimetre depth and millimetre models both end in metres: the median real depth in the visible box of
// each at-least-half-visible object lies within the z range of its posed model widened by 2 cm.
TEST(BopFrame, MedianDepthInVisibleBoxesLiesWithinPosedModelDepth) {
  const LoadedFrame loaded = LoadLmoImage3();
  MeshLoadOptions millimetres;
  millimetres.metres_per_unit = 0.001;
  int checked = 0;
  for (const GroundTruth& truth : loaded.ground_truth) {
    if (truth.visible_fraction < 0.5) continue;
    const TriangleMesh model = LoadMesh(ModelPath(truth.object_id), millimetres);
    double z_min = 1e9, z_max = -1e9;
    for (const Eigen::Vector3f& point : model.parts[0].positions) {
      const double z = (truth.camera_from_object * point.cast<double>()).z();
      z_min = std::min(z_min, z);
      z_max = std::max(z_max, z);
    }
    cv::Mat mask = cv::Mat::zeros(loaded.rgbd.depth.size(), CV_8UC1);
    mask(truth.visible_box).setTo(255);
    const DepthStats real = ComputeDepthStats(loaded.rgbd.depth, mask);
    EXPECT_GE(real.median_m, z_min - 0.02) << truth.object_name;
    EXPECT_LE(real.median_m, z_max + 0.02) << truth.object_name;
    ++checked;
  }
  EXPECT_EQ(checked, 7);  // all but the ape (visib_fract 0.20)
}

}  // namespace
}  // namespace ecv
