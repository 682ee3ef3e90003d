// The request lines of `ecvpose serve` (ParseRequest, recognize/serve_request.h): what each form asks, and the hostile
// lines of fuzz/corpus/serve_request, each refused with a message naming its key, through the fuzz harness too.

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "recognize/serve_request.h"
#include "support/input_error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);  // fuzz/fuzz_serve_request.cpp

namespace ecv {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;

const fs::path kCorpus = fs::path(ECV_SOURCE_DIR) / "fuzz" / "corpus" / "serve_request";

std::string Line(const std::string& name) {
  std::ifstream in(kCorpus / name, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The request a line asks, with a frame in memory decoded.
ServeRequest Parse(const std::string& line, const RequestLimits& limits = {}) {
  ServeRequest request;
  ParseRequest(line, limits, &request);
  if (request.in_memory) DecodeFrameBytes(*request.in_memory);
  return request;
}

TEST(ServeRequest, EachFormGivesWhatItAsks) {
  const ServeRequest frame = Parse(Line("good-frame"));
  EXPECT_EQ(frame.id, 1);
  EXPECT_EQ(frame.frame.positional, "models/frame/000001");
  EXPECT_EQ(frame.track, true);
  EXPECT_FALSE(frame.reset);
  EXPECT_FALSE(frame.in_memory);

  const ServeRequest files = Parse(Line("good-files"));
  EXPECT_EQ(files.id, "b");
  EXPECT_EQ(files.frame.color_path, "c.png");
  EXPECT_EQ(files.frame.depth_path, "d.png");
  EXPECT_EQ(files.frame.depth_scale, 10000.0);
  EXPECT_EQ(ParseIntrinsics(*files.frame.camera, "test"),
            (std::array<double, 4>{1066.778, 1067.487, 312.9869, 241.3109}));
  EXPECT_FALSE(files.track);  // the service's default
  EXPECT_TRUE(files.reset);

  ServeRequest memory;
  ParseRequest(Line("good-in-memory"), {}, &memory);
  EXPECT_EQ(memory.id, nlohmann::json::array({3}));
  ASSERT_TRUE(memory.in_memory);
  const RgbdFrame decoded = DecodeFrameBytes(*memory.in_memory);
  ASSERT_EQ(decoded.color.size(), cv::Size(2, 2));
  EXPECT_EQ(decoded.color.at<cv::Vec3b>(0, 0), cv::Vec3b(200, 30, 10));  // RGB as the PNG stores it
  EXPECT_FLOAT_EQ(decoded.depth.at<float>(0, 1), 1.1F);                  // 1100 / 1000 per metre
  EXPECT_EQ(decoded.camera.fx, 2.0);
}

// Each hostile line of the corpus is an InputError naming the request and what was wrong, with the id echoed where
// the line gave one before the fault; the answer line reads back as JSON (valid UTF-8) whatever the line held.
TEST(ServeRequest, HostileLinesAreRefusedNamingTheKey) {
  const std::map<std::string, std::string> expected = {
      {"not-json", "request: JSON: expected one JSON object per line"},
      {"empty", "request: JSON: expected one JSON object per line"},
      {"not-an-object", "request: JSON: expected an object, got [1,2]"},
      {"deep-nesting", "request: JSON: expected [ and { nested at most 64 deep, got deeper"},
      {"deep-id", "request: JSON: expected [ and { nested at most 64 deep"},
      {"huge-number", "request: JSON: expected one JSON object per line"},
      {"huge-camera", "request: JSON: expected one JSON object per line"},
      {"zero-camera", "request: camera: expected fx and fy finite and positive"},
      {"negative-depth-scale", "request: depth_scale: expected a finite positive scale"},
      {"frame-not-a-string", "request: frame: expected a FRAME string, got 7"},
      {"track-not-a-flag", "request: track: expected true or false, got \"yes\""},
      {"camera-not-an-array", "request: camera: expected [fx, fy, cx, cy] in pixels"},
      {"missing-depth", "request: depth: expected a path string"},
      {"missing-frame", "request: color: expected a path string (or \"frame\": FRAME instead of the frame keys)"},
      {"missing-depth-png", "request: depth_png: expected base64 of a PNG file"},
      {"unknown-key", "request: fram: expected one of id, frame, color, depth"},
      {"both-forms", "request: frame: expected \"color_png\" and \"depth_png\" or paths, not both"},
      {"bad-base64", "request: color_png: expected base64"},
      {"not-a-png", "request: color_png: colour image: expected a PNG file, got no PNG header"},
      {"huge-png-header",
       "request: color_png: colour image: expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000"},
      {"colour-as-depth", "request: depth_png: depth image: expected a 16-bit single-channel PNG"},
      {"bad-utf8", "request: JSON: expected one JSON object per line"},
      {"bad-utf8-cut", "request: JSON: expected one JSON object per line"},
      {"bad-utf8-key", "request: JSON: expected one JSON object per line"},
  };
  size_t hostile = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kCorpus)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("good-", 0) == 0) continue;
    ++hostile;
    ASSERT_EQ(expected.count(name), 1U) << name << ": a corpus line without an expected answer here";
    const std::string line = Line(name);
    ServeRequest request;
    const std::string message = test::InputErrorMessage([&] {
      ParseRequest(line, {}, &request);
      if (request.in_memory) DecodeFrameBytes(*request.in_memory);
    });
    EXPECT_THAT(message, StartsWith(expected.at(name))) << name;
    nlohmann::json answer;
    EXPECT_NO_THROW(answer = nlohmann::json::parse(ResponseLine(ErrorResponse(request.id, message)))) << name;
    if (name.rfind("bad-utf8", 0) == 0) {  // the bad bytes the parser's message echoes become U+FFFD
      EXPECT_THAT(answer.value("error", ""), HasSubstr("\xEF\xBF\xBD")) << name;
    } else {
      EXPECT_EQ(answer.value("error", ""), message) << name;
    }
  }
  EXPECT_EQ(hostile, expected.size());
  // The id is echoed when it came before the fault.
  ServeRequest request;
  test::InputErrorMessage([&] { ParseRequest(Line("track-not-a-flag"), {}, &request); });
  EXPECT_EQ(request.id, 3);
  // A line past the size bound is refused before it is parsed.
  EXPECT_EQ(test::InputErrorMessage([&] {
              Parse(Line("good-frame"), RequestLimits{20, 64});
            }),
            "request: JSON: expected a line of at most 20 bytes");
}

// The fuzz harness over every line of the corpus: nothing but InputErrors, and an answer that reads back, as the
// fuzzer requires (scripts/fuzz runs it on more lines).
TEST(ServeRequestFuzzCorpus, TheHarnessAnswersEveryLine) {
  size_t lines = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(kCorpus)) {
    const std::string line = Line(entry.path().filename().string());
    EXPECT_NO_THROW(LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(line.data()), line.size())) << entry.path();
    ++lines;
  }
  EXPECT_GE(lines, 25U);
}

}  // namespace
}  // namespace ecv
