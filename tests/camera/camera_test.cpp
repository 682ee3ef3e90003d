// The .oni writer and OpenNiCamera: recordings of real frames play back through OpenNI2's file driver to the pixel;
// an unfinished recording leaves nothing; broken files are InputErrors, never a crash.

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "camera/oni_check.h"
#include "camera/oni_writer.h"
#include "camera/openni_camera.h"
#include "camera/recording.h"
#include "support/input_error.h"
#include "support/test_data.h"

namespace ecv {
namespace {

// The first three frames of YCB-Video video 0001 (every other frame is in the shared data: 1, 3, 5).
std::vector<std::string> VideoFrames() {
  std::vector<std::string> frames;
  for (const char* id : {"000001", "000003", "000005"}) {
    frames.push_back(test::DataPath("ycbv_subset/Example-Scenes/0001/" + std::string(id) + "-color.png"));
    frames.back().resize(frames.back().size() - std::string("-color.png").size());
  }
  return frames;
}

// A FrameSource over frame files, as the CLI's --sequence reads them.
class FileFrames : public FrameSource {
 public:
  explicit FileFrames(std::vector<std::string> frames) : frames_(std::move(frames)) {}
  std::optional<std::string> Next() override {
    if (next_ == frames_.size()) return std::nullopt;
    return frames_[next_++];
  }
  LoadedFrame Load() override {
    FrameSpec spec;
    spec.positional = frames_[next_ - 1];
    return LoadFrame(spec);
  }
  std::string Counter() const override { return "[" + std::to_string(next_) + "] "; }

 private:
  std::vector<std::string> frames_;
  size_t next_ = 0;
};

TEST(OniRecording, PlaysBackThroughOpenNi2PixelForPixel) {
  test::TemporaryDirectory directory;
  const std::string recording = directory.File("video.oni");
  FileFrames source(VideoFrames());
  RecordOptions options;
  options.out = recording;
  const RecordResult result = RecordFrames(source, options, nullptr);
  EXPECT_EQ(result.frames, 3);
  EXPECT_TRUE(result.depth_exact);  // YCB-Video's 16-bit depth at 10 000 per metre fits 0.1 mm units exactly
  EXPECT_EQ(result.depth_unit, OniDepthUnit::kHundredMicrometres);
  EXPECT_EQ(CheckOniFile(recording).frames, 6);  // a depth and a colour record per frame

  CameraOptions camera_options;
  camera_options.source = recording;
  OpenNiCamera camera(camera_options);  // openni::Device::open(path): OpenNI2's OniFile driver
  EXPECT_EQ(camera.num_frames(), 3);
  EXPECT_EQ(camera.intrinsics_source(), CalibrationPath(recording));
  for (const std::string& prefix : VideoFrames()) {
    FrameSpec spec;
    spec.positional = prefix;
    const RgbdFrame expected = LoadFrame(spec).rgbd;
    const std::optional<LoadedFrame> played = camera.Next();
    ASSERT_TRUE(played) << prefix;
    const RgbdFrame& frame = played->rgbd;
    EXPECT_EQ(cv::countNonZero(cv::Mat(frame.color != expected.color).reshape(1)), 0) << prefix;
    EXPECT_EQ(cv::countNonZero(frame.depth != expected.depth), 0) << prefix;  // the same floats, metres
    EXPECT_GT(cv::countNonZero(frame.depth), 100000) << prefix;
    EXPECT_EQ(frame.camera.fx, expected.camera.fx);
    EXPECT_EQ(frame.camera.cy, expected.camera.cy);
  }
  EXPECT_FALSE(camera.Next());  // the recording plays once
}

TEST(OniRecording, WithoutCalibrationFileTakesKFromTheFieldsOfView) {
  test::TemporaryDirectory directory;
  const std::string recording = directory.File("one.oni");
  FileFrames source({VideoFrames().front()});
  RecordOptions options;
  options.out = recording;
  const PinholeCamera written = RecordFrames(source, options, nullptr).camera;
  std::filesystem::remove(CalibrationPath(recording));
  CameraOptions camera_options;
  camera_options.source = recording;
  OpenNiCamera camera(camera_options);
  EXPECT_EQ(camera.intrinsics_source(), "fields of view");
  // OpenNI2 keeps the fields of view as floats: the focal lengths come back within a few thousandths of a pixel.
  EXPECT_NEAR(camera.camera().fx, written.fx, 0.01);
  EXPECT_NEAR(camera.camera().fy, written.fy, 0.01);
  EXPECT_DOUBLE_EQ(camera.camera().cx, 319.5);
  camera_options.intrinsics = std::array<double, 4>{500.0, 501.0, 320.0, 240.0};
  EXPECT_EQ(OpenNiCamera(camera_options).camera().fy, 501.0);
}

TEST(OniRecording, MillimetreDepthIsRecordedInMillimetres) {
  cv::Mat depth(4, 4, CV_32F), back;
  cv::Mat(4, 4, CV_16U, cv::Scalar(1234)).convertTo(depth, CV_32F, 1.0 / 1000.0);  // as a millimetre PNG reads
  bool exact = false;
  EXPECT_EQ(ExactDepthUnit(depth, &exact), OniDepthUnit::kMillimetre);
  EXPECT_TRUE(exact);
  DepthValues(depth, OniDepthUnit::kMillimetre, "test").convertTo(back, CV_32F, 1.0 / 1000.0);
  EXPECT_EQ(cv::countNonZero(back != depth), 0);
}

TEST(OniRecording, UnfinishedRecordingLeavesNothing) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("cut.oni");
  {
    OniWriterOptions options;
    options.width = 8;
    options.height = 6;
    OniWriter writer(path, options);
    writer.Write(cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)), cv::Mat(6, 8, CV_16U, cv::Scalar(5)));
    EXPECT_NE(test::InputErrorMessage([&] {
                writer.Write(cv::Mat(6, 8, CV_8UC3), cv::Mat(5, 8, CV_16U));
              }).find("depth image"),
              std::string::npos);
  }  // destroyed without Finish
  EXPECT_TRUE(std::filesystem::is_empty(directory.path()));
  OniWriterOptions too_large;
  too_large.width = 4000;
  too_large.height = 3000;
  EXPECT_NE(test::InputErrorMessage([&] { too_large.Check(); }).find("1600x1200"), std::string::npos);
}

TEST(OniRecording, BrokenFilesAreInputErrors) {
  test::TemporaryDirectory directory;
  const std::string recording = directory.File("good.oni");
  FileFrames source({VideoFrames().front()});
  RecordOptions options;
  options.out = recording;
  RecordFrames(source, options, nullptr);
  std::string bytes;
  {
    std::ifstream in(recording, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(directory.File(name), std::ios::binary) << content;
    return directory.File(name);
  };
  const std::string cut = write("cut.oni", bytes.substr(0, bytes.size() / 2));
  EXPECT_NE(test::InputErrorMessage([&] { CheckOniFile(cut); }).find("cut short"), std::string::npos);
  const std::string garbage = write("garbage.oni", std::string(4096, '\x5a'));
  EXPECT_NE(test::InputErrorMessage([&] { CheckOniFile(garbage); }).find("NI10"), std::string::npos);
  std::string huge_record = bytes;
  huge_record[24 + 15] = '\x7f';  // the first record's fields size (top byte), far beyond the player's buffer
  const std::string huge = write("huge.oni", huge_record);
  EXPECT_NE(test::InputErrorMessage([&] { CheckOniFile(huge); }).find("byte 24"), std::string::npos);
  CameraOptions camera_options;
  camera_options.source = cut;
  EXPECT_NE(test::InputErrorMessage([&] { OpenNiCamera camera(camera_options); }).find(cut), std::string::npos);
}

}  // namespace
}  // namespace ecv
