// Real YCB-Video frames: intrinsics, depth scale and ground truth read from -meta.mat agree with the
// label image and the depth image; an object pasted from another frame; a frame JSON written and read back.

#include <algorithm>
#include <filesystem>
#include <map>

#include <matio.h>

#include <gtest/gtest.h>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/frame.h"
#include "io/frame_io.h"
#include "io/points_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

std::string FramePrefix(const std::string& video, int frame) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d", frame);
  return test::DataPath("ycbv_subset/Example-Scenes/" + video) + "/" + name;
}

const std::vector<Eigen::Vector3d>& ModelPoints(const std::string& name) {
  static std::map<std::string, std::vector<Eigen::Vector3d>> cache;
  auto found = cache.find(name);
  if (found == cache.end()) {
    found = cache.emplace(name, ReadXyzFile(test::DataPath("ycbv_subset/models/" + name + "/points.xyz"))).first;
  }
  return found->second;
}

TEST(YcbvFrame, ReadsImagesIntrinsicsAndDepthScale) {
  FrameSpec spec;
  spec.positional = FramePrefix("0001", 1);
  const LoadedFrame loaded = LoadFrame(spec);
  const RgbdFrame& frame = loaded.rgbd;
  EXPECT_EQ(frame.color.size(), cv::Size(640, 480));
  EXPECT_EQ(frame.depth.type(), CV_32FC1);
  EXPECT_NEAR(frame.camera.fx, 1066.778, 1e-3);
  EXPECT_NEAR(frame.camera.fy, 1067.487, 1e-3);
  EXPECT_NEAR(frame.camera.cx, 312.9869, 1e-3);
  EXPECT_NEAR(frame.camera.cy, 241.3109, 1e-3);
  // Depth = PNG value / 10000: compare one pixel with the raw PNG.
  const cv::Mat raw = cv::imread(spec.positional + "-depth.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(raw.type(), CV_16UC1);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(240, 320), raw.at<uint16_t>(240, 320) / 10000.0F);
  // Colour is RGB: the PNG on disk decodes as BGR in OpenCV.
  const cv::Mat bgr = cv::imread(spec.positional + "-color.png", cv::IMREAD_COLOR);
  EXPECT_EQ(frame.color.at<cv::Vec3b>(100, 100)[0], bgr.at<cv::Vec3b>(100, 100)[2]);
  EXPECT_EQ(frame.color.at<cv::Vec3b>(100, 100)[2], bgr.at<cv::Vec3b>(100, 100)[0]);

  std::vector<std::string> names;
  for (const GroundTruth& truth : loaded.ground_truth) names.push_back(truth.object_name);
  EXPECT_EQ(names, (std::vector<std::string>{"002_master_chef_can", "003_cracker_box", "004_sugar_box",
                                             "006_mustard_bottle"}));
  EXPECT_EQ(loaded.scene_id, 1);  // the video and frame numbers: BOP's scene and image ids
  EXPECT_EQ(loaded.image_id, 1);
}

// A copy of frame 0001/000001's images in `directory`; its prefix.
std::string CopyOfFrameImages(const test::TemporaryDirectory& directory) {
  const std::string prefix = directory.File("000001"), source = FramePrefix("0001", 1);
  for (const char* suffix : {"-color.png", "-depth.png"}) {
    std::filesystem::copy_file(source + suffix, prefix + suffix);
  }
  return prefix;
}

// The message of LoadYcbvFrame's InputError on `prefix`, or a failure.
std::string Refusal(const std::string& prefix) {
  try {
    LoadYcbvFrame(prefix);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

// A meta file whose object list is longer than any frame's is refused before its values are read (a broken file
// costs at most a few hundred kilobytes).
TEST(YcbvFrame, AMetaFileWithMoreObjectsThanAFrameHoldsIsRefused) {
  test::TemporaryDirectory directory;
  const std::string prefix = CopyOfFrameImages(directory);
  mat_t* file = Mat_CreateVer((prefix + "-meta.mat").c_str(), nullptr, MAT_FT_MAT5);
  ASSERT_NE(file, nullptr);
  const auto write = [&](const char* name, std::vector<size_t> dims, std::vector<double> values) {
    matvar_t* variable =
        Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, static_cast<int>(dims.size()), dims.data(), values.data(), 0);
    Mat_VarWrite(file, variable, MAT_COMPRESSION_NONE);
    Mat_VarFree(variable);
  };
  write("intrinsic_matrix", {3, 3}, {1066.778, 0, 0, 0, 1067.487, 0, 312.9869, 241.3109, 1});
  write("factor_depth", {1, 1}, {10000});
  write("cls_indexes", {1001, 1}, std::vector<double>(1001, 2.0));
  write("poses", {3, 4, 1001}, std::vector<double>(12 * 1001, 0.0));
  Mat_Close(file);
  const std::string message = Refusal(prefix);
  EXPECT_NE(message.find("cls_indexes"), std::string::npos) << message;
  EXPECT_NE(message.find("at most 1000 values"), std::string::npos) << message;
}

// A MAT-file at `path` of `version` holding only factor_depth.
void WriteFactorDepth(const std::string& path, mat_ft version, matio_compression compression = MAT_COMPRESSION_NONE) {
  mat_t* file = Mat_CreateVer(path.c_str(), nullptr, version);
  ASSERT_NE(file, nullptr);
  size_t dims[2] = {1, 1};
  double factor = 10000;
  matvar_t* variable = Mat_VarCreate("factor_depth", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, &factor, 0);
  Mat_VarWrite(file, variable, compression);
  Mat_VarFree(variable);
  Mat_Close(file);
}

// Version 4 MAT-files (no text header), which matio reads by their own counts alone, are refused before it sees them.
TEST(YcbvFrame, AVersion4MetaFileIsRefusedNamingTheVersion) {
  test::TemporaryDirectory directory;
  const std::string prefix = CopyOfFrameImages(directory);
  WriteFactorDepth(prefix + "-meta.mat", MAT_FT_MAT4);
  const std::string message = Refusal(prefix);
  EXPECT_NE(message.find("version 5 or later"), std::string::npos) << message;
  EXPECT_NE(message.find("no such header"), std::string::npos) << message;
}

// A version 5 meta file whose counts claim more than it holds (matio allocates by them: a 318-byte file found by
// fuzzing asked for 4 GB) is refused before matio reads it, naming the file and the element.
TEST(YcbvFrame, AMetaFileWhoseCountsExceedItIsRefusedBeforeMatioReadsIt) {
  test::TemporaryDirectory directory;
  const std::string prefix = CopyOfFrameImages(directory);
  const std::string meta = prefix + "-meta.mat";
  auto write = [&](matio_compression compression) { WriteFactorDepth(meta, MAT_FT_MAT5, compression); };
  auto patch = [&](size_t offset, std::vector<uint32_t> words) {
    std::fstream file(meta, std::ios::in | std::ios::out | std::ios::binary);
    file.seekp(static_cast<std::streamoff>(offset));
    file.write(reinterpret_cast<const char*>(words.data()), static_cast<std::streamsize>(4 * words.size()));
  };
  // Uncompressed: the matrix's tag at byte 128, its array flags at 136, dimensions at 152, name at 168.
  write(MAT_COMPRESSION_NONE);
  patch(172, {0xffffff00U});
  std::string message = Refusal(prefix);
  EXPECT_NE(message.find(meta), std::string::npos) << message;
  EXPECT_NE(message.find("element at byte 168"), std::string::npos) << message;
  EXPECT_NE(message.find("4294967040 bytes"), std::string::npos) << message;
  write(MAT_COMPRESSION_NONE);
  patch(160, {100000, 100000});
  message = Refusal(prefix);
  EXPECT_NE(message.find("values in"), std::string::npos) << message;
  write(MAT_COMPRESSION_NONE);
  patch(132, {0x7fffffffU});
  EXPECT_NE(Refusal(prefix).find("element at byte 128"), std::string::npos);
  // Compressed: the deflate stream cut short by a wrong size, and broken inside.
  write(MAT_COMPRESSION_ZLIB);
  const uintmax_t size = std::filesystem::file_size(meta);
  std::filesystem::resize_file(meta, size - 6);
  patch(132, {static_cast<uint32_t>(size - 6 - 136)});
  message = Refusal(prefix);
  EXPECT_NE(message.find("does not inflate whole"), std::string::npos) << message;
  write(MAT_COMPRESSION_ZLIB);
  patch(144, {0xffffffffU, 0xffffffffU});
  EXPECT_NE(Refusal(prefix).find("MAT-file element at byte 128"), std::string::npos);
  // Version 7.3 (HDF5) is refused by name: the HDF5 library trusts what it reads.
  WriteFactorDepth(meta, MAT_FT_MAT73);
  message = Refusal(prefix);
  EXPECT_NE(message.find("version 7.3 (HDF5)"), std::string::npos) << message;
}

// The check on 0001/000001: each object's origin projects onto its own label pixels.
TEST(YcbvFrame, GroundTruthOriginsProjectOntoTheirLabels) {
  const std::string prefix = FramePrefix("0001", 1);
  const LoadedFrame loaded = LoadYcbvFrame(prefix);
  const cv::Mat label = cv::imread(prefix + "-label.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(loaded.ground_truth.size(), 4U);
  for (const GroundTruth& truth : loaded.ground_truth) {
    const Eigen::Vector2d pixel = loaded.rgbd.camera.Project(truth.camera_from_object.translation());
    ASSERT_TRUE(loaded.rgbd.camera.Contains(pixel)) << truth.object_name;
    const int u = static_cast<int>(std::lround(pixel.x())), v = static_cast<int>(std::lround(pixel.y()));
    EXPECT_EQ(label.at<uint8_t>(v, u), truth.object_id) << truth.object_name << " at (" << u << ", " << v << ")";
  }
}

// On all 30 frames: the median real depth over an object's label pixels lies within the z range of its
// points.xyz under the ground-truth pose, widened by 1 cm. A wrong depth scale or pose convention fails.
TEST(YcbvFrame, MedianDepthOverLabelsLiesWithinPosedModelDepth) {
  int checked = 0;
  for (const char* video : {"0000", "0001", "0002"}) {
    for (int frame_number = 1; frame_number <= 19; frame_number += 2) {
      const std::string prefix = FramePrefix(video, frame_number);
      const LoadedFrame loaded = LoadYcbvFrame(prefix);
      const cv::Mat label = cv::imread(prefix + "-label.png", cv::IMREAD_UNCHANGED);
      for (const GroundTruth& truth : loaded.ground_truth) {
        const cv::Mat mask = label == truth.object_id;
        if (cv::countNonZero(mask) < 200) continue;  // hardly visible: the median says little
        const DepthStats real = ComputeDepthStats(loaded.rgbd.depth, mask);
        double z_min = 1e9, z_max = -1e9;
        for (const Eigen::Vector3d& point : ModelPoints(truth.object_name)) {
          const double z = (truth.camera_from_object * point).z();
          z_min = std::min(z_min, z);
          z_max = std::max(z_max, z);
        }
        EXPECT_GE(real.median_m, z_min - 0.01) << prefix << " " << truth.object_name;
        EXPECT_LE(real.median_m, z_max + 0.01) << prefix << " " << truth.object_name;
        ++checked;
      }
    }
  }
  EXPECT_GE(checked, 100);  // 10 frames x (3 + 4 + 6) objects, less the hardly visible ones
}

// The mustard bottle of 0002/000001 pasted into 0001/000001 (which has one too): exactly its label pixels change,
// to the source's colour and depth, and its ground truth is added.
TEST(YcbvFrame, PastedObjectBringsItsPixelsAndGroundTruth) {
  const LoadedFrame into = LoadYcbvFrame(FramePrefix("0001", 1));
  const LoadedFrame source = LoadYcbvFrame(FramePrefix("0002", 1));
  const LoadedFrame pasted = PasteYcbvObject(into, FramePrefix("0002", 1), "006_mustard_bottle");
  ASSERT_EQ(pasted.ground_truth.size(), into.ground_truth.size() + 1);
  EXPECT_EQ(pasted.ground_truth.back().object_name, "006_mustard_bottle");
  EXPECT_TRUE(pasted.ground_truth.back().camera_from_object.isApprox(
      std::find_if(source.ground_truth.begin(), source.ground_truth.end(), [](const GroundTruth& g) {
        return g.object_name == "006_mustard_bottle";
      })->camera_from_object));
  const cv::Mat label = cv::imread(FramePrefix("0002", 1) + "-label.png", cv::IMREAD_UNCHANGED);
  const cv::Mat bottle = label == 5;  // class index of 006_mustard_bottle
  int changed = 0, outside = 0;
  for (int v = 0; v < label.rows; ++v) {
    for (int u = 0; u < label.cols; ++u) {
      const bool in = bottle.at<uchar>(v, u) != 0;
      const RgbdFrame& expected = in ? source.rgbd : into.rgbd;
      EXPECT_EQ(pasted.rgbd.depth.at<float>(v, u), expected.depth.at<float>(v, u)) << u << "," << v;
      EXPECT_EQ(pasted.rgbd.color.at<cv::Vec3b>(v, u), expected.color.at<cv::Vec3b>(v, u)) << u << "," << v;
      changed += in ? 1 : 0;
      outside += in ? 0 : 1;
    }
  }
  EXPECT_GT(changed, 5000);
  EXPECT_GT(outside, 250000);
  // The banana is not in video 0001's frame: nothing to paste; a BOP frame's camera is another camera.
  EXPECT_THROW(PasteYcbvObject(into, FramePrefix("0001", 1), "011_banana"), InputError);
  LoadedFrame other_camera = into;
  other_camera.rgbd.camera.fx += 1.0;
  try {
    PasteYcbvObject(other_camera, FramePrefix("0002", 1), "006_mustard_bottle");
    FAIL() << "pasted across cameras";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("intrinsic_matrix"), std::string::npos) << error.what();
  }
}

TEST(YcbvFrame, FrameJsonRoundTripKeepsColourExactlyAndDepthToATenthOfAMillimetre) {
  const LoadedFrame frame = LoadYcbvFrame(FramePrefix("0000", 1));
  const test::TemporaryDirectory directory;
  const std::string path = directory.File("frame.json");
  WriteFrameJson(path, frame.rgbd);
  const LoadedFrame read = LoadFrameJson(path);
  EXPECT_EQ(cv::norm(read.rgbd.color, frame.rgbd.color, cv::NORM_INF), 0.0);
  EXPECT_LE(cv::norm(read.rgbd.depth, frame.rgbd.depth, cv::NORM_INF), 0.5e-4 + 1e-7);
  EXPECT_EQ(read.rgbd.camera.fx, frame.rgbd.camera.fx);
  EXPECT_EQ(read.rgbd.camera.cy, frame.rgbd.camera.cy);
  EXPECT_THROW(WriteFrameJson(path, frame.rgbd, 1e6), InputError);  // metres x 1e6 overflow 16 bits
}

}  // namespace
}  // namespace ecv
