#pragma once

#include <filesystem>
#include <string>

namespace ecv::test {

/// Path inside the shared real data (../shared/data beside the checkout, or -DECVPOSE_DATA_DIR).
/// Fails the test when the file is not there, naming the path.
std::string DataPath(const std::string& relative);

/// A fresh empty directory under the system's temporary directory, removed when it goes out of scope.
class TemporaryDirectory {
 public:
  TemporaryDirectory();
  ~TemporaryDirectory();
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

/// Output and exit code of a command run through the shell.
struct CommandResult {
  int exit_code = -1;
  std::string output;     ///< standard output and standard error together
  long peak_rss_kb = -1;  ///< the largest resident set of the command's processes (getrusage ru_maxrss), KB
};

/// Runs the ecvpose tool with `arguments` (shell syntax), after `prefix` (e.g. a command that drops
/// privileges) when given.
CommandResult RunCli(const std::string& arguments, const std::string& prefix = "");

/// Runs `command` (shell syntax) with standard error joined to standard output.
CommandResult RunCommand(const std::string& command);

}  // namespace ecv::test
