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
