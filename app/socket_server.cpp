// The Unix-socket and standard-input server of `ecvpose serve`: request lines read as they arrive, clients on threads
// of their own, one recognition at a time, ended by SIGTERM or SIGINT.

#include "app/socket_server.h"

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
#include <iostream>
#include <list>
#include <thread>

#include "core/error.h"
#include "io/files.h"

namespace ecv::app {

namespace {

// Set by the signal handler, read by every client thread (a lock-free atomic: safe in a handler).
std::atomic<bool> stop_requested{false};

}  // namespace

bool StopRequested() {
  return stop_requested;
}

void InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = [](int) { stop_requested = true; };
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  signal(SIGPIPE, SIG_IGN);  // a client gone: its write fails with EPIPE instead of ending the service
}

mode_t ParseSocketMode(const std::string& text) {
  if (text.empty() || text.size() > 4 || text.find_first_not_of("01234567") != std::string::npos ||
      std::stoi(text, nullptr, 8) > 0777) {
    ThrowInputError(text, "--socket-mode", "permissions in octal, 0000 to 0777 (e.g. 0600, 0660)");
  }
  return static_cast<mode_t>(std::stoi(text, nullptr, 8));
}

namespace {

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

}  // namespace

void ServeClient(int in, int out, RecognitionService& service, std::mutex* queue) {
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

namespace {

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

}  // namespace

void ServeSocket(const SocketOptions& args, const std::function<RecognitionService()>& make_service) {
  const int listener = ListenOn(args.path, args.mode);
  std::cerr << "serve: ready, listening on " << args.path << '\n';
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
  unlink(args.path.c_str());
}

}  // namespace ecv::app
