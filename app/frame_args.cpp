#include "app/frame_args.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <new>
#include <sstream>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/parallel.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"

namespace ecv::app {

void AddFrameFlags(CLI::App& command, FrameSpec* spec) {
  command.add_option("--color", spec->color_path, "Colour image (PNG or JPG)")->group("Frame from files");
  command.add_option("--depth", spec->depth_path, "16-bit depth PNG (also replaces a BOP image's depth)")
      ->group("Frame from files");
  command
      .add_option_function<double>(
          "--depth-scale", [spec](double scale) { spec->depth_scale = scale; },
          "Depth PNG values per metre: metres = value / S (YCB-Video 10000, millimetre PNGs 1000)")
      ->group("Frame from files");
  command
      .add_option_function<std::string>(
          "--camera", [spec](const std::string& text) { spec->camera = text; }, "Intrinsics fx,fy,cx,cy in pixels")
      ->group("Frame from files");
}

namespace {

// `load()`, with running out of memory (std::bad_alloc, or OpenCV's "Failed to allocate N bytes") as an InputError
// naming `source`, the file being read: the readers bound what a file may claim, but not the memory left.
template <typename Load>
auto NamingTheFileOutOfMemory(const std::string& source, Load load) {
  try {
    return load();
  } catch (const std::bad_alloc&) {
    ThrowInputError(source, "memory", "a file whose contents fit in the memory left", "out of memory (std::bad_alloc)");
  } catch (const cv::Exception& error) {
    if (error.code != cv::Error::StsNoMem) throw;
    ThrowInputError(source, "memory", "a file whose contents fit in the memory left",
                    "out of memory (" + error.err + ")");
  }
}

}  // namespace

LoadedFrame LoadFrameWithWarnings(const FrameSpec& spec) {
  std::vector<std::string> warnings;
  const std::string source = !spec.positional.empty() ? spec.positional : spec.color_path + ", " + spec.depth_path;
  LoadedFrame frame = NamingTheFileOutOfMemory(source, [&] { return LoadFrame(spec, &warnings); });
  for (const std::string& warning : warnings) std::cerr << "ecvpose: warning: " << warning << '\n';
  return frame;
}

int AllCores() {
  return std::min(kMaxThreads, static_cast<int>(std::max(1U, std::thread::hardware_concurrency())));
}

namespace {

// A validator of numbers that `accepts`; anything else gets "expected <what>, got <text>".
CLI::Validator NumberCheck(const std::string& what, const std::string& description,
                           const std::function<bool(double)>& accepts) {
  return CLI::Validator(
      [what, accepts](std::string& text) {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        const bool number = !text.empty() && end == text.c_str() + text.size() && std::isfinite(value);
        return number && accepts(value) ? std::string() : "expected " + what + ", got " + text;
      },
      description);
}

}  // namespace

CLI::Validator AtLeastOne() {
  return NumberCheck("a whole number of at least 1", "POSITIVE",
                     [](double v) { return v >= 1.0 && v == std::floor(v); });
}

CLI::Validator OneTo(int most) {
  return NumberCheck("a whole number from 1 to " + std::to_string(most), "[1 - " + std::to_string(most) + "]",
                     [most](double v) { return v >= 1.0 && v <= most && v == std::floor(v); });
}

CLI::Validator ThreadCount() {
  return OneTo(kMaxThreads);
}

CLI::Validator Positive() {
  return NumberCheck("a number > 0", "POSITIVE", [](double v) { return v > 0.0; });
}

CLI::Validator NonNegative() {
  return NumberCheck("a number >= 0", "NONNEGATIVE", [](double v) { return v >= 0.0; });
}

CLI::Validator AboveAtMost(double low, double high) {
  std::ostringstream what;
  what << "a number above " << low << " and at most " << high;
  return NumberCheck(what.str(), "NUMBER", [low, high](double v) { return v > low && v <= high; });
}

void AddMeshFlags(CLI::App& command, MeshArgs* args) {
  command.add_option("--unit", args->unit, "Unit of mesh coordinates")
      ->check(CLI::IsMember({"m", "cm", "mm"}))
      ->capture_default_str()
      ->group("Mesh");
  command
      .add_option("--object-from-mesh", args->object_from_mesh_path,
                  "Pose JSON with key object_from_mesh applied to meshes after the unit")
      ->check(CLI::ExistingFile)
      ->group("Mesh");
  command
      .add_flag("--allow-missing-textures", args->allow_missing_textures,
                "Use vertex or material colours where a texture file is missing (with a warning)")
      ->group("Mesh");
}

TriangleMesh LoadMeshWithArgs(const std::string& path, const MeshArgs& args) {
  MeshLoadOptions options;
  options.metres_per_unit = MetresPerUnit(args.unit);
  options.allow_missing_textures = args.allow_missing_textures;
  if (!args.object_from_mesh_path.empty()) {
    options.object_from_mesh = ReadPoseFile(args.object_from_mesh_path, "object_from_mesh");
  }
  std::vector<std::string> warnings;
  TriangleMesh mesh = NamingTheFileOutOfMemory(path, [&] { return LoadMesh(path, options, &warnings); });
  for (const std::string& warning : warnings) std::cerr << "ecvpose: warning: " << warning << '\n';
  return mesh;
}

}  // namespace ecv::app
