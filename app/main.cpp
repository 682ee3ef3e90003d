// ecvpose: one command-line tool, a table of subcommands. Each reads its flags into options and calls
// one library function; only this file turns exceptions into exit codes.

#include <algorithm>
#include <iostream>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include "app/commands.h"
#include "core/error.h"
#include "core/version.h"

namespace {

using ecv::app::Subcommand;

const Subcommand kSubcommands[] = {
    {"info", "Describe RGB-D frames (size, camera, depth) and meshes (size, colouring, diameter)",
     ecv::app::SetupInfoCommand},
    {"features", "Extract ECV primitives (segments, texlets) of a frame; counts, picture, PLY",
     ecv::app::SetupFeaturesCommand},
    {"render", "Render a mesh's views (RGB, metric depth, mask), a model over a frame, or a scene",
     ecv::app::SetupRenderCommand},
    {"modeldb", "Build the model library (SQLite) from meshes; list, info, remove, verify, export",
     ecv::app::SetupModeldbCommand},
    {"colorcal", "Fit a model's colour matrix from pairs or a frame with a known pose; show, clear",
     ecv::app::SetupColorcalCommand},
    {"register", "Align two views of a scene (ECV context + prerejective RANSAC + ICP); writes b_from_a",
     ecv::app::SetupRegisterCommand},
    {"recognize", "Find the library's objects with their 6D poses in RGB-D frames; JSON and a picture",
     [](CLI::App& command) { return ecv::app::SetupRecognizeCommand(command, ecv::app::OpenCameraSource); }},
    {"serve", "Keep the library loaded and answer recognition requests, JSON lines on stdin or a Unix socket",
     ecv::app::SetupServeCommand},
    {"eval", "Score detections against ground truth: rotation, translation, ADD, ADD-S, recall",
     ecv::app::SetupEvalCommand},
    {"bop", "Run BOP's localisation task over a dataset (resumable BOP CSV) and print its average recall",
     ecv::app::SetupBopCommand},
    {"record", "Record an OpenNI2 camera or any frame sequence as an .oni file (lossless), K beside it",
     ecv::app::SetupRecordCommand},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "ecvpose: find known objects, with their 6D pose, in RGB-D images.\n"
      "Give a subcommand; `ecvpose <subcommand> --help` describes each.",
      "ecvpose"};
  app.set_version_flag("--version", std::string("ecvpose ") + ecv::kVersion);
  app.require_subcommand(1);
  std::vector<std::pair<CLI::App*, ecv::app::CommandAction>> actions;
  for (const Subcommand& subcommand : kSubcommands) {
    CLI::App* command = app.add_subcommand(subcommand.name, subcommand.summary);
    actions.emplace_back(command, subcommand.setup(*command));
  }

  if (argc <= 1) {
    std::cout << app.help();
    return ecv::app::kExitBadUsage;
  }
  const std::string first = argv[1];
  const bool known = std::any_of(std::begin(kSubcommands), std::end(kSubcommands),
                                 [&](const Subcommand& subcommand) { return first == subcommand.name; });
  if (!known && first.rfind('-', 0) != 0) {
    std::cerr << "ecvpose: unknown subcommand '" << first << "'; the subcommands are:";
    for (const Subcommand& subcommand : kSubcommands) std::cerr << ' ' << subcommand.name;
    std::cerr << " (`ecvpose --help` describes them)\n";
    return ecv::app::kExitBadUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error);  // prints help, the version, or the usage error
    return code == 0 ? ecv::app::kExitOk : ecv::app::kExitBadUsage;
  }

  try {
    for (auto& [command, action] : actions) {
      if (command->parsed()) return action();
    }
  } catch (const ecv::InputError& error) {
    std::cerr << "ecvpose: error: " << error.what() << '\n';
    return ecv::app::kExitBadInput;
  } catch (const std::exception& error) {
    std::cerr << "ecvpose: error: " << error.what() << '\n';
    return ecv::app::kExitBadInput;
  }
  return ecv::app::kExitBadUsage;
}
