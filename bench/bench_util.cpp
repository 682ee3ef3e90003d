#include "bench_util.h"

#include <sched.h>
#include <sys/wait.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numeric>
#include <sstream>

namespace ecv::bench {

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : 2;  // prints the help or the usage error
  }
  return std::nullopt;
}

CLI::Validator AtLeastOne() {
  return CLI::Range(1, std::numeric_limits<int>::max()).description("POSITIVE");
}

std::string MachineDescription() {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  const int cores = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : 0;
  return model + " (" + std::to_string(cores) + " cores)";
}

std::string CommandLine(int argc, char** argv) {
  std::string command;
  for (int i = 0; i < argc; ++i) command += (i > 0 ? " " : "") + std::string(argv[i]);
  return command;
}

std::string Fixed(double value, int decimals) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

double Mean(const std::vector<double>& values) {
  if (values.empty()) return 0.0;
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

LoadedFrame LmoFrame(const std::string& data_dir) {
  const std::string lmo = data_dir + "/lmo_subset";
  return LoadBopFrame(lmo + "/data/bop/lmo/test/000002", 3, lmo + "/SAM-6D/Data/Example/depth.png");
}

std::vector<std::string> YcbvFramePrefixes(const std::string& data_dir) {
  std::vector<std::string> prefixes;
  const std::string suffix = "-color.png";
  for (const auto& video : std::filesystem::directory_iterator(data_dir + "/ycbv_subset/Example-Scenes")) {
    for (const auto& file : std::filesystem::directory_iterator(video.path())) {
      const std::string name = file.path().string();
      if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        prefixes.push_back(name.substr(0, name.size() - suffix.size()));
      }
    }
  }
  std::sort(prefixes.begin(), prefixes.end());
  return prefixes;
}

namespace {

std::string Section(const std::string& title, const std::string& command, const std::string& markdown) {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  return "## " + title + "\n\n" + date + ", " + MachineDescription() + ", `" + command + "`\n\n" + markdown + "\n";
}

}  // namespace

void ReportSection(const std::string& results_path, const std::string& title, const std::string& command,
                   const std::string& markdown) {
  const std::string section = Section(title, command, markdown);
  std::cout << section;
  std::string text;
  {
    std::ifstream in(results_path);
    std::ostringstream whole;
    whole << in.rdbuf();
    text = whole.str();
  }
  const std::string heading = "## " + title + "\n";
  size_t begin = text.rfind("\n" + heading);
  begin = text.compare(0, heading.size(), heading) == 0 ? 0 : begin == std::string::npos ? begin : begin + 1;
  if (begin == std::string::npos) {  // a new section, after a blank line
    while (!text.empty() && text.back() == '\n') text.pop_back();
    text += (text.empty() ? "" : "\n\n") + section;
  } else {
    const size_t end = text.find("\n## ", begin + heading.size());
    text.replace(begin, end == std::string::npos ? std::string::npos : end + 1 - begin, section);
  }
  const std::string temporary = results_path + ".tmp";
  std::ofstream out(temporary);
  out << text;
  out.close();
  if (!out || std::rename(temporary.c_str(), results_path.c_str()) != 0) {
    std::cerr << "could not write " << results_path << '\n';
  }
}

std::string ShellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

int RunShellCommand(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace ecv::bench
