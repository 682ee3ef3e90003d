#pragma once

#include <optional>
#include <string>
#include <vector>

#include "io/frame_io.h"

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace ecv::bench {

/// Parses the command line into `app`'s options (CLI11). Returns nothing when the bench should go on, else the
/// exit code: 0 after --help (the help printed), 2 after bad usage (CLI11's message on stderr).
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv);

/// Check of a count flag (runs, frames, seeds, threads): a whole number of at least 1.
CLI::Validator AtLeastOne();

/// "Intel(R) Xeon(R) ... (2 cores)" from /proc/cpuinfo and the scheduler.
std::string MachineDescription();

/// The command line, for the record.
std::string CommandLine(int argc, char** argv);

/// `value` with `decimals` digits after the point.
std::string Fixed(double value, int decimals);

/// Median of `values` (copied); 0 for none.
double Median(std::vector<double> values);

/// Mean of `values`; 0 for none.
double Mean(const std::vector<double>& values);

/// The frame prefixes ("DIR/0001/000001") of YCB-Video's subset under `data_dir` (ycbv_subset/Example-Scenes),
/// sorted: the 30 frames of videos 0000-0002.
std::vector<std::string> YcbvFramePrefixes(const std::string& data_dir);

/// LM-O test scene 000002, image 3 under `data_dir` (lmo_subset): the one LM-O image with depth (SAM-6D's example
/// depth, see lmo_subset/SOURCE.md).
LoadedFrame LmoFrame(const std::string& data_dir);

/// `text` quoted for the shell (single quotes; a single quote inside is closed, escaped and reopened).
std::string ShellQuoted(const std::string& text);

/// Runs `command` with the shell; its exit code, or -1 when it did not exit normally.
int RunShellCommand(const std::string& command);

/// Prints `markdown` under a heading with `title`, the date, the machine and the command, and puts it in
/// `results_path` in place of the section with that heading (up to the next "## "), or at its end when it has none:
/// the file keeps each bench's latest figures (git keeps the older ones). `title` must not change from run to run
/// (no date, no flags), and `markdown` must not hold a line starting with "## " (use "### " within a section).
void ReportSection(const std::string& results_path, const std::string& title, const std::string& command,
                   const std::string& markdown);

}  // namespace ecv::bench
