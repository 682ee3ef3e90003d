// `ecvpose record` and `ecvpose recognize --sequence FILE.oni | openni2://` through the command line.

#include <chrono>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/demo_library.h"

namespace ecv {
namespace {

class CameraCli : public test::DemoLibrarySuite {
 protected:
  // A list file of the first three frames of YCB-Video video 0001 (frame prefixes, one a line).
  static std::string FrameList() {
    const std::string list = directory_->File("frames.txt");
    std::ofstream out(list);
    for (const char* id : {"000001", "000003", "000005"}) {
      const std::string color = test::DataPath("ycbv_subset/Example-Scenes/0001/" + std::string(id) + "-color.png");
      out << color.substr(0, color.size() - std::string("-color.png").size()) << '\n';
    }
    return list;
  }

  // The detections of each line of a JSON Lines file.
  static std::vector<nlohmann::json> Detections(const std::string& path) {
    std::vector<nlohmann::json> detections;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);) detections.push_back(nlohmann::json::parse(line).at("detections"));
    return detections;
  }
};

TEST_F(CameraCli, RecordingRecognisesAsTheFrameFiles) {
  const std::string list = FrameList(), recording = directory_->File("video.oni");
  const test::CommandResult record = test::RunCli("record --sequence " + list + " --out " + recording);
  ASSERT_EQ(record.exit_code, 0) << record.output;
  EXPECT_NE(record.output.find("[3/3]"), std::string::npos) << record.output;  // progress
  EXPECT_NE(record.output.find("exact"), std::string::npos) << record.output;
  EXPECT_TRUE(std::filesystem::exists(recording + ".json"));
  EXPECT_FALSE(std::filesystem::exists(recording + ".tmp"));

  const std::string from_files = directory_->File("files.jsonl"), from_oni = directory_->File("oni.jsonl");
  const test::CommandResult files =
      test::RunCli("recognize --db " + library_ + " --sequence " + list + " --out-json " + from_files);
  ASSERT_EQ(files.exit_code, 0) << files.output;
  const test::CommandResult oni =
      test::RunCli("recognize --db " + library_ + " --sequence " + recording + " --out-json " + from_oni);
  ASSERT_EQ(oni.exit_code, 0) << oni.output;
  EXPECT_NE(oni.output.find("from " + recording + ".json"), std::string::npos) << oni.output;  // where K came from
  const std::vector<nlohmann::json> expected = Detections(from_files), got = Detections(from_oni);
  ASSERT_EQ(got.size(), 3u);
  ASSERT_EQ(expected.size(), 3u);
  int detections = 0;
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i], expected[i]) << "frame " << i;
    detections += static_cast<int>(got[i].size());
  }
  EXPECT_GE(detections, 3);  // the demo objects are found, so the comparison compares something
}

// Sources are opened before the library is read: these need no library (the path leads nowhere).
constexpr const char* kNoLibrary = "/nonexistent/library.sqlite";

TEST(CameraCliErrors, NoDeviceIsAClearErrorWithinSeconds) {
  test::TemporaryDirectory directory;
  for (const std::string& source : {std::string("openni2://"), std::string("openni2://1d27/0600@9/9")}) {
    const auto start = std::chrono::steady_clock::now();
    const test::CommandResult run = test::RunCli(std::string("recognize --db ") + kNoLibrary + " --sequence " + source);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_LT(seconds, 5.0) << run.output;
    EXPECT_NE(run.output.find(source + ": device: expected a connected OpenNI2 device"), std::string::npos)
        << run.output;
    EXPECT_EQ(run.output.find("meshes loaded"), std::string::npos) << run.output;  // before the library is loaded
  }
  const test::CommandResult record =
      test::RunCli("record --sequence openni2:// --frames 3 --out " + directory.File("live.oni"));
  EXPECT_EQ(record.exit_code, 1) << record.output;
  EXPECT_FALSE(std::filesystem::exists(directory.File("live.oni")));
  const test::CommandResult unbounded = test::RunCli("record --sequence openni2:// --out " + directory.File("a.oni"));
  EXPECT_EQ(unbounded.exit_code, 2) << unbounded.output;
  EXPECT_NE(unbounded.output.find("--frames"), std::string::npos) << unbounded.output;
}

TEST(CameraCliErrors, BrokenRecordingsExitOne) {
  test::TemporaryDirectory directory;
  const std::string cut = directory.File("cut.oni"), garbage = directory.File("garbage.oni");
  {
    std::ofstream out(cut, std::ios::binary);
    out.write("NI10\x01\x00\x01\x00\x00\x00\x00\x00", 12);  // a header cut short
  }
  std::ofstream(garbage, std::ios::binary) << std::string(1000, 'x');
  for (const std::string& file : {cut, garbage, directory.File("missing.oni")}) {
    const test::CommandResult run = test::RunCli(std::string("recognize --db ") + kNoLibrary + " --sequence " + file);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find("ecvpose: error: " + file), std::string::npos) << run.output;
  }
  const test::CommandResult follow =
      test::RunCli(std::string("recognize --db ") + kNoLibrary + " --sequence " + garbage + " --follow");
  EXPECT_EQ(follow.exit_code, 1) << follow.output;
}

}  // namespace
}  // namespace ecv
