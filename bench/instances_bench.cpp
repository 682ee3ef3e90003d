// Several instances of one model (`recognize --max-instances`): the demo frame (YCB-Video 0001/000001) with the
// mustard bottle of 0002/000001 pasted in at its ground-truth pose (PasteYcbvObject: its label pixels, colour and
// depth; both videos come from one camera), over RANSAC seeds, for one and two instances and for several counts
// of views tried after the first instance; with --ycbv-db, what asking for two instances costs on the 30
// single-instance YCB-Video frames (found, false positives, time).
//
//   ecvpose modeldb build models/meshes --views 40 --distance 0.9 --db /tmp/demo.sqlite
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   instances_bench --db /tmp/demo.sqlite [--ycbv-db /tmp/ycbv.sqlite] [--seeds 10]
//                   [--overlay bench/figures/two_mustard_bottles.jpg] [--results bench/RESULTS.md]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <sstream>

#include "bench_util.h"
#include "io/frame_io.h"
#include "modeldb/model_library.h"
#include "recognize/evaluation.h"
#include "recognize/recognizer.h"

namespace ecv::bench {
namespace {

constexpr char kMustard[] = "006_mustard_bottle";

std::string Prefix(const std::string& frame) {
  return std::string(ECV_DATA_DIR) + "/ycbv_subset/Example-Scenes/" + frame;
}

// One setting over the seeds, on the two-bottle frame.
struct SeedRuns {
  int both_correct = 0;     // runs with both bottles within ADD < 0.1 d
  int second_near = 0;      // runs with the pasted bottle found within 15 mm and 20 degrees
  int bottles = 0;          // mustard detections, all runs
  int false_positives = 0;  // all runs
  std::vector<double> ms;
};

SeedRuns RunSeeds(const ModelLibrary& library, const LoadedFrame& frame, const std::vector<EvalModel>& models,
                  RecognizerOptions options, int seeds, const std::string& overlay) {
  SeedRuns runs;
  for (int seed = 1; seed <= seeds; ++seed) {
    options.ransac.seed = static_cast<uint64_t>(seed);
    Recognizer recognizer(library, options);
    const RecognitionResult result = recognizer.Recognize(frame.rgbd);
    runs.ms.push_back(result.timings_ms.at("total"));
    const FrameEvaluation evaluation = EvaluateFrame("two bottles", result.detections, frame.ground_truth, models);
    runs.false_positives += evaluation.false_positives;
    runs.bottles += static_cast<int>(std::count_if(result.detections.begin(), result.detections.end(),
                                                   [](const Detection& d) { return d.model == kMustard; }));
    int correct = 0;
    for (const ObjectEvaluation& object : evaluation.objects) {
      if (object.model == kMustard) correct += object.correct ? 1 : 0;
    }
    runs.both_correct += correct == 2 ? 1 : 0;
    const ObjectEvaluation& pasted = evaluation.objects.back();  // PasteYcbvObject appends its ground truth
    runs.second_near +=
        pasted.detected && pasted.error.translation_mm < 15.0 && pasted.error.rotation_deg < 20.0 ? 1 : 0;
    if (seed == 1 && !overlay.empty())
      WriteColorImage(overlay, recognizer.DrawDetections(frame.rgbd, result.detections));
    std::cerr << "instances_bench: seed " << seed << ", max_instances " << options.max_instances << ", later views "
              << options.later_instance_views << ": " << result.detections.size() << " detections\n";
  }
  return runs;
}

std::string TwoBottlesTable(const ModelLibrary& library, int seeds, const std::string& overlay) {
  const LoadedFrame frame = PasteYcbvObject(LoadYcbvFrame(Prefix("0001/000001")), Prefix("0002/000001"), kMustard);
  const std::vector<EvalModel> models = EvalModels(library);
  std::ostringstream table;
  table << "The demo frame (0001/000001, models/ library) with the mustard bottle of 0002/000001 pasted in at its "
           "ground-truth pose; RANSAC seeds 1-"
        << seeds
        << ", one thread. Both correct = both bottles within ADD < 0.1 d; second found = the pasted "
           "bottle detected within 15 mm and 20 degrees.\n\n"
        << "| max_instances | views after the first | both correct | second found | mustard detections | "
           "false positives | mean ms per frame |\n|---|---|---|---|---|---|---|\n";
  struct Setting {
    int instances, later_views;
  };
  for (const Setting setting : {Setting{1, 0}, Setting{2, 7}, Setting{2, 14}, Setting{2, 21}, Setting{2, 40}}) {
    RecognizerOptions options;
    options.max_instances = setting.instances;
    options.later_instance_views = setting.later_views;
    const bool drawn = setting.instances == 2 && setting.later_views == RecognizerOptions().later_instance_views;
    const SeedRuns runs = RunSeeds(library, frame, models, options, seeds, drawn ? overlay : "");
    table << "| " << setting.instances << " | " << (setting.instances == 1 ? "-" : std::to_string(setting.later_views))
          << " | " << runs.both_correct << " of " << seeds << " | " << runs.second_near << " of " << seeds << " | "
          << runs.bottles << " | " << runs.false_positives << " | " << Fixed(Mean(runs.ms), 0) << " |\n";
  }
  return table.str();
}

std::string SingleInstanceTable(const ModelLibrary& library) {
  const std::vector<EvalModel> models = EvalModels(library);
  std::vector<LoadedFrame> frames;
  for (const std::string& prefix : YcbvFramePrefixes(ECV_DATA_DIR)) frames.push_back(LoadYcbvFrame(prefix));
  std::ostringstream table;
  table << "\nThe " << frames.size()
        << " YCB-Video frames (one instance of each object), 7-model library, seed 1, one thread:\n\n"
        << "| max_instances | found | false positives per frame | median ms | mean ms |\n|---|---|---|---|---|\n";
  for (const int instances : {1, 2}) {
    RecognizerOptions options;
    options.max_instances = instances;
    Recognizer recognizer(library, options);
    int found = 0, objects = 0, false_positives = 0;
    std::vector<double> ms;
    for (const LoadedFrame& frame : frames) {
      const RecognitionResult result = recognizer.Recognize(frame.rgbd);
      ms.push_back(result.timings_ms.at("total"));
      const FrameEvaluation evaluation = EvaluateFrame("", result.detections, frame.ground_truth, models);
      false_positives += evaluation.false_positives;
      for (const ObjectEvaluation& object : evaluation.objects) {
        ++objects;
        found += object.correct ? 1 : 0;
      }
    }
    std::cerr << "instances_bench: 30 frames, max_instances " << instances << " done\n";
    table << "| " << instances << " | " << found << " of " << objects << " | "
          << Fixed(static_cast<double>(false_positives) / static_cast<double>(frames.size()), 2) << " | "
          << Fixed(Median(ms), 0) << " | " << Fixed(Mean(ms), 0) << " |\n";
  }
  return table.str();
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  using namespace ecv;
  using namespace ecv::bench;
  std::string db, ycbv_db, overlay, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  int seeds = 10;
  CLI::App app{
      "instances_bench: several instances of one model (recognize --max-instances) on a real frame with a "
      "second mustard bottle pasted in, over RANSAC seeds; with --ycbv-db, the cost of asking for two "
      "instances on the 30 single-instance YCB-Video frames.",
      "instances_bench"};
  app.add_option("--db", db, "Library of the demo models (models/meshes)")->required();
  app.add_option("--ycbv-db", ycbv_db,
                 "Library of the 7 YCB-Video models: also run the 30 single-instance frames (default: not run)");
  app.add_option("--seeds", seeds, "RANSAC seeds 1..N on the two-bottle frame")
      ->check(AtLeastOne())
      ->capture_default_str();
  app.add_option("--overlay", overlay, "Picture of the two-instance detections, seed 1 (default: none)");
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.footer(
      "Libraries:\n  ecvpose modeldb build models/meshes --views 40 --distance 0.9 --db DEMO_LIB.sqlite\n"
      "  scripts/build_ycbv_library YCBV_LIB.sqlite --views 40 --distance 0.9");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  try {
    LibraryLoadOptions load;
    load.build_matchers = false;
    std::string markdown = TwoBottlesTable(ModelLibrary::Load(db, load), seeds, overlay);
    if (!ycbv_db.empty()) markdown += SingleInstanceTable(ModelLibrary::Load(ycbv_db, load));
    ReportSection(results, "Several instances of one model (instances_bench)", CommandLine(argc, argv), markdown);
  } catch (const std::exception& error) {
    std::cerr << "instances_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
