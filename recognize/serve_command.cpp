// `ecvpose serve --db lib.sqlite`: one process that loads the library and the meshes once and answers recognition
// requests, JSON lines on standard input or on a Unix socket (RecognitionService holds the protocol).

#include <errno.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/files.h"
#include "recognize/recognition_service.h"
#include "recognize/recognize_flags.h"

namespace ecv::app {
namespace {

volatile std::sig_atomic_t stop_requested = 0;

// SIGTERM and SIGINT end the service after the request in hand; without SA_RESTART a blocking read or accept returns
// EINTR, so that a service waiting for a request ends at once.
void InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = [](int) { stop_requested = 1; };
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a client gone: its write fails with EPIPE instead of ending the service
}

struct ServeArgs {
  RecognizerArgs recognizer;
  std::string socket;
  RequestLimits limits;
};

// Lines of a file descriptor, read as they arrive; nothing once the input ends or a stop is requested.
class LineReader {
 public:
  LineReader(int fd, size_t max_bytes) : fd_(fd), max_bytes_(max_bytes) {}

  // The next line (without its newline); `too_long` is set for a line past `max_bytes`, which is skipped (returned
  // empty) without being kept whole.
  std::optional<std::string> Next(bool* too_long) {
    while (true) {
      const size_t newline = buffer_.find('\n', scanned_);
      if (newline != std::string::npos) {
        *too_long = skipping_ || newline > max_bytes_;
        std::string line = *too_long ? std::string() : buffer_.substr(0, newline);
        buffer_.erase(0, newline + 1);
        scanned_ = 0;
        skipping_ = false;
        return line;
      }
      scanned_ = buffer_.size();  // a long line is searched for its newline once, not once per chunk
      if (buffer_.size() > max_bytes_) {
        buffer_.clear();
        scanned_ = 0;
        skipping_ = true;
      }
      char chunk[65536];
      const ssize_t got = read(fd_, chunk, sizeof(chunk));
      if (got < 0 && errno == EINTR && !stop_requested) continue;
      if (got <= 0 || stop_requested) return std::nullopt;
      buffer_.append(chunk, static_cast<size_t>(got));
    }
  }

 private:
  int fd_;
  size_t max_bytes_;
  std::string buffer_;
  size_t scanned_ = 0;  // bytes of buffer_ known to hold no newline
  bool skipping_ = false;
};

// Answers the requests of one client, a line each, until its input ends, it goes or a stop is requested.
void ServeClient(int in, int out, RecognitionService& service) {
  LineReader reader(in, service.limits().max_bytes);
  bool too_long = false;
  while (const std::optional<std::string> line = reader.Next(&too_long)) {
    if (!too_long && line->find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string text = (too_long ? service.AnswerTooLong() : service.Answer(*line)) + "\n";
    if (!WriteAll(out, text.data(), text.size()) || stop_requested) return;
  }
}

// A listening Unix socket at `path`; a stale socket file there is replaced, any other file is refused.
int ListenOn(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof(address.sun_path)) {
    ThrowInputError(path, "--socket", "a path of 1 to " + std::to_string(sizeof(address.sun_path) - 1) + " bytes");
  }
  std::memcpy(address.sun_path, path.c_str(), path.size());
  struct stat status {};
  if (lstat(path.c_str(), &status) == 0) {
    if (!S_ISSOCK(status.st_mode)) ThrowInputError(path, "--socket", "a free path or a stale socket", "another file");
    const int probe = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const bool live = probe >= 0 && connect(probe, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
    if (probe >= 0) close(probe);
    if (live) ThrowInputError(path, "--socket", "a free path or a stale socket", "a service listening there");
    unlink(path.c_str());
  }
  const int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0 || bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0 || listen(fd, 8) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) close(fd);
    ThrowInputError(path, "--socket", "a path where a socket can be made", reason);
  }
  return fd;
}

// Clients one at a time, each with tracks of its own, until a stop is requested.
void ServeSocket(const std::string& path, RecognitionService& service) {
  const int listener = ListenOn(path);
  std::cerr << "serve: ready, listening on " << path << '\n';
  while (!stop_requested) {
    const int client = accept4(listener, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) {
      // EINTR (a stop, checked above) or a client gone before it was accepted: at once; anything else (out of file
      // descriptors, say) is said and tried again shortly, not in a busy loop.
      if (errno != EINTR && errno != ECONNABORTED) {
        std::cerr << "serve: warning: accept: " << std::strerror(errno) << '\n';
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
      }
      continue;
    }
    service.Reset();
    ServeClient(client, client, service);
    close(client);
  }
  close(listener);
  unlink(path.c_str());
}

int RunServe(const ServeArgs& args) {
  const RecognizerOptions options = RecognizerOptionsFromArgs(args.recognizer);
  const LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options, "serve");
  RecognitionService service(*loaded.recognizer, args.recognizer.stream, args.limits);
  InstallStopHandlers();
  if (!args.socket.empty()) {
    ServeSocket(args.socket, service);
  } else {
    std::cerr << "serve: ready, reading requests on standard input\n";
    ServeClient(STDIN_FILENO, STDOUT_FILENO, service);
  }
  std::cerr << "serve: " << (stop_requested ? "stopped" : "input ended") << '\n';
  return kExitOk;
}

}  // namespace

CommandAction SetupServeCommand(CLI::App& command) {
  auto args = std::make_shared<ServeArgs>();
  AddRecognizerFlags(command, &args->recognizer);
  command.add_option("--socket", args->socket,
                     "Serve a Unix socket at this path, one client at a time, each with tracks of its own (default: "
                     "standard input and output)");
  command
      .add_option("--max-request-bytes", args->limits.max_bytes,
                  "Longest request line, bytes: a longer one gets an error answer and is skipped, not kept")
      ->capture_default_str()
      ->check(AtLeastOne());
  command.footer(
      "Requests, one JSON object per line: {\"frame\": FRAME} or {\"color\": PATH, \"depth\": PATH, \"depth_scale\": "
      "S,\n\"camera\": [fx, fy, cx, cy]}, with optional \"id\" (echoed), \"track\": true|false (default: --track) and "
      "\"reset\": true.\nEach gets one line: the detections as `recognize --out-json` writes them, or {\"id\": ..., "
      "\"error\": ...}\n(also for a line past --max-request-bytes, nested deeper than 64 or not UTF-8); the service "
      "goes on.\nSIGTERM ends the service after the request in hand (exit 0). Protocol: docs/serve.md.");
  return [args] { return RunServe(*args); };
}

}  // namespace ecv::app
