#include "support/test_data.h"

#include <sys/wait.h>

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
  const std::string command = shell_command + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  size_t count = 0;
  while ((count = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.output.append(buffer.data(), count);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace ecv::test
