// render_bench: milliseconds per 640x480 view for the YCB textured meshes (google_16k, 4096^2 textures)
// with one OSMesa context reused, plus the overlay figure of the cracker box at its ground-truth pose.
// Prints a markdown table and puts it in bench/RESULTS.md with the date, the machine and the command, in place of
// its section of the previous run (bench_util ReportSection).
//
//   render_bench [--views N] [--data DIR] [--results FILE] [--figure FILE]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "core/timing.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "render/overlay.h"
#include "render/render_io.h"
#include "render/renderer.h"
#include "render/view_sampling.h"

namespace {

using ecv::Clock;
using ecv::MillisecondsSince;
using ecv::bench::Fixed;

const char* const kObjects[] = {"003_cracker_box",    "004_sugar_box",   "005_tomato_soup_can",
                                "006_mustard_bottle", "009_gelatin_box", "010_potted_meat_can"};

struct Settings {
  int views = 50;
  std::string data = ECV_DATA_DIR;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  std::string figure = std::string(ECV_SOURCE_DIR) + "/bench/figures/render_overlay_0001_000001.png";
  std::string command;
};

// object_from_mesh of `object` from derived/google16k_to_ycbv.txt (p_ycbv = R p_g16k + t).
Eigen::Isometry3d Google16kToYcbv(const std::string& data, const std::string& object) {
  return ecv::ReadTransformTable(data + "/ycbv_subset/derived/google16k_to_ycbv.txt").at(object);
}

ecv::TriangleMesh LoadYcbMesh(const std::string& data, const std::string& object) {
  ecv::MeshLoadOptions options;
  options.object_from_mesh = Google16kToYcbv(data, object);
  return ecv::LoadMesh(data + "/ycbv_subset/ycb_google16k_textured/" + object + "_textured.obj", options);
}

// One table row: load, upload and per-view times of one mesh.
std::string BenchmarkMesh(ecv::Renderer& renderer, const Settings& settings, const std::string& object,
                          const ecv::PinholeCamera& camera) {
  auto start = Clock::now();
  const ecv::TriangleMesh mesh = LoadYcbMesh(settings.data, object);
  const double load_ms = MillisecondsSince(start);
  start = Clock::now();
  const ecv::MeshId id = renderer.AddMesh(mesh);
  const double upload_ms = MillisecondsSince(start);
  ecv::ViewSamplingOptions sampling;
  sampling.num_views = settings.views;
  const auto views = ecv::SampleViews(ecv::ComputeBoundingSphere(mesh), camera, sampling);
  std::vector<double> times;
  double covered = 0.0;
  for (const Eigen::Isometry3d& camera_from_object : views) {
    start = Clock::now();
    const ecv::RenderResult rendered = renderer.Render(id, camera, camera_from_object);
    times.push_back(MillisecondsSince(start));
    covered += static_cast<double>(cv::countNonZero(rendered.mask)) / rendered.mask.total() / views.size();
  }
  renderer.RemoveMesh(id);
  std::sort(times.begin(), times.end());
  const double mean = std::accumulate(times.begin(), times.end(), 0.0) / times.size();
  cv::Mat texture;
  for (const ecv::MeshMaterial& material : mesh.materials) {
    if (!material.texture.empty()) texture = material.texture;
  }
  return "| " + object + " | " + std::to_string(mesh.NumTriangles()) + " | " + std::to_string(texture.cols) + "x" +
         std::to_string(texture.rows) + " | " + Fixed(load_ms, 0) + " | " + Fixed(upload_ms, 0) + " | " +
         Fixed(times[times.size() / 2], 1) + " | " + Fixed(mean, 1) + " | " + Fixed(times.back(), 1) + " | " +
         Fixed(100.0 * covered, 1) + " |\n";
}

void SaveOverlayFigure(ecv::Renderer& renderer, const Settings& settings) {
  const ecv::LoadedFrame frame = ecv::LoadYcbvFrame(settings.data + "/ycbv_subset/Example-Scenes/0001/000001");
  for (const ecv::GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name != "003_cracker_box") continue;
    const ecv::MeshId id = renderer.AddMesh(LoadYcbMesh(settings.data, truth.object_name));
    const cv::Mat overlay =
        ecv::RenderOverlay(renderer, {{id, truth.camera_from_object}}, frame.rgbd.camera, frame.rgbd.color);
    ecv::WriteColorImage(settings.figure, overlay(cv::Rect(80, 60, 400, 360)));  // the box and its neighbours
    renderer.RemoveMesh(id);
    std::cout << "wrote " << settings.figure << '\n';
  }
}

}  // namespace

int main(int argc, char** argv) {
  Settings settings;
  CLI::App app{
      "render_bench: milliseconds per 640x480 view of the textured YCB meshes with one OSMesa context "
      "reused, and the overlay figure of the cracker box at its ground-truth pose.",
      "render_bench"};
  app.add_option("--views", settings.views, "Views rendered per mesh")->capture_default_str();
  app.add_option("--data", settings.data, "Data directory (with ycbv_subset)")->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_option("--figure", settings.figure, "File the overlay picture is written to")->capture_default_str();
  if (const auto exit_code = ecv::bench::ParseCommandLine(app, argc, argv)) return *exit_code;
  settings.command = "render_bench";  // the arguments as given, without the program's path
  for (int i = 1; i < argc; ++i) settings.command += std::string(" ") + argv[i];
  try {
    const ecv::PinholeCamera camera{1066.778, 1067.487, 312.9869, 241.3109, 640, 480};  // YCB-Video
    auto start = Clock::now();
    ecv::Renderer renderer;
    const double context_ms = MillisecondsSince(start);
    std::string table =
        "| mesh | triangles | texture | load ms | upload ms | ms/view median | mean | max | object pixels % |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
    for (const char* object : kObjects) table += BenchmarkMesh(renderer, settings, object, camera);
    const std::string report = "Renderer: " + renderer.Description() + " (context created once in " +
                               Fixed(context_ms, 0) + " ms, reused). " + std::to_string(settings.views) +
                               " views per mesh, 640x480, YCB-Video intrinsics, Fibonacci lattice over the sphere; "
                               "ms/view = Render() wall time incl. read-back of colour, depth and labels.\n\n" +
                               table;
    ecv::bench::ReportSection(settings.results, "Rendering the YCB meshes (render_bench)", settings.command, report);
    SaveOverlayFigure(renderer, settings);
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "render_bench: " << error.what() << '\n';
    return 1;
  }
}
