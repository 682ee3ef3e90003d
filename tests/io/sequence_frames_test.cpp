// ListSequenceFrames on real folders: a YCB-Video video, a BOP scene (LM-O, which ships rgb/ but no depth/),
// a directory of frame JSONs and a text list.

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;

std::string ListError(const std::string& path) {
  try {
    ListSequenceFrames(path);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an InputError for " << path;
  return "";
}

TEST(SequenceFrames, YcbVideoFolderGivesItsTenFramesInOrder) {
  const std::string video = test::DataPath("ycbv_subset/Example-Scenes/0001");
  const std::vector<std::string> frames = ListSequenceFrames(video);
  ASSERT_EQ(frames.size(), 10U);
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[16];
    std::snprintf(name, sizeof(name), "%06zu", 2 * i + 1);  // 000001, 000003, ..., 000019
    EXPECT_EQ(frames[i], (fs::path(video) / name).string());
  }
  // Each is a FRAME that loads, with the ground truth of its own -meta.mat.
  FrameSpec spec;
  spec.positional = frames.back();
  EXPECT_EQ(LoadFrame(spec).ground_truth.size(), 4U);
  EXPECT_EQ(ListSequenceFrames(video + "/"), frames) << "a trailing slash changes nothing";
}

TEST(SequenceFrames, BopSceneWithoutDepthFolderIsAClearError) {
  const std::string scene = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  EXPECT_THAT(ListError(scene), AllOf(HasSubstr(scene), HasSubstr("depth/"), HasSubstr("no such folder")));
}

// A copy of the LM-O scene with the depth of image 3 (SAM-6D's example) and an rgb-only image 8: only image 3
// is a frame, and it loads with its 8 ground-truth poses.
TEST(SequenceFrames, BopSceneGivesImagesWithColourAndDepth) {
  test::TemporaryDirectory temporary;
  const fs::path scene = temporary.path() / "000002";
  const fs::path source = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  fs::create_directories(scene / "rgb");
  fs::create_directories(scene / "depth");
  for (const char* file : {"scene_camera.json", "scene_gt.json", "scene_gt_info.json", "rgb/000003.png"}) {
    fs::copy_file(source / file, scene / file);
  }
  fs::copy_file(source / "rgb/000003.png", scene / "rgb/000008.png");  // id 8 is in scene_camera.json
  fs::copy_file(test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png"), scene / "depth/000003.png");
  const std::vector<std::string> frames = ListSequenceFrames(scene.string());
  ASSERT_EQ(frames, std::vector<std::string>{scene.string() + ":3"});
  FrameSpec spec;
  spec.positional = frames[0];
  const LoadedFrame loaded = LoadFrame(spec);
  EXPECT_EQ(loaded.ground_truth.size(), 8U);
  EXPECT_EQ(loaded.rgbd.depth.cols, 640);

  // With depth for image 8 too, both come in increasing id order (not name or file order).
  fs::copy_file(scene / "depth/000003.png", scene / "depth/000008.png");
  EXPECT_EQ(ListSequenceFrames(scene.string()),
            (std::vector<std::string>{scene.string() + ":3", scene.string() + ":8"}));

  // A depth/ folder but no image with both files: an error naming the scene.
  fs::remove(scene / "depth/000003.png");
  fs::remove(scene / "depth/000008.png");
  EXPECT_THAT(ListError(scene.string()), AllOf(HasSubstr(scene.string()), HasSubstr("rgb/ and depth/")));
}

TEST(SequenceFrames, DirectoryOfFrameJsonsInNameOrderAndTextLists) {
  test::TemporaryDirectory temporary;
  const std::string prefix = test::DataPath("ycbv_subset/Example-Scenes/0000/000001");
  for (const char* name : {"b.json", "a.json"}) {
    std::ofstream(temporary.File(name))
        << R"({"color": ")" << prefix << R"(-color.png", "depth": ")" << prefix
        << R"(-depth.png", "depth_scale": 10000, "camera": [1066.8, 1067.5, 313, 241]})";
  }
  std::ofstream(temporary.File("notes.txt")) << "not a frame\n";
  const std::vector<std::string> frames = ListSequenceFrames(temporary.path().string());
  ASSERT_EQ(frames, (std::vector<std::string>{temporary.File("a.json"), temporary.File("b.json")}));
  FrameSpec spec;
  spec.positional = frames[0];
  EXPECT_EQ(LoadFrame(spec).rgbd.color.cols, 640);

  const std::string list = temporary.File("notes.txt");
  std::ofstream(list) << "# frames\n" << frames[1] << "  # the second\n\n  " << prefix << "\n";
  EXPECT_EQ(ListSequenceFrames(list), (std::vector<std::string>{frames[1], prefix}));

  std::ofstream(list) << "# nothing\n\n";
  EXPECT_THAT(ListError(list), AllOf(HasSubstr(list), HasSubstr("at least one FRAME")));
  const std::string empty = temporary.File("empty");
  fs::create_directories(empty);
  EXPECT_THAT(ListError(empty), AllOf(HasSubstr(empty), HasSubstr("*-color.png")));
  EXPECT_THAT(ListError(temporary.File("missing")), HasSubstr("no such file or directory"));
}

}  // namespace
}  // namespace ecv
