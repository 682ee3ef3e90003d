#include "app/frame_args.h"

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

}  // namespace ecv::app
