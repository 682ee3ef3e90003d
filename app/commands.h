#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "io/frame_source.h"

namespace ecv::app {

/// Exit codes of every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 1;
inline constexpr int kExitBadUsage = 2;

/// Declares the required `--db LIB` flag, a model library file, on `command`; `description` says what the command
/// takes from it.
inline CLI::Option* AddDbOption(CLI::App& command, std::string* db,
                                const std::string& description = "Model library file (SQLite)") {
  return command.add_option("--db", *db, description)->required();
}

/// What a subcommand does once its flags are parsed; returns the exit code.
using CommandAction = std::function<int()>;

/// One row of the subcommand table: its name, a one-line summary, and a function that declares its
/// flags on `command` and returns its action.
struct Subcommand {
  const char* name;
  const char* summary;
  CommandAction (*setup)(CLI::App& command);
};

CommandAction SetupInfoCommand(CLI::App& command);
CommandAction SetupFeaturesCommand(CLI::App& command);
CommandAction SetupRenderCommand(CLI::App& command);   // render/render_command.cpp
CommandAction SetupModeldbCommand(CLI::App& command);  // modeldb/modeldb_command.cpp
CommandAction SetupRegisterCommand(CLI::App& command);
CommandAction SetupColorcalCommand(CLI::App& command);  // colorcal/colorcal_command.cpp
/// `open_live` opens the --sequence sources beyond files (camera/: OpenNI2 devices and recordings).
CommandAction SetupRecognizeCommand(CLI::App& command, FrameSourceOpener open_live);  // recognize/recognize_command.cpp
CommandAction SetupServeCommand(CLI::App& command);                                   // recognize/serve_command.cpp
CommandAction SetupEvalCommand(CLI::App& command);                                    // recognize/eval_command.cpp
CommandAction SetupBopCommand(CLI::App& command);                                     // app/bop_command.cpp
CommandAction SetupRecordCommand(CLI::App& command);                                  // camera/camera_command.cpp
/// Opens openni2:// cameras and .oni recordings as frame sources; nullptr for other sequences (camera_command.cpp).
std::unique_ptr<FrameSource> OpenCameraSource(const std::string& sequence,
                                              const std::optional<std::string>& intrinsics);

}  // namespace ecv::app
