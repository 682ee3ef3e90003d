#pragma once

#include <CLI/CLI.hpp>

#include "io/frame_io.h"

namespace ecv::app {

/// Declares the frame flags shared by every subcommand (--color, --depth, --depth-scale, --camera) on
/// `command`; parsed values land in `spec`. The positional FRAME is declared by each command.
void AddFrameFlags(CLI::App& command, FrameSpec* spec);

}  // namespace ecv::app
