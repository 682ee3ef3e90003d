#include "support/test_data.h"

#include <errno.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

namespace ecv::test {

std::string DataPath(const std::string& relative) {
  const std::filesystem::path path = std::filesystem::path(ECV_DATA_DIR) / relative;
  // A YCB-Video frame prefix names files that start with it.
  if (!std::filesystem::exists(path) && !std::filesystem::exists(path.string() + "-color.png")) {
    ADD_FAILURE() << "missing test data " << path
                  << " (the tests read ../shared/data beside the checkout; set -DECVPOSE_DATA_DIR otherwise)";
  }
  return path.string();
}

TemporaryDirectory::TemporaryDirectory() {
  std::random_device device;
  path_ = std::filesystem::temp_directory_path() / ("ecvpose-test-" + std::to_string(device()));
  std::filesystem::create_directories(path_);
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

CommandResult RunCli(const std::string& arguments, const std::string& prefix) {
  return RunCommand(prefix + ECV_CLI_PATH + " " + arguments);
}

CommandResult RunCommand(const std::string& shell_command) {
  CommandResult result;
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return result;
  // posix_spawn and wait4, not popen: the child's rusage covers the shell and every process it waited for.
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
  const char* argv[] = {"sh", "-c", shell_command.c_str(), nullptr};
  pid_t child = -1;
  const int failed = posix_spawn(&child, "/bin/sh", &actions, nullptr, const_cast<char* const*>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (failed != 0) {
    close(fds[0]);
    return result;
  }
  std::array<char, 4096> buffer{};
  for (;;) {
    const ssize_t count = read(fds[0], buffer.data(), buffer.size());
    if (count < 0 && errno == EINTR) continue;
    if (count <= 0) break;
    result.output.append(buffer.data(), static_cast<size_t>(count));
  }
  close(fds[0]);
  int status = 0;
  rusage usage{};
  while (wait4(child, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.peak_rss_kb = usage.ru_maxrss;
  return result;
}

}  // namespace ecv::test
