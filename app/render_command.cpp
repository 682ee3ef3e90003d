// `ecvpose render`: views of a mesh to a folder, a model overlaid on a real frame, or a scene file.
// Compiled only into the ecvpose executable; reads flags into options and calls ecv_render.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "render/overlay.h"
#include "render/render_io.h"
#include "render/renderer.h"
#include "render/sensor_noise.h"
#include "render/view_sampling.h"

namespace ecv::app {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct RenderArgs {
  std::vector<std::string> positionals;  // MESH [FRAME]
  FrameSpec frame;
  int views = 0;
  std::string out_dir;
  int width = 640;
  int height = 480;
  MeshArgs mesh;
  std::string shading = "unlit";
  std::vector<double> elevation_deg = {-90.0, 90.0};
  std::string up = "0,0,1";
  double margin = 0.1;
  std::string pose_path;
  std::string overlay_path;
  std::string scene_path;
};

// Prints "render: i/n views (t s)" to stderr at most once a second, and at the end.
class Progress {
 public:
  explicit Progress(int total) : total_(total) {}
  void Step(int done) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (done < total_ && seconds - last_ < 1.0) return;
    last_ = seconds;
    std::cerr << "render: " << done << "/" << total_ << " views (" << std::round(seconds * 10) / 10 << " s)\n";
  }

 private:
  int total_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double last_ = 0.0;
};

int UsageError(const std::string& message) {
  std::cerr << "ecvpose render: " << message << "\nRun `ecvpose render --help` for the forms of the command.\n";
  return kExitBadUsage;
}

// --camera fx,fy,cx,cy (the frame flag) with --width/--height; by default a 58 degree horizontal field of view (Kinect
// v1) with the principal point at the image centre.
PinholeCamera CameraArgument(const RenderArgs& args) {
  PinholeCamera camera;
  camera.width = args.width;
  camera.height = args.height;
  if (!args.frame.camera) {
    camera.fx = camera.fy = args.width / (2.0 * std::tan(29.0 * kDegree));
    camera.cx = (args.width - 1) / 2.0;
    camera.cy = (args.height - 1) / 2.0;
  } else {
    const auto k = ParseIntrinsics(*args.frame.camera, "--camera");
    camera = PinholeCamera{k[0], k[1], k[2], k[3], args.width, args.height};
  }
  camera.Check("--camera/--width/--height");
  return camera;
}

// "x,y,z" as a vector; throws InputError naming `flag` otherwise.
Eigen::Vector3d ParseDirection(const std::string& text, const std::string& flag) {
  Eigen::Vector3d direction;
  char comma1 = 0, comma2 = 0;
  std::istringstream stream(text);
  stream >> direction.x() >> comma1 >> direction.y() >> comma2 >> direction.z();
  if (!stream || comma1 != ',' || comma2 != ',' || !(stream >> std::ws).eof()) {
    ThrowInputError(flag, "direction", "three numbers x,y,z", text);
  }
  return direction;
}

ViewSamplingOptions SamplingArguments(const RenderArgs& args) {
  ViewSamplingOptions sampling;
  sampling.num_views = args.views;
  sampling.min_elevation_rad = args.elevation_deg.at(0) * kDegree;
  sampling.max_elevation_rad = args.elevation_deg.at(1) * kDegree;
  sampling.margin = args.margin;
  sampling.up_object = ParseDirection(args.up, "--up");
  if (std::abs(sampling.up_object.normalized().x()) > 0.9) sampling.forward_object = Eigen::Vector3d::UnitY();
  sampling.Check();
  return sampling;
}

RenderOptions RenderArguments(const RenderArgs& args) {
  RenderOptions options;
  options.shading = args.shading == "headlight" ? Shading::kHeadlight : Shading::kUnlit;
  return options;
}

std::string Stem(int index) {
  char text[16];
  std::snprintf(text, sizeof(text), "%06d", index);
  return text;
}

int RunViews(const RenderArgs& args) {
  const std::string& mesh_path = args.positionals.at(0);
  const TriangleMesh mesh = LoadMeshWithArgs(mesh_path, args.mesh);
  const PinholeCamera camera = CameraArgument(args);
  const std::vector<Eigen::Isometry3d> views =
      SampleViews(ComputeBoundingSphere(mesh), camera, SamplingArguments(args));
  const RenderOptions options = RenderArguments(args);
  Renderer renderer;
  const MeshId id = renderer.AddMesh(mesh);
  nlohmann::json index = nlohmann::json::array();
  Progress progress(static_cast<int>(views.size()));
  int out_of_range = 0;
  for (size_t i = 0; i < views.size(); ++i) {
    const RenderResult rendered = renderer.Render(id, camera, views[i], options);
    const nlohmann::json pose = {{"camera_from_object", PoseToJson(views[i])}, {"mesh", mesh_path}};
    const RenderedViewFiles files = WriteRenderedView(args.out_dir, Stem(static_cast<int>(i)), rendered, camera, pose);
    out_of_range += files.depth_out_of_range;
    index.push_back({{"frame", files.json}, {"camera_from_object", PoseToJson(views[i])}});
    progress.Step(static_cast<int>(i + 1));
  }
  if (out_of_range > 0)
    std::cerr << "ecvpose: warning: " << out_of_range << " depth pixels beyond 6.5535 m written as 0\n";
  WriteJsonFile(args.out_dir + "/views.json", {{"mesh", mesh_path},
                                               {"unit", args.mesh.unit},
                                               {"camera", CameraToJson(camera)},
                                               {"depth_scale", kRenderedDepthScale},
                                               {"renderer", renderer.Description()},
                                               {"views", index}});
  std::cout << "wrote " << views.size() << " views of " << mesh_path << " to " << args.out_dir << '\n';
  return kExitOk;
}

int RunOverlay(const RenderArgs& args) {
  if (args.pose_path.empty()) return UsageError("--overlay needs --pose POSE.json (key camera_from_object)");
  FrameSpec spec = args.frame;
  if (args.positionals.size() > 1) spec.positional = args.positionals[1];
  const LoadedFrame frame = LoadFrame(spec);
  const Eigen::Isometry3d camera_from_object = ReadPoseFile(args.pose_path);
  Renderer renderer;
  const MeshId id = renderer.AddMesh(LoadMeshWithArgs(args.positionals.at(0), args.mesh));
  WriteColorImage(args.overlay_path,
                  RenderOverlay(renderer, {SceneObject{id, camera_from_object}}, frame.rgbd.camera, frame.rgbd.color));
  std::cout << "wrote " << args.overlay_path << '\n';
  return kExitOk;
}

// Renders view `v` of `scene` (with the noise model if the scene asks) and writes its files; returns
// the entry of views.json.
nlohmann::json RenderSceneView(Renderer& renderer, const SceneFile& scene, const std::vector<MeshId>& ids, size_t v,
                               const RenderArgs& args) {
  const Eigen::Isometry3d& camera_from_scene = scene.camera_from_scene[v];
  std::vector<SceneObject> placed;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    placed.push_back({ids[i], camera_from_scene * scene.objects[i].scene_from_object});
  }
  const RenderResult rendered = renderer.RenderScene(placed, scene.camera, RenderArguments(args));
  nlohmann::json objects = nlohmann::json::array();
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    objects.push_back({{"name", scene.objects[i].name},
                       {"mesh", scene.objects[i].mesh_path},
                       {"label", i + 1},
                       {"visible_pixels", rendered.visible_pixels[i]},
                       {"camera_from_object", PoseToJson(placed[i].camera_from_object)}});
  }
  cv::Mat depth;
  if (scene.add_noise) {
    SensorNoiseOptions noise = scene.noise;
    noise.seed += static_cast<uint32_t>(v);  // one random stream per view, repeatable
    depth = SimulateStructuredLight(rendered.depth, scene.camera, noise).depth;
  }
  const nlohmann::json extra = {
      {"camera_from_scene", PoseToJson(camera_from_scene)}, {"objects", objects}, {"depth_noise", scene.add_noise}};
  const RenderedViewFiles files =
      WriteRenderedView(args.out_dir, Stem(static_cast<int>(v)), rendered, scene.camera, extra, true, depth);
  return {{"frame", files.json}, {"camera_from_scene", PoseToJson(camera_from_scene)}};
}

int RunScene(const RenderArgs& args) {
  const SceneFile scene = ReadSceneFile(args.scene_path);
  Renderer renderer;
  std::vector<MeshId> ids;
  for (const SceneFileObject& object : scene.objects) ids.push_back(renderer.AddMesh(object.mesh));
  nlohmann::json index = nlohmann::json::array();
  Progress progress(static_cast<int>(scene.camera_from_scene.size()));
  for (size_t v = 0; v < scene.camera_from_scene.size(); ++v) {
    index.push_back(RenderSceneView(renderer, scene, ids, v, args));
    progress.Step(static_cast<int>(v + 1));
  }
  WriteJsonFile(args.out_dir + "/views.json", {{"scene", args.scene_path},
                                               {"camera", CameraToJson(scene.camera)},
                                               {"depth_scale", kRenderedDepthScale},
                                               {"views", index}});
  std::cout << "wrote " << scene.camera_from_scene.size() << " views of " << args.scene_path << " to " << args.out_dir
            << '\n';
  return kExitOk;
}

int RunRender(const RenderArgs& args) {
  if (!args.scene_path.empty()) {
    if (!args.positionals.empty()) return UsageError("--scene takes no MESH or FRAME");
    if (args.out_dir.empty()) return UsageError("--scene needs --out DIR");
    return RunScene(args);
  }
  if (args.positionals.empty()) return UsageError("give a MESH, or --scene SCENE.json");
  if (!args.overlay_path.empty()) return RunOverlay(args);
  if (args.positionals.size() > 1) return UsageError("a FRAME is only used with --overlay");
  if (args.views < 1 || args.out_dir.empty()) return UsageError("give --views N (N >= 1) and --out DIR");
  return RunViews(args);
}

}  // namespace

CommandAction SetupRenderCommand(CLI::App& command) {
  auto args = std::make_shared<RenderArgs>();
  command.add_option("PATHS", args->positionals, "MESH (.obj .ply .gltf ...), and with --overlay the FRAME")
      ->expected(0, 2);
  AddFrameFlags(command, &args->frame);
  command.add_option("--views", args->views, "Number of viewpoints spread over the sphere (or --elevation band)");
  command.add_option("--out", args->out_dir, "Folder for PNGs (colour, 16-bit depth, mask) and JSON per view");
  command.add_option("--width", args->width, "Image width, pixels")
      ->capture_default_str()
      ->check(OneTo(kMaxRenderSide));
  command.add_option("--height", args->height, "Image height, pixels")
      ->capture_default_str()
      ->check(OneTo(kMaxRenderSide));
  AddMeshFlags(command, &args->mesh);
  command.add_option("--shading", args->shading, "unlit (surface colours as stored) or headlight")
      ->check(CLI::IsMember({"unlit", "headlight"}))
      ->capture_default_str();
  command.add_option("--elevation", args->elevation_deg, "Band of view elevations MIN MAX, degrees")
      ->expected(2)
      ->capture_default_str();
  command.add_option("--up", args->up, "Object-frame up direction x,y,z (upright in the images)")
      ->capture_default_str();
  command.add_option("--margin", args->margin, "Free fraction of the image half-size around the object")
      ->capture_default_str();
  command.add_option("--pose", args->pose_path, "Pose JSON with camera_from_object, for --overlay")
      ->check(CLI::ExistingFile);
  command.add_option("--overlay", args->overlay_path, "Write the model in red over FRAME to this PNG");
  command.add_option("--scene", args->scene_path, "Scene JSON (meshes with poses, camera, viewpoints, noise)")
      ->check(CLI::ExistingFile);
  command.footer(
      "Forms:\n  ecvpose render MESH --views N --out DIR [--width W --height H --camera fx,fy,cx,cy] [--unit mm]\n"
      "  ecvpose render MESH FRAME --pose POSE.json --overlay overlay.png\n"
      "  ecvpose render --scene SCENE.json --out DIR\n"
      "--camera fx,fy,cx,cy also sets the intrinsics of rendered views (default: 58 deg wide, centred).\n"
      "Depth PNGs hold metres * 10000 (depth_scale in each view's JSON); each view's JSON is a frame JSON.");
  return [args] { return RunRender(*args); };
}

}  // namespace ecv::app
