// Point pair features alone (src/registration/ppf.h): for every ground-truth object of the 30 YCB-Video frames of
// ../shared/data, the rank among the best 20 pose clusters of the first within 2 cm and 15 degrees of the truth, and
// of the first with ADD-S below 0.1 x diameter (what ICP and verification can take from there), and the time per
// model and frame, under the settings given.
//
//   ppf_bench [--stride 2] [--reference-spacing 0.3] [--coplanar 12] [--scene-normals 30] [--spread-margin 0.5]
//             [--frames 000001] [--results F]

#include <CLI/CLI.hpp>

#include <array>
#include <iostream>
#include <map>
#include <sstream>

#include "bench_util.h"
#include "core/pose.h"
#include "core/timing.h"
#include "io/frame_io.h"
#include "io/mesh_io.h"
#include "recognize/evaluation.h"
#include "registration/ppf.h"

namespace ecv::bench {
namespace {

int Run(int argc, char** argv) {
  CLI::App app{"ppf_bench: point pair features alone on the YCB-Video frames' ground-truth objects"};
  PpfOptions options;
  int stride = 2;
  std::string frames_filter, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  app.add_option("--stride", stride, "Scene depth samples every N pixels")->capture_default_str();
  app.add_option("--reference-spacing", options.reference_spacing,
                 "Reference points: one per voxel of this share of the diameter and differing normal")
      ->capture_default_str();
  app.add_option("--coplanar", options.coplanar_deg, "Pairs of one plane within this angle are skipped (degrees)")
      ->capture_default_str();
  app.add_option("--model-normals", options.keep_normal_deg,
                 "A model voxel keeps a second point whose normal differs by more (180: one per voxel, as Drost)")
      ->capture_default_str();
  app.add_option("--scene-normals", options.scene_keep_normal_deg,
                 "A scene voxel keeps a second point whose normal differs by more (180: one per voxel)")
      ->capture_default_str();
  app.add_option("--spread-margin", options.spread_margin,
                 "A feature value this near a bin border (share of a bin) also votes in the neighbouring bin")
      ->capture_default_str();
  app.add_option("--angle-bins", options.angle_bins, "Bins of each angle")->capture_default_str();
  app.add_option("--sampling", options.sampling, "Sub-sampling voxel, share of the diameter")->capture_default_str();
  bool keep_plane = false;
  app.add_flag("--keep-plane", keep_plane, "Keep the scene's dominant plane's points (a table top)");
  app.add_option("--frames", frames_filter, "Only frames whose name contains this (default: all 30)");
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;

  std::map<std::string, PpfModel> models;
  std::ostringstream table;
  table << "| frame | object | rank | error mm / deg | rank ADD-S | references | pairs | entries | ms |\n"
           "|---|---|---:|---|---:|---:|---:|---:|---:|\n";
  int found = 0, objects = 0, found_adds = 0, top5_adds = 0, top20_adds = 0;
  std::vector<double> times, build_times, plane_times;
  double all_ms = 0.0, all_entries = 0.0, all_references = 0.0;      // over every model and frame
  std::map<std::string, std::vector<Eigen::Vector3f>> model_points;  // for ADD-S
  std::map<std::string, std::array<int, 2>> per_video;               // objects, in the best 5 by ADD-S
  for (const std::string& prefix : YcbvFramePrefixes(ECV_DATA_DIR)) {
    if (!frames_filter.empty() && prefix.find(frames_filter) == std::string::npos) continue;
    const LoadedFrame loaded = LoadYcbvFrame(prefix);
    const Clock::time_point plane = Clock::now();
    const std::vector<OrientedPoint> scene = keep_plane
                                                 ? OrientedScenePoints(loaded.rgbd, stride)
                                                 : WithoutDominantPlane(OrientedScenePoints(loaded.rgbd, stride));
    plane_times.push_back(MillisecondsSince(plane));
    const std::string frame = prefix.substr(prefix.size() - 11);
    for (const GroundTruth& truth : loaded.ground_truth) {
      if (models.count(truth.object_name) == 0) {
        MeshLoadOptions load;
        load.allow_missing_textures = true;
        const TriangleMesh mesh = LoadMesh(
            std::string(ECV_DATA_DIR) + "/ycbv_subset/models/" + truth.object_name + "/textured_simple.obj", load);
        const Clock::time_point build = Clock::now();
        models.emplace(truth.object_name, PpfModel(SampleMeshSurface(mesh, 20000), mesh.Diameter(), options));
        build_times.push_back(MillisecondsSince(build));
        std::vector<Eigen::Vector3f>& points = model_points[truth.object_name];
        for (const OrientedPoint& p : SampleMeshSurface(mesh, 2000, 7)) points.push_back(p.position);
      }
      const Clock::time_point start = Clock::now();
      PpfSearchStats stats;
      const std::vector<PpfPose> poses = FindPpfPoses(models.at(truth.object_name), scene, {}, &stats);
      const double ms = MillisecondsSince(start);
      times.push_back(ms);
      all_ms += ms;
      all_entries += static_cast<double>(stats.entries);
      all_references += static_cast<double>(stats.references);
      int rank = -1;
      double mm = 0.0, deg = 0.0;
      for (size_t i = 0; i < poses.size() && rank < 0; ++i) {
        mm = TranslationDistance(poses[i].camera_from_object, truth.camera_from_object) * 1000.0;
        deg = RotationAngle(poses[i].camera_from_object, truth.camera_from_object) * 180.0 / M_PI;
        if (mm < 20.0 && deg < 15.0) rank = static_cast<int>(i);
      }
      const PpfModel& model = models.at(truth.object_name);
      int rank_adds = -1;
      for (size_t i = 0; i < poses.size() && rank_adds < 0; ++i) {
        const PoseError error =
            ComputePoseError(model_points.at(truth.object_name), poses[i].camera_from_object, truth.camera_from_object);
        if (error.adds_m < 0.1 * model.diameter_m()) rank_adds = static_cast<int>(i);
      }
      ++objects;
      found += rank == 0 ? 1 : 0;
      found_adds += rank_adds == 0 ? 1 : 0;
      top5_adds += rank_adds >= 0 && rank_adds < 5 ? 1 : 0;
      top20_adds += rank_adds >= 0 ? 1 : 0;
      std::array<int, 2>& video = per_video[frame.substr(0, 4)];
      ++video[0];
      video[1] += rank_adds >= 0 && rank_adds < 5 ? 1 : 0;
      table << "| " << frame << " | " << truth.object_name << " | " << rank << " | "
            << (rank >= 0 ? Fixed(mm, 0) + " / " + Fixed(deg, 0) : "") << " | " << rank_adds << " | "
            << stats.references << " | " << stats.pairs << " | " << stats.entries << " | " << Fixed(ms, 0) << " |\n";
      std::cerr << frame << ' ' << truth.object_name << " rank " << rank << ", ADD-S rank " << rank_adds << ", "
                << Fixed(ms, 0) << " ms\n";
    }
  }
  std::ostringstream report;
  report << "Best cluster right (within 2 cm and 15 degrees) for " << found << " of " << objects
         << " objects; by ADD-S < 0.1 d: best " << found_adds << ", in the best 5 " << top5_adds << ", in the best 20 "
         << top20_adds << ". Median " << Fixed(Median(times), 0)
         << " ms per model and frame (one thread); model tables " << Fixed(Median(build_times), 0)
         << " ms per model (median); scene points " << Fixed(Median(plane_times), 0)
         << " ms per frame (median). Per reference point " << Fixed(1000.0 * all_ms / all_references, 0) << " us and "
         << Fixed(all_entries / all_references, 0) << " table entries voted for (mean); "
         << Fixed(1e6 * all_ms / all_entries, 1) << " ns per entry. In the best 5 per video:";
  for (const auto& [video, counts] : per_video) report << ' ' << video << ' ' << counts[1] << '/' << counts[0];
  report << ".\n\n" << table.str();
  ReportSection(results, "Point pair features alone on YCB-Video (ppf_bench)", CommandLine(argc, argv), report.str());
  return 0;
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  return ecv::bench::Run(argc, argv);
}
