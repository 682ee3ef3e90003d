// `ecvpose features FRAME`: ECV primitives of one frame, as counts, a picture and a PLY.

#include <iomanip>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/frame_args.h"
#include "ecv/draw.h"
#include "ecv/primitives.h"
#include "io/ply_io.h"
#include "io/pose_io.h"

namespace ecv::app {
namespace {

struct FeaturesArgs {
  FrameSpec frame;
  EcvOptions options;
  std::string overlay;
  std::string ply;
  std::string out_json;
};

nlohmann::json CountsJson(const ExtractionResult& result) {
  const ExtractionCounts& c = result.counts;
  const ExtractionTimings& t = result.timings;
  return {{"cells", c.cells},
          {"homogeneous", c.homogeneous},
          {"edge_cells", c.edge_cells},
          {"texture_cells", c.texture_cells},
          {"no_depth", c.no_depth},
          {"no_surface", c.no_surface},
          {"segments", c.segments},
          {"texlets", c.texlets},
          {"timings_ms",
           {{"monogenic", t.monogenic_ms},
            {"grid", t.grid_ms},
            {"classify", t.classify_ms},
            {"reconstruct", t.reconstruct_ms},
            {"total", t.Total()}}}};
}

int RunFeatures(const FeaturesArgs& args) {
  const LoadedFrame loaded = app::LoadFrameWithWarnings(args.frame);
  const ExtractionResult result = ExtractPrimitives(loaded.rgbd, args.options);
  const ExtractionCounts& c = result.counts;
  std::cout << std::fixed << std::setprecision(1) << "frame " << loaded.rgbd.name << '\n'
            << "  cells      " << c.cells << " (" << c.homogeneous << " homogeneous, " << c.edge_cells << " edge, "
            << c.texture_cells << " texture)\n"
            << "  dropped    " << c.no_depth << " without depth, " << c.no_surface << " without a surface fit\n"
            << "  primitives " << c.segments << " segments, " << c.texlets << " texlets\n"
            << "  time       " << result.timings.Total() << " ms (monogenic " << result.timings.monogenic_ms
            << ", grid " << result.timings.grid_ms << ", classify " << result.timings.classify_ms << ", 3D "
            << result.timings.reconstruct_ms << ")\n";
  if (!args.overlay.empty()) WriteColorImage(args.overlay, DrawPrimitives(loaded.rgbd.color, result.primitives));
  if (!args.ply.empty()) WritePrimitivesPly(args.ply, result.primitives);
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, CountsJson(result));
  return kExitOk;
}

}  // namespace

CommandAction SetupFeaturesCommand(CLI::App& command) {
  auto args = std::make_shared<FeaturesArgs>();
  command.add_option("FRAME", args->frame.positional,
                     "Frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or organized .pcd (or the frame flags)");
  AddFrameFlags(command, &args->frame);
  command.add_option("--overlay", args->overlay, "Picture: segments blue, texlets green over the image (PNG)");
  command.add_option("--ply", args->ply, "Primitives as a PLY point cloud (camera frame, metres)");
  command.add_option("--out-json", args->out_json, "Counts per stage and timings as JSON");
  EcvOptions& options = args->options;
  command.add_option("--wavelength", options.monogenic.wavelength_px, "Centre wavelength of the band-pass, pixels")
      ->check(AboveAtMost(2.0, MonogenicOptions::kMaxWavelengthPx))
      ->capture_default_str()
      ->group("Extraction");
  command.add_option("--spacing", options.grid_spacing_px, "Hexagonal grid spacing, pixels")
      ->capture_default_str()
      ->group("Extraction");
  command.add_option("--min-magnitude", options.min_magnitude, "Cells below are homogeneous (grey in [0, 1])")
      ->capture_default_str()
      ->group("Extraction");
  command.add_option("--max-edge-variance", options.max_edge_variance, "Circular variance below: edge; above: texture")
      ->capture_default_str()
      ->group("Extraction");
  command.footer(
      "Example:\n  ecvpose features ../shared/data/ycbv_subset/Example-Scenes/0001/000001 --overlay features.png");
  return [args] { return RunFeatures(*args); };
}

}  // namespace ecv::app
