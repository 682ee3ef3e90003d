// `ecvpose serve --db lib.sqlite`: one process that loads the library and the meshes once and answers recognition
// requests, JSON lines on standard input or on a Unix socket (RecognitionService holds the protocol).

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/files.h"
#include "recognize/recognition_service.h"
#include "recognize/recognize_flags.h"

namespace ecv::app {
namespace {

// Set by the signal handler, read by every client thread (a lock-free atomic: safe in a handler).
std::atomic<bool> stop_requested{false};

// SIGTERM and SIGINT end the service after the request in hand; without SA_RESTART a blocking read or accept returns
// EINTR, so that a service waiting for a request ends at once.
void InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = [](int) { stop_requested = true; };
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a client gone: its write fails with EPIPE instead of ending the service
}

struct ServeArgs {
  RecognizerArgs recognizer;
  std::string socket;
  std::string socket_mode = "0600";  // octal permissions of the socket file
  std::vector<std::string> roots;    // folders frames are read below; none: the socket's default
  int max_clients = 16;              // socket clients served at once
  double idle_timeout_s = 60.0;      // a socket client that sends nothing for this long is closed; 0: never
  RequestLimits limits;
};

// The permission bits an octal text such as "0660" spells; InputError unless it is 1 to 4 octal digits up to 0777.
mode_t ParseSocketMode(const std::string& text) {
  if (text.empty() || text.size() > 4 || text.find_first_not_of("01234567") != std::string::npos ||
      std::stoi(text, nullptr, 8) > 0777) {
    ThrowInputError(text, "--socket-mode", "permissions in octal, 0000 to 0777 (e.g. 0600, 0660)");
  }
  return static_cast<mode_t>(std::stoi(text, nullptr, 8));
}

// Lines of a file descriptor, read as they arrive; nothing once the input ends or a stop is requested.
class LineReader {
 public:
  LineReader(int fd, size_t max_bytes) : fd_(fd), max_bytes_(max_bytes) {}

  // Whether the input ended by the receive timeout of a socket.
  bool timed_out() const { return timed_out_; }

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
      timed_out_ = got < 0 && (errno == EAGAIN || errno == EWOULDBLOCK);  // a socket's receive timeout
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
  bool timed_out_ = false;
};

// Answers the requests of one client, a line each, until its input ends, it goes, it sends nothing for longer than
// the socket's receive timeout (said in an error line) or a stop is requested. `queue`, when given, is held for each
// answer: one recognition at a time, as recognition uses every core.
void ServeClient(int in, int out, RecognitionService& service, std::mutex* queue = nullptr) {
  LineReader reader(in, service.limits().max_bytes);
  bool too_long = false;
  while (const std::optional<std::string> line = reader.Next(&too_long)) {
    if (!too_long && line->find_first_not_of(" \t\r") == std::string::npos) continue;
    std::unique_lock<std::mutex> turn;
    if (queue != nullptr) turn = std::unique_lock<std::mutex>(*queue);
    const std::string text = (too_long ? service.AnswerTooLong() : service.Answer(*line)) + "\n";
    if (turn.owns_lock()) turn.unlock();
    if (!WriteAll(out, text.data(), text.size()) || stop_requested) return;
  }
  if (reader.timed_out()) {
    const std::string text =
        nlohmann::json{{"id", nullptr}, {"error", "serve: idle: expected a request within --idle-timeout: closed"}}
            .dump() +
        "\n";
    WriteAll(out, text.data(), text.size());
  }
}

// The clients of a socket, each served on a thread of its own; at most `max_clients` at once.
class ClientThreads {
 public:
  explicit ClientThreads(int max_clients) : max_clients_(max_clients) {}
  ClientThreads(const ClientThreads&) = delete;
  ClientThreads& operator=(const ClientThreads&) = delete;
  ~ClientThreads() { StopAll(); }

  // Calls `serve(client)` on a thread of its own, which then closes `client`; false, `client` left to the caller,
  // when `max_clients` are served already. The thread leaves SIGTERM and SIGINT to the thread that accepts.
  bool Start(int client, std::function<void(int)> serve) {
    std::lock_guard<std::mutex> lock(mutex_);
    int active = 0;
    for (auto it = clients_.begin(); it != clients_.end();) {
      if (it->done) {
        it->thread.join();
        it = clients_.erase(it);
      } else {
        ++active;
        ++it;
      }
    }
    if (active >= max_clients_) return false;
    Client& entry = clients_.emplace_back();
    entry.fd = client;
    sigset_t stops, old;
    sigemptyset(&stops);
    sigaddset(&stops, SIGTERM);
    sigaddset(&stops, SIGINT);
    pthread_sigmask(SIG_BLOCK, &stops, &old);
    entry.thread = std::thread([this, &entry, serve = std::move(serve)] {
      serve(entry.fd);
      std::lock_guard<std::mutex> done(mutex_);
      close(entry.fd);
      entry.done = true;
    });
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    return true;
  }

  // Ends the reading of every client (the answer in hand is still written) and waits for their threads.
  void StopAll() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const Client& client : clients_) {
        if (!client.done) shutdown(client.fd, SHUT_RD);
      }
    }
    for (Client& client : clients_) {
      if (client.thread.joinable()) client.thread.join();
    }
    clients_.clear();
  }

 private:
  struct Client {
    int fd = -1;
    std::thread thread;
    bool done = false;  // served and closed (under mutex_)
  };
  int max_clients_;
  std::mutex mutex_;
  std::list<Client> clients_;  // a list: the threads hold their entries
};

// A listening Unix socket at `path` with permissions `mode`; a stale socket file there is replaced, any other file is
// refused. The file is made under a umask that leaves it to its owner, and given `mode` before anyone may connect.
int ListenOn(const std::string& path, mode_t mode) {
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
  const mode_t old_umask = umask(0177);  // before any thread: the mask is the process's
  const bool bound = fd >= 0 && bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address)) == 0;
  umask(old_umask);
  if (!bound || chmod(path.c_str(), mode) != 0 || listen(fd, 8) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) close(fd);
    if (bound) unlink(path.c_str());
    ThrowInputError(path, "--socket", "a path where a socket can be made", reason);
  }
  return fd;
}

// Clients on threads of their own, each with tracks of its own (`make_service`), one recognition at a time, until a
// stop is requested. A client past `max_clients` gets an error line and is closed.
void ServeSocket(const ServeArgs& args, mode_t mode, const std::function<RecognitionService()>& make_service) {
  const int listener = ListenOn(args.socket, mode);
  std::cerr << "serve: ready, listening on " << args.socket << '\n';
  std::mutex queue;
  const timeval idle = {static_cast<time_t>(args.idle_timeout_s),
                        static_cast<suseconds_t>(std::fmod(args.idle_timeout_s, 1.0) * 1e6)};
  ClientThreads clients(args.max_clients);
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
    if (args.idle_timeout_s > 0) setsockopt(client, SOL_SOCKET, SO_RCVTIMEO, &idle, sizeof(idle));
    const bool started = clients.Start(client, [&](int fd) {
      RecognitionService service = make_service();
      ServeClient(fd, fd, service, &queue);
    });
    if (!started) {
      const std::string text =
          nlohmann::json{{"id", nullptr},
                         {"error", "serve: clients: expected at most " + std::to_string(args.max_clients) +
                                       " at once (--max-clients): closed, try again later"}}
              .dump() +
          "\n";
      WriteAll(client, text.data(), text.size());
      close(client);
    }
  }
  clients.StopAll();
  close(listener);
  unlink(args.socket.c_str());
}

// The folders of --root; without one, the working directory for a socket and anywhere for standard input. Said on
// standard error.
ReadRoots ServeRoots(const ServeArgs& args) {
  std::vector<std::string> folders = args.roots;
  if (folders.empty() && !args.socket.empty()) folders.push_back(".");
  ReadRoots roots(folders);
  std::cerr << "serve: frames read " << (folders.empty() ? "anywhere (no --root)" : "below");
  for (const std::filesystem::path& folder : roots.folders()) std::cerr << ' ' << folder.string();
  std::cerr << '\n';
  return roots;
}

int RunServe(const ServeArgs& args) {
  const mode_t socket_mode = ParseSocketMode(args.socket_mode);
  const ReadRoots roots = ServeRoots(args);
  const StreamRecognizerOptions options =
      ShareThreads(RecognizerOptionsFromArgs(args.recognizer), args.recognizer.stream);
  const LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options.track, "serve");
  const auto make_service = [&] {
    return RecognitionService(*loaded.recognizer, args.recognizer.stream, args.limits, roots,
                              MakeRecognizerFactory(*loaded.library, options.search));
  };
  InstallStopHandlers();
  if (!args.socket.empty()) {
    ServeSocket(args, socket_mode, make_service);
  } else {
    RecognitionService service = make_service();
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
                     "Serve a Unix socket at this path, each client on a thread and with tracks of its own, one "
                     "recognition at a time (default: standard input and output)");
  command.add_option("--max-clients", args->max_clients, "Socket clients served at once: one more gets an error line")
      ->capture_default_str()
      ->check(CLI::Range(1, 1024));
  command
      .add_option("--idle-timeout", args->idle_timeout_s,
                  "Seconds a socket client may send nothing before it is closed (0: never)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  command.add_option("--root", args->roots,
                     "Read frames only below this folder (repeatable): regular files whose path, links followed, "
                     "lies below a --root (default: the working directory with --socket; anywhere on standard input)");
  command
      .add_option("--socket-mode", args->socket_mode,
                  "Permissions of the socket file, octal, whatever the umask: 0600 lets only this user connect, 0660 "
                  "also the group")
      ->capture_default_str();
  command
      .add_option("--max-request-bytes", args->limits.max_bytes,
                  "Longest request line, bytes: a longer one gets an error answer and is skipped, not kept")
      ->capture_default_str()
      ->check(AtLeastOne());
  command.footer(
      "Requests, one JSON object per line: {\"frame\": FRAME}, {\"color\": PATH, \"depth\": PATH, \"depth_scale\": "
      "S,\n\"camera\": [fx, fy, cx, cy]} or the images themselves, {\"color_png\": BASE64, \"depth_png\": BASE64, "
      "\"depth_scale\": S,\n\"camera\": [...]}, with optional \"id\" (echoed), \"track\": true|false (default: "
      "--track) and \"reset\": true.\nEach gets one line: the detections as `recognize --out-json` writes them, or "
      "{\"id\": ..., \"error\": ...}\n(also for a line past --max-request-bytes, nested deeper than 64 or not UTF-8, "
      "and for a file outside --root); the service goes on.\nSIGTERM ends the service after the request in hand (exit "
      "0). Protocol and security: docs/serve.md.");
  return [args] { return RunServe(*args); };
}

}  // namespace ecv::app
