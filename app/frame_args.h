#pragma once

#include <CLI/CLI.hpp>

#include <string>

#include "core/mesh.h"
#include "io/frame_io.h"

namespace ecv::app {

/// Declares the frame flags shared by every subcommand (--color, --depth, --depth-scale, --camera) on
/// `command`; parsed values land in `spec`. The positional FRAME is declared by each command.
void AddFrameFlags(CLI::App& command, FrameSpec* spec);

/// Loads the frame `spec` names (LoadFrame); what looks suspect (a depth scale off by 10x or more) is printed as
/// a warning.
LoadedFrame LoadFrameWithWarnings(const FrameSpec& spec);

/// Default of the --threads flags: every core of the machine (at least 1, at most kMaxThreads).
int AllCores();

/// Checks of numeric flags whose messages say what was expected ("--views: expected a whole number of at least 1,
/// got 0"), for counts, sizes and distances.
CLI::Validator AtLeastOne();     ///< a whole number >= 1 (views, pixels)
CLI::Validator OneTo(int most);  ///< a whole number from 1 to `most` (threads, image sizes)
CLI::Validator ThreadCount();    ///< OneTo(kMaxThreads), for every --threads
CLI::Validator Positive();       ///< a number > 0
CLI::Validator NonNegative();    ///< a number >= 0
/// A number above `low` and at most `high` (a wavelength, whose upper bound keeps its padding within memory).
CLI::Validator AboveAtMost(double low, double high);

/// The mesh flags shared by every subcommand that reads meshes.
struct MeshArgs {
  std::string unit = "m";               ///< --unit m|cm|mm
  std::string object_from_mesh_path;    ///< --object-from-mesh POSE.json
  bool allow_missing_textures = false;  ///< --allow-missing-textures
};

/// Declares --unit, --object-from-mesh and --allow-missing-textures on `command`.
void AddMeshFlags(CLI::App& command, MeshArgs* args);

/// Loads the mesh at `path` as the flags say; what was tolerated is printed as a warning.
TriangleMesh LoadMeshWithArgs(const std::string& path, const MeshArgs& args);

}  // namespace ecv::app
