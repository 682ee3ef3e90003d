#include "app/view/recognizer_child.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <stdexcept>

extern char** environ;

namespace ecv::view {
namespace {

// The exit code of a wait status: the program's own, or 128 + the signal that ended it (as a shell reports it).
int ExitCodeOf(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace

RecognizerChild::RecognizerChild(const std::string& program, const std::vector<std::string>& arguments) {
  int fds[2];
  // Close-on-exec: only the child's standard output (dup2 clears the flag) keeps the write end.
  if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(program + ": cannot make a pipe: " + std::strerror(errno));
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
  argv.push_back(nullptr);
  // posix_spawn, not fork: Qt's threads may hold locks that a forked child would inherit held.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  const int failed = posix_spawn(&pid_, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (failed != 0) {
    close(fds[0]);
    throw std::runtime_error(program + ": cannot start it: " + std::strerror(failed));
  }
  output_ = fds[0];
}

RecognizerChild::~RecognizerChild() {
  if (output_ >= 0) close(output_);  // a child blocked on a full pipe gets EPIPE
  if (pid_ > 0 && !exit_code_) {
    kill(pid_, SIGTERM);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
}

void RecognizerChild::ReadAvailable(int timeout_ms) {
  if (output_ended_) return;
  pollfd ready{output_, POLLIN, 0};
  if (poll(&ready, 1, timeout_ms) <= 0) return;  // nothing yet (or interrupted by a signal: the caller polls again)
  std::array<char, 65536> chunk{};
  const ssize_t count = read(output_, chunk.data(), chunk.size());
  if (count > 0) {
    buffer_.append(chunk.data(), static_cast<size_t>(count));
  } else if (count == 0 || errno != EINTR) {
    output_ended_ = true;
  }
}

std::optional<std::string> RecognizerChild::NextLine(int timeout_ms) {
  if (buffer_.find('\n') == std::string::npos) ReadAvailable(timeout_ms);
  const size_t end = buffer_.find('\n');
  if (end == std::string::npos) return std::nullopt;
  std::string line = buffer_.substr(0, end);
  buffer_.erase(0, end + 1);
  return line;
}

std::optional<int> RecognizerChild::ExitCode() {
  if (!exit_code_ && pid_ > 0) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) exit_code_ = ExitCodeOf(status);
  }
  return exit_code_;
}

}  // namespace ecv::view
