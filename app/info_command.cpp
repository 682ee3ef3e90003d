// `ecvpose info PATH...`: what a frame or a mesh holds, for people (text) and programs (--out-json).

#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"

namespace ecv::app {
namespace {

struct InfoArgs {
  std::vector<std::string> paths;
  FrameSpec frame;
  MeshArgs mesh;
  std::string out_json;
};

// `value` with `decimals` digits after the point.
std::string Fixed(double value, int decimals) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(decimals) << value;
  return text.str();
}

// "x .. y .. z" triple in millimetres.
std::string Millimetres(const Eigen::Vector3d& metres, const char* separator) {
  return Fixed(1000 * metres.x(), 1) + separator + Fixed(1000 * metres.y(), 1) + separator +
         Fixed(1000 * metres.z(), 1);
}

nlohmann::json DescribeFrame(const LoadedFrame& loaded) {
  const RgbdFrame& frame = loaded.rgbd;
  const DepthStats depth = ComputeDepthStats(frame.depth);
  const PinholeCamera& camera = frame.camera;
  std::cout << "frame " << frame.name << '\n'
            << "  size      " << frame.color.cols << " x " << frame.color.rows << " pixels\n"
            << "  camera    fx " << Fixed(camera.fx, 3) << "  fy " << Fixed(camera.fy, 3) << "  cx "
            << Fixed(camera.cx, 3) << "  cy " << Fixed(camera.cy, 3) << " (pixels)\n"
            << "  depth     " << Fixed(100.0 * depth.valid_fraction, 1) << " % valid, " << Fixed(depth.min_m, 3)
            << " .. " << Fixed(depth.max_m, 3) << " m (median " << Fixed(depth.median_m, 3) << " m)\n";
  nlohmann::json objects = nlohmann::json::array();
  if (!loaded.ground_truth.empty()) std::cout << "  truth     " << loaded.ground_truth.size() << " objects\n";
  for (const GroundTruth& truth : loaded.ground_truth) {
    std::cout << "            " << truth.object_name << " (id " << truth.object_id << ") at ("
              << Millimetres(truth.camera_from_object.translation(), ", ") << ") mm\n";
    objects.push_back({{"object_id", truth.object_id},
                       {"object_name", truth.object_name},
                       {"camera_from_object", PoseToJson(truth.camera_from_object)}});
  }
  return {{"kind", "frame"},
          {"path", frame.name},
          {"width", frame.color.cols},
          {"height", frame.color.rows},
          {"camera", {camera.fx, camera.fy, camera.cx, camera.cy}},
          {"depth_valid_fraction", depth.valid_fraction},
          {"depth_min_m", depth.min_m},
          {"depth_max_m", depth.max_m},
          {"depth_median_m", depth.median_m},
          {"ground_truth", objects}};
}

nlohmann::json DescribeMesh(const std::string& path, const InfoArgs& args) {
  const TriangleMesh mesh = LoadMeshWithArgs(path, args.mesh);

  std::vector<std::string> colorings;
  for (const MeshPart& part : mesh.parts) {
    std::string coloring = ToString(mesh.Coloring(part));
    if (mesh.Coloring(part) == MeshColoring::kTexture) {
      const cv::Mat& texture = mesh.materials[static_cast<size_t>(part.material)].texture;
      coloring += " " + std::to_string(texture.cols) + "x" + std::to_string(texture.rows);
    }
    colorings.push_back(coloring);
  }
  const Eigen::AlignedBox3d box = mesh.BoundingBox();
  const Eigen::Vector3d size = box.sizes();
  const double diameter = mesh.Diameter();
  std::cout << "mesh " << path << '\n'
            << "  geometry  " << mesh.NumVertices() << " vertices, " << mesh.NumTriangles() << " triangles, "
            << mesh.parts.size() << " part(s)\n"
            << "  colour    ";
  for (size_t i = 0; i < colorings.size(); ++i) std::cout << (i > 0 ? ", " : "") << colorings[i];
  std::cout << '\n'
            << "  box       " << Millimetres(size, " x ") << " mm, from (" << Millimetres(box.min(), ", ") << ") mm\n"
            << "  diameter  " << Fixed(1000 * diameter, 1) << " mm\n";
  if (diameter > 5.0 && args.mesh.unit == "m") {
    std::cerr << "ecvpose: warning: " << path << " is " << diameter
              << " m across; if its unit is millimetres, give --unit mm\n";
  }
  return {{"kind", "mesh"},
          {"path", path},
          {"vertices", mesh.NumVertices()},
          {"triangles", mesh.NumTriangles()},
          {"coloring", colorings},
          {"bbox_min_m", {box.min().x(), box.min().y(), box.min().z()}},
          {"bbox_max_m", {box.max().x(), box.max().y(), box.max().z()}},
          {"diameter_m", diameter}};
}

int RunInfo(const InfoArgs& args) {
  nlohmann::json described = nlohmann::json::array();
  if (args.paths.empty()) described.push_back(DescribeFrame(app::LoadFrameWithWarnings(args.frame)));
  for (const std::string& path : args.paths) {
    if (LooksLikeMesh(path)) {
      described.push_back(DescribeMesh(path, args));
    } else {
      FrameSpec spec = args.frame;
      spec.positional = path;
      described.push_back(DescribeFrame(app::LoadFrameWithWarnings(spec)));
    }
  }
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, {{"items", described}});
  return kExitOk;
}

}  // namespace

CommandAction SetupInfoCommand(CLI::App& command) {
  auto args = std::make_shared<InfoArgs>();
  command.add_option("PATH", args->paths,
                     "Frames (frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID, organized .pcd) and meshes "
                     "(.obj .ply .gltf .glb ...)");
  AddFrameFlags(command, &args->frame);
  AddMeshFlags(command, &args->mesh);
  command.add_option("--out-json", args->out_json, "Also write what is printed as JSON");
  command.footer(
      "Examples:\n  ecvpose info ../shared/data/ycbv_subset/Example-Scenes/0001/000001\n"
      "  ecvpose info --unit mm ../shared/data/lmo_subset/data/bop/lmo/models/obj_000005.ply");
  return [args] { return RunInfo(*args); };
}

}  // namespace ecv::app
