// The protocol of `ecvpose serve` (RecognitionService), in the process and through the command: a tracked video gives
// `recognize --sequence --track`'s detections, a bad request gets an error line and the next one is answered.

#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "modeldb/model_library.h"
#include "recognize/recognition_service.h"
#include "recognize/recognizer.h"
#include "support/demo_library.h"
#include "support/test_data.h"

namespace ecv {
namespace {

class ServeProtocol : public test::DemoLibrarySuite {
 protected:
  void SetUp() override {
    LibraryLoadOptions load;
    load.build_matchers = false;
    library_models_ = std::make_unique<ModelLibrary>(ModelLibrary::Load(library_, load));
    recognizer_ = std::make_unique<Recognizer>(*library_models_);
  }

  static std::vector<nlohmann::json> ReadLines(const std::string& path) {
    std::ifstream in(path);
    std::vector<nlohmann::json> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
    return lines;
  }

  std::unique_ptr<ModelLibrary> library_models_;
  std::unique_ptr<Recognizer> recognizer_;  // over library_models_, default options
};

TEST_F(ServeProtocol, TenTrackedFramesOfAVideoGiveTheSequencesDetections) {
  const std::string video = test::DataPath("ycbv_subset/Example-Scenes/0001");
  const std::string requests = directory_->File("requests.jsonl"), served = directory_->File("served.jsonl");
  const std::string sequence = directory_->File("sequence.jsonl");
  std::vector<std::string> frames;
  {
    std::ofstream out(requests);
    for (int i = 1; i <= 19; i += 2) {
      char name[16];
      std::snprintf(name, sizeof(name), "/%06d", i);
      frames.push_back(video + name);
      out << nlohmann::json{{"id", i}, {"frame", frames.back()}, {"track", true}}.dump() << '\n';
    }
  }
  const std::string flags = " --db " + library_ + " --seed 2 --threads 2 --search-every 3";
  // In a subshell: its standard output to the file, its standard error to the result.
  const test::CommandResult serve =
      test::RunCommand(std::string("(") + ECV_CLI_PATH + " serve" + flags + " < " + requests + " > " + served + ")");
  ASSERT_EQ(serve.exit_code, 0) << serve.output;
  const test::CommandResult run =
      test::RunCli("recognize --sequence " + video + " --track" + flags + " --out-json " + sequence);
  ASSERT_EQ(run.exit_code, 0) << run.output;

  const std::vector<nlohmann::json> answers = ReadLines(served), expected = ReadLines(sequence);
  ASSERT_EQ(answers.size(), frames.size());
  ASSERT_EQ(expected.size(), frames.size());
  int tracked = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(answers[i].at("id"), static_cast<int>(2 * i + 1));
    EXPECT_EQ(answers[i].at("frame"), frames[i]);
    EXPECT_EQ(answers[i].at("detections"), expected[i].at("detections")) << frames[i];
    for (const nlohmann::json& detection : answers[i].at("detections")) tracked += detection.at("tracked") ? 1 : 0;
  }
  EXPECT_GE(tracked, 15);  // most of the 27 detections after the first frame follow their track
}

TEST_F(ServeProtocol, ABadRequestGetsAnErrorLineAndTheNextOneIsAnswered) {
  RecognitionService service(*recognizer_, StreamOptions{});
  const auto error_of = [&](const std::string& line) {
    const nlohmann::json response = service.Handle(line);
    EXPECT_FALSE(response.contains("detections")) << line;
    return response.value("error", std::string());
  };
  EXPECT_NE(error_of("{\"id\": 1, \"frame\": ").find("one JSON object per line"), std::string::npos);
  EXPECT_NE(error_of("[1, 2]").find("an object"), std::string::npos);
  EXPECT_NE(error_of(R"({"id": 2, "frame": "/no/such/000001"})").find("/no/such/000001"), std::string::npos);
  EXPECT_NE(error_of(R"({"id": 3, "frame": "x", "fram": 1})").find("fram: expected one of id, frame"),
            std::string::npos);
  const std::string color = DemoFrame() + "-color.png", depth = DemoFrame() + "-depth.png";
  const std::string flags = R"({"color": ")" + color + R"(", "depth": ")" + depth + R"(", "depth_scale": 10000)";
  EXPECT_NE(error_of(flags + R"(, "camera": [1, 2, 3]})").find("camera: expected [fx, fy, cx, cy]"), std::string::npos);
  EXPECT_NE(error_of(flags + R"(, "camera": [1066.8, 1067.5, 313, 241], "frame": "x"})").find("not both"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"frame": "x", "track": "yes"})").find("track: expected true or false"), std::string::npos);
  EXPECT_EQ(service.Handle(R"({"id": [7], "frame": "/no/such/000001"})").at("id"), nlohmann::json::array({7}));

  const nlohmann::json answer = service.Handle(flags + R"(, "camera": [1066.778, 1067.487, 312.9869, 241.3109]})");
  ASSERT_TRUE(answer.contains("detections")) << answer.dump();
  EXPECT_EQ(answer.at("detections").size(), 3U) << answer.dump();
  EXPECT_EQ(answer.at("frame"), color);
  EXPECT_TRUE(answer.at("id").is_null());
}

// Lines a hostile client may send: each is answered with an error line that is valid UTF-8, and the next is answered.
TEST_F(ServeProtocol, InvalidUtf8AndDeepNestingGetErrorLines) {
  RecognitionService service(*recognizer_, StreamOptions{});
  const auto error_of = [&](const std::string& line) {
    const std::string answer = service.Answer(line);
    nlohmann::json response;
    EXPECT_NO_THROW(response = nlohmann::json::parse(answer)) << answer;  // the parser refuses invalid UTF-8
    EXPECT_FALSE(response.contains("detections")) << answer;
    return response.value("error", std::string());
  };
  EXPECT_NE(error_of("{\"id\": 14, \"frame\": \"\xff\xfe\"}").find("one JSON object per line"), std::string::npos);
  EXPECT_NE(error_of("{\"id\": 15, \"frame\": \"a\xc3\"}").find("one JSON object per line"), std::string::npos);
  const std::string deep = "request: JSON: expected [ and { nested at most 64 deep";
  EXPECT_NE(error_of(std::string(100000, '[') + std::string(100000, ']')).find(deep), std::string::npos);
  EXPECT_NE(error_of(std::string(100000, '[')).find(deep), std::string::npos);
  EXPECT_NE(error_of(R"({"id": )" + std::string(64, '{') + "}").find(deep), std::string::npos);
  // Brackets inside strings, escaped quotes included, are text: the request is judged on its frame.
  const std::string text = R"(\"[)" + std::string(100, '[') + std::string(100, '{');
  EXPECT_NE(error_of(R"({"id": ")" + text + R"(", "frame": "/no/such/000001"})").find("/no/such/000001"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"id": )" + std::string(63, '[') + std::string(63, ']') + R"(, "frame": "/no/such/000001"})")
                .find("/no/such/000001"),
            std::string::npos);

  RecognitionService small(*recognizer_, StreamOptions{}, RequestLimits{100, 64});
  EXPECT_EQ(nlohmann::json::parse(small.Answer(std::string(101, ' '))).at("error"),
            "request: JSON: expected a line of at most 100 bytes");
  EXPECT_EQ(small.AnswerTooLong(), small.Answer(std::string(101, ' ')));
}

// The same through the command: a line of invalid UTF-8, a deep one and one past --max-request-bytes each get an
// error line and the service answers the request after them.
TEST_F(ServeProtocol, TheServiceGoesOnAfterHostileLines) {
  const std::string requests = directory_->File("hostile.jsonl"), served = directory_->File("hostile_served.jsonl");
  {
    std::ofstream out(requests, std::ios::binary);
    out << "{\"id\": 14, \"frame\": \"\xff\xfe\"}\n";
    out << std::string(100000, '[') << std::string(100000, ']') << '\n';  // 200 KB
    out << R"({"id": 16, "frame": ")" << std::string(300000, 'x') << "\"}\n";
    out << R"({"id": 17, "frame": "/no/such/000001"})" << '\n';
  }
  const test::CommandResult serve =
      test::RunCommand(std::string("(") + ECV_CLI_PATH + " serve --db " + library_ + " --max-request-bytes 250000 < " +
                       requests + " > " + served + ")");
  ASSERT_EQ(serve.exit_code, 0) << serve.output;
  const std::vector<nlohmann::json> answers = ReadLines(served);
  ASSERT_EQ(answers.size(), 4U);
  EXPECT_NE(answers[0].at("error").get<std::string>().find("one JSON object per line"), std::string::npos);
  EXPECT_NE(answers[1].at("error").get<std::string>().find("nested at most 64 deep"), std::string::npos);
  EXPECT_EQ(answers[2].at("error"), "request: JSON: expected a line of at most 250000 bytes");
  EXPECT_EQ(answers[3].at("id"), 17);
  EXPECT_NE(answers[3].at("error").get<std::string>().find("/no/such/000001"), std::string::npos);
}

TEST_F(ServeProtocol, TrackedRequestsFollowTheirObjectsUntilAResetOrAnUntrackedOne) {
  RecognitionService service(*recognizer_, StreamOptions{});
  const std::string frame = "\"frame\": \"" + DemoFrame() + "\"";
  const auto tracked_count = [&](const std::string& request) {
    const nlohmann::json response = service.Handle("{" + frame + request + "}");
    int tracked = 0;
    for (const nlohmann::json& detection : response.at("detections")) tracked += detection.at("tracked") ? 1 : 0;
    EXPECT_EQ(response.at("detections").size(), 3U) << request;
    return tracked;
  };
  EXPECT_EQ(tracked_count(", \"track\": true"), 0);  // the first frame of a stream searches
  EXPECT_EQ(tracked_count(", \"track\": true"), 3);
  EXPECT_EQ(tracked_count(", \"track\": true, \"reset\": true"), 0);
  EXPECT_EQ(tracked_count(", \"track\": true"), 3);
  EXPECT_EQ(tracked_count(""), 0);  // a frame on its own (the service's default) ends the tracks
  EXPECT_EQ(tracked_count(", \"track\": true"), 0);
}

}  // namespace
}  // namespace ecv
