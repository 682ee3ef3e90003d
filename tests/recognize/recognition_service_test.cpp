// The protocol of `ecvpose serve` (RecognitionService), in the process and through the command: a tracked video gives
// `recognize --sequence --track`'s detections, a bad request gets an error line and the next one is answered.

#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/image_bytes.h"
#include "modeldb/model_library.h"
#include "recognize/recognition_service.h"
#include "recognize/recognizer.h"
#include "support/demo_library.h"
#include "support/test_data.h"

namespace ecv {
namespace {

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Base64 (RFC 4648, padded), written here independently of the decoder under test.
std::string Base64(const std::string& bytes) {
  static const char* kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string text;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t count = std::min<size_t>(3, bytes.size() - i);
    uint32_t bits = 0;
    for (size_t j = 0; j < 3; ++j) bits = (bits << 8) | (j < count ? static_cast<unsigned char>(bytes[i + j]) : 0U);
    for (size_t j = 0; j < 4; ++j) text += j <= count ? kDigits[(bits >> (18 - 6 * j)) & 63] : '=';
  }
  return text;
}

// A connection to a Unix socket at `path`, or -1.
int ConnectTo(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::strncpy(address.sun_path, path.c_str(), sizeof(address.sun_path) - 1);
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd >= 0 && connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0) return fd;
  if (fd >= 0) close(fd);
  return -1;
}

// The next line `fd` gives (without its newline), "<end>" when it ends first, "<timeout>" after `timeout_ms` without
// one.
std::string ReadLine(int fd, int timeout_ms) {
  std::string line;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
  while (true) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd ready = {fd, POLLIN, 0};
    if (left.count() <= 0 || poll(&ready, 1, static_cast<int>(left.count())) <= 0) return "<timeout>";
    char c = 0;
    if (read(fd, &c, 1) != 1) return line.empty() ? "<end>" : line;
    if (c == '\n') return line;
    line += c;
  }
}

// `ecvpose serve ARGS` in the background, started by the shell after `shell_prefix` (e.g. "umask 000; cd DIR;"),
// its standard error in `log`; stopped with SIGTERM when it goes out of scope.
class BackgroundServe {
 public:
  BackgroundServe(const std::string& shell_prefix, const std::string& args, const std::string& log) : log_(log) {
    const std::string command = shell_prefix + " exec " + ECV_CLI_PATH + " serve " + args + " 2> " + log;
    const char* argv[] = {"sh", "-c", command.c_str(), nullptr};
    if (posix_spawn(&pid_, "/bin/sh", nullptr, nullptr, const_cast<char* const*>(argv), environ) != 0) pid_ = -1;
  }
  ~BackgroundServe() {
    if (pid_ <= 0) return;
    kill(pid_, SIGTERM);
    int status = 0;
    waitpid(pid_, &status, 0);
  }

  // Whether the service said it listens within 60 s (the library loads first).
  bool WaitForReady() const {
    for (int i = 0; i < 1200 && pid_ > 0; ++i) {
      std::ifstream in(log_);
      const std::string said((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (said.find("serve: ready, listening") != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

 private:
  std::string log_;
  pid_t pid_ = -1;
};

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

// A followed object is tracked, or, when its track was due for confirmation (the frame after the search that found
// it), confirmed by the search's pose on its surface if that scored higher.
TEST_F(ServeProtocol, TrackedRequestsFollowTheirObjectsUntilAResetOrAnUntrackedOne) {
  RecognitionService service(*recognizer_, StreamOptions{});
  const std::string frame = "\"frame\": \"" + DemoFrame() + "\"";
  const auto followed_count = [&](const std::string& request) {
    const nlohmann::json response = service.Handle("{" + frame + request + "}");
    int followed = 0;
    for (const nlohmann::json& detection : response.at("detections")) {
      followed += detection.at("tracked") || detection.at("confirmed") ? 1 : 0;
    }
    EXPECT_EQ(response.at("detections").size(), 3U) << request;
    return followed;
  };
  EXPECT_EQ(followed_count(", \"track\": true"), 0);  // the first frame of a stream searches
  EXPECT_EQ(followed_count(", \"track\": true"), 3);
  EXPECT_EQ(followed_count(", \"track\": true, \"reset\": true"), 0);
  EXPECT_EQ(followed_count(", \"track\": true"), 3);
  EXPECT_EQ(followed_count(""), 0);  // a frame on its own (the service's default) ends the tracks
  EXPECT_EQ(followed_count(", \"track\": true"), 0);
}

// With roots, a request reads only regular files below them: a path outside, a link leading out (of a YCB-Video prefix
// or named in a frame JSON) and a FIFO are refused with one message, without reading them; a frame below is served.
TEST_F(ServeProtocol, FramesAreReadOnlyBelowTheRoots) {
  namespace fs = std::filesystem;
  const fs::path root = directory_->path() / "root";
  fs::create_directories(root / "frames");
  for (const char* suffix : {"-color.png", "-depth.png", "-meta.mat"}) {
    fs::copy_file(DemoFrame() + suffix, (root / "frames" / "000001").string() + suffix);
    if (suffix[1] != 'c') fs::copy_file(DemoFrame() + suffix, (root / "fifo").string() + suffix);  // colour a FIFO
  }
  fs::create_symlink(fs::path(DemoFrame()).parent_path(), root / "linked");  // a folder outside
  ASSERT_EQ(mkfifo((root / "fifo.json").c_str(), 0600), 0);
  ASSERT_EQ(mkfifo((root / "fifo-color.png").c_str(), 0600), 0);
  {
    std::ofstream out(root / "outside.json");
    out << nlohmann::json{{"color", DemoFrame() + "-color.png"},
                          {"depth", "frames/000001-depth.png"},
                          {"depth_scale", 10000},
                          {"camera", {1066.778, 1067.487, 312.9869, 241.3109}}};
  }
  RecognitionService service(*recognizer_, StreamOptions{}, RequestLimits{}, ReadRoots({root.string()}));
  const auto error_of = [&](const nlohmann::json& request) {
    const nlohmann::json response = service.Handle(request.dump());
    EXPECT_FALSE(response.contains("detections")) << request;
    return response.value("error", std::string());
  };
  const auto refused = [](const std::string& path) { return "frame: not readable here: " + path; };
  for (const std::string& path :
       {DemoFrame(), std::string("/no/such/000001"), std::string("/etc/passwd"), (root / "linked" / "000001").string(),
        (root / "outside.json").string(), (root / "fifo.json").string(), (root / "fifo").string(),
        (root / "frames" / ".." / ".." / "library.sqlite").string()}) {
    EXPECT_EQ(error_of({{"frame", path}}), refused(path));
  }
  const std::string depth = (root / "frames" / "000001-depth.png").string();
  const nlohmann::json keys = {
      {"depth", depth}, {"depth_scale", 10000}, {"camera", {1066.778, 1067.487, 312.9869, 241.3109}}};
  nlohmann::json request = keys;
  request["color"] = (root / "fifo-color.png").string();
  EXPECT_EQ(error_of(request), refused(request["color"]));
  request["color"] = DemoFrame() + "-color.png";
  EXPECT_EQ(error_of(request), refused(request["color"]));

  const nlohmann::json answer = service.Handle(nlohmann::json{{"frame", (root / "frames" / "000001").string()}}.dump());
  ASSERT_TRUE(answer.contains("detections")) << answer.dump();
  EXPECT_EQ(answer.at("detections").size(), 3U);
}

TEST(Base64, DecodesWhatItEncodesAndRefusesTheRest) {
  std::string bytes;
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(DecodeBase64(Base64(bytes), "request", "color_png"), bytes) << i;
    bytes.push_back(static_cast<char>(251 - 37 * i));
  }
  EXPECT_EQ(DecodeBase64("TWFu", "request", "color_png"), "Man");
  for (const std::string bad : {"TWF", "TW=u", "TWF*", "T===", "TWFu\n", "=TWF"}) {
    try {
      DecodeBase64(bad, "request", "depth_png");
      ADD_FAILURE() << bad;
    } catch (const InputError& error) {
      EXPECT_EQ(std::string(error.what()).rfind("request: depth_png: expected base64", 0), 0U) << error.what();
    }
  }
}

// A frame's images carried in the request give the detections of the same files named by path.
TEST_F(ServeProtocol, AFrameInMemoryGivesTheDetectionsOfItsFiles) {
  RecognitionService service(*recognizer_, StreamOptions{});
  const std::string color = DemoFrame() + "-color.png", depth = DemoFrame() + "-depth.png";
  const nlohmann::json camera = {1066.778, 1067.487, 312.9869, 241.3109};
  const nlohmann::json by_path = service.Handle(
      nlohmann::json{{"color", color}, {"depth", depth}, {"depth_scale", 10000}, {"camera", camera}}.dump());
  nlohmann::json request = {{"id", 5},
                            {"color_png", Base64(FileBytes(color))},
                            {"depth_png", Base64(FileBytes(depth))},
                            {"depth_scale", 10000},
                            {"camera", camera}};
  const nlohmann::json in_memory = service.Handle(request.dump());
  ASSERT_TRUE(in_memory.contains("detections")) << in_memory.dump().substr(0, 400);
  ASSERT_EQ(by_path.at("detections").size(), 3U) << by_path.dump();
  ASSERT_EQ(in_memory.at("detections").size(), by_path.at("detections").size());
  EXPECT_EQ(in_memory.at("id"), 5);
  EXPECT_TRUE(in_memory.at("frame").is_null());
  for (size_t i = 0; i < by_path.at("detections").size(); ++i) {
    const nlohmann::json& expected = by_path["detections"][i];
    const nlohmann::json& got = in_memory["detections"][i];
    EXPECT_EQ(got.at("model"), expected.at("model"));
    for (size_t r = 0; r < 4; ++r) {
      for (size_t c = 0; c < 4; ++c) {
        EXPECT_NEAR(got["camera_from_object"][r][c].get<double>(), expected["camera_from_object"][r][c].get<double>(),
                    1e-9);
      }
    }
  }

  const auto error_of = [&](const std::string& key, const nlohmann::json& value) {
    nlohmann::json bad = request;
    bad[key] = value;
    const nlohmann::json response = service.Handle(bad.dump());
    EXPECT_FALSE(response.contains("detections")) << key;
    return response.value("error", std::string());
  };
  EXPECT_EQ(error_of("color_png", "not base64!").rfind("request: color_png: expected base64", 0), 0U);
  EXPECT_NE(error_of("depth_png", request["color_png"]).find("request: depth_png: depth image: expected a 16-bit"),
            std::string::npos);
  // A header that claims 20000 x 20000 pixels is refused before anything is decoded.
  std::string huge = FileBytes(color).substr(0, 33);
  for (size_t at : {16, 20}) huge.replace(at, 4, std::string("\0\0\x4e\x20", 4));
  EXPECT_NE(error_of("color_png", Base64(huge)).find("expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000"),
            std::string::npos);
  EXPECT_NE(error_of("frame", "x").find("not both"), std::string::npos);
  EXPECT_NE(error_of("depth_scale", 0).find("depth_scale: expected a finite positive scale"), std::string::npos);
}

// The socket file lets only its owner connect whatever the umask; --socket-mode widens it.
TEST_F(ServeProtocol, TheSocketIsTheOwnersUnderAnyUmask) {
  for (const std::string mode : {"", "0660"}) {
    const std::string socket = directory_->File("mode" + mode + ".sock");
    std::string args = "--db " + library_ + " --socket " + socket;
    if (!mode.empty()) args += " --socket-mode " + mode;
    const BackgroundServe serve("umask 000;", args, directory_->File("mode" + mode + ".log"));
    ASSERT_TRUE(serve.WaitForReady()) << mode;
    struct stat status {};
    ASSERT_EQ(stat(socket.c_str(), &status), 0);
    EXPECT_TRUE(S_ISSOCK(status.st_mode));
    EXPECT_EQ(status.st_mode & 07777, mode.empty() ? 0600U : 0660U) << mode;
  }
  const test::CommandResult bad = test::RunCli("serve --db " + library_ + " --socket x.sock --socket-mode 0999");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("--socket-mode: expected permissions in octal"), std::string::npos) << bad.output;
}

// Clients on threads of their own: while A stays connected and silent, B is answered; C, one past --max-clients, gets
// an error line and is closed; A is closed after --idle-timeout.
TEST_F(ServeProtocol, ASilentClientHoldsNoOther) {
  const std::string socket = directory_->File("clients.sock"), log = directory_->File("clients.log");
  const BackgroundServe serve("",
                              "--db " + library_ + " --socket " + socket + " --root " + ECV_SOURCE_DIR +
                                  "/models --max-clients 2 --idle-timeout 2",
                              log);
  ASSERT_TRUE(serve.WaitForReady());
  const auto start = std::chrono::steady_clock::now();
  const int a = ConnectTo(socket), b = ConnectTo(socket), c = ConnectTo(socket);
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  ASSERT_GE(c, 0);
  EXPECT_NE(ReadLine(c, 10000).find("serve: clients: expected at most 2 at once"), std::string::npos);
  EXPECT_EQ(ReadLine(c, 10000), "<end>");

  const std::string request = nlohmann::json{{"id", 7}, {"frame", DemoFrame()}}.dump() + "\n";
  ASSERT_EQ(write(b, request.data(), request.size()), static_cast<ssize_t>(request.size()));
  const std::string answer = ReadLine(b, 60000);
  ASSERT_EQ(answer.front(), '{') << answer;
  const nlohmann::json response = nlohmann::json::parse(answer);
  EXPECT_EQ(response.at("id"), 7);
  EXPECT_EQ(response.at("detections").size(), 3U) << answer;

  EXPECT_NE(ReadLine(a, 10000).find("serve: idle: expected a request within --idle-timeout"), std::string::npos);
  EXPECT_EQ(ReadLine(a, 10000), "<end>");
  EXPECT_GE(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(1900));
  for (const int fd : {a, b, c}) close(fd);
}

// 8 clients at once, each sending 5 frames and 2 bad requests in one write: every line is answered, in order, with its
// own id (null for a line that is not JSON), while the recognitions share one queue. The frames are a 160 x 120 crop
// of the demo frame without its depth (nothing to find: a few milliseconds each), the first client's first one the
// whole demo frame (its 3 objects found, in half a second).
TEST_F(ServeProtocol, EightClientsOfFiveFramesAndBadRequestsAreAnsweredWithTheirIds) {
  namespace fs = std::filesystem;
  const fs::path root = directory_->path() / "clients";
  fs::create_directories(root);
  RgbdFrame crop = LoadYcbvFrame(DemoFrame()).rgbd;
  const cv::Rect window(240, 160, 160, 120);
  crop.color = crop.color(window).clone();
  crop.depth = crop.depth(window).clone();
  crop.camera.cx -= window.x;
  crop.camera.cy -= window.y;
  crop.camera.width = window.width;
  crop.camera.height = window.height;
  crop.depth.setTo(0.0F);
  const std::string small = (root / "crop.json").string();
  WriteFrameJson(small, crop);

  const std::string socket = directory_->File("eight.sock");
  const BackgroundServe serve("",
                              "--db " + library_ + " --socket " + socket + " --threads 2 --root " + root.string() +
                                  " --root " + fs::path(DemoFrame()).parent_path().string(),
                              directory_->File("eight.log"));
  ASSERT_TRUE(serve.WaitForReady());
  constexpr int kClients = 8, kFrames = 5;
  std::vector<std::vector<nlohmann::json>> answers(kClients);
  std::vector<std::thread> clients;
  for (int c = 0; c < kClients; ++c) {
    clients.emplace_back([&, c] {
      const int fd = ConnectTo(socket);
      if (fd < 0) return;
      std::string lines;
      for (int f = 0; f < kFrames; ++f) {
        const std::string frame = c == 0 && f == 0 ? DemoFrame() : small;
        lines += nlohmann::json{{"id", std::to_string(c) + "-" + std::to_string(f)}, {"frame", frame}}.dump() + "\n";
      }
      lines += "{\"id\": 7, \"frame\": \n";                                                         // not JSON: id null
      lines += nlohmann::json{{"id", c}, {"frame", "/etc/passwd"}, {"track", true}}.dump() + "\n";  // outside the roots
      if (write(fd, lines.data(), lines.size()) != static_cast<ssize_t>(lines.size())) return;
      for (int i = 0; i < kFrames + 2; ++i) {
        const std::string line = ReadLine(fd, 120000);
        answers[static_cast<size_t>(c)].push_back(nlohmann::json::parse(line, nullptr, false));
      }
      close(fd);
    });
  }
  for (std::thread& client : clients) client.join();
  for (int c = 0; c < kClients; ++c) {
    const std::vector<nlohmann::json>& got = answers[static_cast<size_t>(c)];
    ASSERT_EQ(got.size(), static_cast<size_t>(kFrames + 2)) << "client " << c;
    for (int f = 0; f < kFrames; ++f) {
      const nlohmann::json& answer = got[static_cast<size_t>(f)];
      EXPECT_EQ(answer.value("id", ""), std::to_string(c) + "-" + std::to_string(f)) << answer.dump().substr(0, 300);
      EXPECT_TRUE(answer.contains("detections")) << answer.dump().substr(0, 300);
    }
    EXPECT_TRUE(got[kFrames].at("id").is_null());
    EXPECT_NE(got[kFrames].value("error", "").find("one JSON object per line"), std::string::npos);
    EXPECT_EQ(got[kFrames + 1].at("id"), c);
    EXPECT_EQ(got[kFrames + 1].value("error", ""), "frame: not readable here: /etc/passwd");
  }
  EXPECT_EQ(answers[0][0].at("detections").size(), 3U) << answers[0][0].dump().substr(0, 300);
}

}  // namespace
}  // namespace ecv
