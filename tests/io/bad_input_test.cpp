// Broken inputs give an InputError whose message names the file, the field and what was expected.

#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "support/input_error.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

using test::InputErrorMessage;

class BadInput : public ::testing::Test {
 protected:
  const std::string prefix_ = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const std::string color_ = prefix_ + "-color.png";
  const std::string depth_ = prefix_ + "-depth.png";
  const std::array<double, 4> intrinsics_{1066.778, 1067.487, 312.9869, 241.3109};
  test::TemporaryDirectory temporary_;

  void WriteText(const std::string& path, const std::string& text) const { std::ofstream(path) << text; }
};

TEST_F(BadInput, MissingFile) {
  const std::string missing = temporary_.File("nothing-color.png");
  EXPECT_THAT(InputErrorMessage([&] { MakeFrame(missing, depth_, 10000, intrinsics_, "test"); }),
              AllOf(HasSubstr(missing), HasSubstr("colour image"), HasSubstr("no such file")));
  FrameSpec spec;
  spec.positional = temporary_.File("0009/000001");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrame(spec); }),
              AllOf(HasSubstr(spec.positional), HasSubstr("YCB-Video prefix"), HasSubstr("BOP image")));
}

// Paths the system cannot look at (a name longer than it allows) are missing files, never another kind of exception.
TEST_F(BadInput, APathTooLongForTheSystemIsAMissingFile) {
  const std::string too_long = temporary_.File(std::string(300, 'c') + "-color.png");
  EXPECT_THAT(InputErrorMessage([&] { MakeFrame(too_long, depth_, 10000, intrinsics_, "test"); }),
              AllOf(HasSubstr(too_long), HasSubstr("no such file")));
  const std::string path = temporary_.File("frame.json");
  WriteText(path, R"({"color": ")" + std::string(300, 'c') +
                      R"(.png", "depth": "b.png", "depth_scale": 1000, "camera": [1, 2, 3, 4]})");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(path); }), HasSubstr("no such file"));
  FrameSpec spec;
  spec.positional = temporary_.File(std::string(300, 'p') + "/000001");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrame(spec); }), HasSubstr(spec.positional));
  EXPECT_THAT(InputErrorMessage([&] { ReadJsonFile(too_long); }), HasSubstr("no such file"));
}

TEST_F(BadInput, EightBitDepthWhereSixteenBitIsExpected) {
  const std::string depth8 = temporary_.File("depth8.png");
  cv::imwrite(depth8, cv::Mat(480, 640, CV_8UC1, cv::Scalar(100)));
  EXPECT_THAT(InputErrorMessage([&] { MakeFrame(color_, depth8, 1000, intrinsics_, "test"); }),
              AllOf(HasSubstr(depth8), HasSubstr("expected a 16-bit single-channel PNG"), HasSubstr("got 8-bit")));
}

TEST_F(BadInput, ColourAndDepthSizesDiffer) {
  const std::string small_depth = temporary_.File("small-depth.png");
  cv::imwrite(small_depth, cv::Mat(240, 320, CV_16UC1, cv::Scalar(1000)));
  EXPECT_THAT(InputErrorMessage([&] { MakeFrame(color_, small_depth, 1000, intrinsics_, "test"); }),
              AllOf(HasSubstr(small_depth), HasSubstr("640x480"), HasSubstr("320x240")));
}

TEST_F(BadInput, MalformedFrameJson) {
  const std::string path = temporary_.File("frame.json");
  WriteText(path, "{\"color\": \"a.png\", \"depth\": \n  \"b.png\",, }");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(path); }),
              AllOf(HasSubstr(path), HasSubstr("well-formed JSON"), HasSubstr("line 2")));
  WriteText(path, R"({"color": "a.png", "depth": "b.png", "depth_scale": 1000, "camera": [1, 2, 3]})");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(path); }),
              AllOf(HasSubstr(path), HasSubstr("camera"), HasSubstr("[fx, fy, cx, cy]")));
  const std::string frame = R"({"color": ")" + color_ + R"(", "depth": ")" + depth_ +
                            R"(", "depth_scale": 10000, "camera": [1066.8, 1067.5, 313, 241])";
  WriteText(path, frame + R"(, "scene_id": -1, "image_id": 2})");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(path); }), AllOf(HasSubstr("scene_id"), HasSubstr(">= 0")));
  WriteText(path, frame + R"(, "scene_id": 4})");
  EXPECT_THAT(InputErrorMessage([&] { LoadFrameJson(path); }), HasSubstr("image_id"));
  WriteText(path, frame + R"(, "image_id": 7})");
  const LoadedFrame ids = LoadFrameJson(path);
  EXPECT_EQ(ids.scene_id, 0);  // an image id alone: scene 0
  EXPECT_EQ(ids.image_id, 7);
}

TEST_F(BadInput, NanInIntrinsics) {
  EXPECT_THAT(InputErrorMessage([&] {
                MakeFrame(color_, depth_, 10000, {std::nan(""), 1067.487, 312.9869, 241.3109}, "frame.json");
              }),
              AllOf(HasSubstr("frame.json"), HasSubstr("fx"), HasSubstr("finite positive"), HasSubstr("nan")));
  FrameSpec spec;
  spec.color_path = color_;
  spec.depth_path = depth_;
  spec.depth_scale = 10000;
  spec.camera = "1066.778,nan,312.9,241.3";
  EXPECT_THAT(InputErrorMessage([&] { LoadFrame(spec); }), AllOf(HasSubstr("fy"), HasSubstr("nan")));
  spec.camera = "1066.778,1067";
  EXPECT_THAT(InputErrorMessage([&] { LoadFrame(spec); }), HasSubstr("four numbers fx,fy,cx,cy"));
}

TEST_F(BadInput, MissingTexture) {
  const std::string path = test::DataPath("ycbv_subset/models/003_cracker_box/textured_simple.obj");
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(path); }),
              AllOf(HasSubstr(path), HasSubstr("material_0"), HasSubstr("texture_map.png"),
                    HasSubstr("--allow-missing-textures")));
}

TEST_F(BadInput, OtherBrokenInputs) {
  // A mesh file that is not one.
  const std::string not_mesh = temporary_.File("broken.obj");
  WriteText(not_mesh, "this is not a mesh\n");
  EXPECT_THAT(InputErrorMessage([&] { LoadMesh(not_mesh); }), HasSubstr(not_mesh));
  // A cloud without colour.
  const std::string milk = test::DataPath("pcl_milk_scene/test/milk.pcd");
  EXPECT_THAT(InputErrorMessage([&] { LoadPcdFrame(milk); }), AllOf(HasSubstr(milk), HasSubstr("rgb")));
  // A BOP image that the scene does not list.
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  EXPECT_THAT(InputErrorMessage([&] { LoadBopFrame(scene, 999999); }),
              AllOf(HasSubstr("scene_camera.json"), HasSubstr("999999")));
  // Frame flags and a positional frame together.
  FrameSpec both;
  both.positional = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  both.camera = "1,1,1,1";
  EXPECT_THAT(InputErrorMessage([&] { LoadFrame(both); }), HasSubstr("not both"));
  // A non-positive depth scale.
  EXPECT_THAT(InputErrorMessage([&] { ReadDepthImage(depth_, 0.0); }), HasSubstr("depth_scale"));
  // A pose that is not rigid.
  const std::string pose = temporary_.File("pose.json");
  WriteText(pose, R"({"camera_from_object": [[2,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})");
  EXPECT_THAT(InputErrorMessage([&] { ReadPoseFile(pose); }),
              AllOf(HasSubstr(pose), HasSubstr("camera_from_object"), HasSubstr("rotation")));
  // An unknown unit.
  EXPECT_THAT(InputErrorMessage([&] { MetresPerUnit("inch"); }), HasSubstr("m, cm or mm"));
}

}  // namespace
}  // namespace ecv
