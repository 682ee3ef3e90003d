// Recognition on real data: every YCB-Video frame under ../shared/data through the recognizer with a library
// of the textured YCB meshes, scored against the ground truth (recall at ADD < 0.1 d, false positives), with
// and without ICP, and the time per frame split by stage.
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   recognize_bench --db /tmp/ycbv.sqlite [--results bench/RESULTS.md] [--frames N]

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "bench_util.h"
#include "io/frame_io.h"
#include "recognize/evaluation.h"
#include "recognize/recognizer.h"

namespace ecv::bench {
namespace {

std::vector<std::string> YcbvFrames(const std::string& data, int limit) {
  std::vector<std::string> prefixes;
  for (const auto& video : std::filesystem::directory_iterator(data + "/ycbv_subset/Example-Scenes")) {
    for (const auto& file : std::filesystem::directory_iterator(video.path())) {
      const std::string name = file.path().string();
      const std::string suffix = "-color.png";
      if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
        prefixes.push_back(name.substr(0, name.size() - suffix.size()));
      }
    }
  }
  std::sort(prefixes.begin(), prefixes.end());
  if (limit > 0 && static_cast<int>(prefixes.size()) > limit) prefixes.resize(static_cast<size_t>(limit));
  return prefixes;
}

struct Run {
  std::vector<FrameEvaluation> frames;
  std::map<std::string, std::vector<double>> stage_ms;
};

Run RunRecognizer(const ModelLibrary& library, const RecognizerOptions& options, const std::vector<std::string>& frames,
                  const std::vector<EvalModel>& models, const std::string& label) {
  Recognizer recognizer(library, options);
  Run run;
  for (size_t i = 0; i < frames.size(); ++i) {
    const LoadedFrame frame = LoadYcbvFrame(frames[i]);
    const RecognitionResult result = recognizer.Recognize(frame.rgbd);
    const std::string name = std::filesystem::path(frames[i]).parent_path().filename().string() + "/" +
                             std::filesystem::path(frames[i]).filename().string();
    run.frames.push_back(EvaluateFrame(name, result.detections, frame.ground_truth, models));
    for (const auto& [stage, ms] : result.timings_ms) run.stage_ms[stage].push_back(ms);
    int correct = 0;
    for (const ObjectEvaluation& object : run.frames.back().objects) correct += object.correct ? 1 : 0;
    std::cerr << label << " [" << i + 1 << "/" << frames.size() << "] " << name << ": " << correct << " of "
              << run.frames.back().objects.size() << " correct, " << run.frames.back().false_positives
              << " false positives, " << Fixed(result.timings_ms.at("total"), 0) << " ms\n";
  }
  return run;
}

// Per object: frames present, correct, recall; then the totals.
std::string RecallTable(const std::map<std::string, Run>& runs) {
  std::map<std::string, std::map<std::string, std::pair<int, int>>> counts;  // object -> run -> (correct, present)
  std::map<std::string, int> false_positives;
  for (const auto& [label, run] : runs) {
    for (const FrameEvaluation& frame : run.frames) {
      false_positives[label] += frame.false_positives;
      for (const ObjectEvaluation& object : frame.objects) {
        auto& [correct, present] = counts[object.model][label];
        correct += object.correct ? 1 : 0;
        ++present;
      }
    }
  }
  std::ostringstream out;
  out << "| object |";
  for (const auto& [label, run] : runs) out << ' ' << label << " |";
  out << "\n|---|";
  for (size_t i = 0; i < runs.size(); ++i) out << "---:|";
  out << '\n';
  std::map<std::string, std::pair<int, int>> totals;
  for (const auto& [object, per_run] : counts) {
    out << "| " << object << " |";
    for (const auto& [label, run] : runs) {
      const auto [correct, present] = per_run.at(label);
      totals[label].first += correct;
      totals[label].second += present;
      out << ' ' << correct << " / " << present << " |";
    }
    out << '\n';
  }
  out << "| **all (recall)** |";
  for (const auto& [label, run] : runs) {
    const auto [correct, present] = totals[label];
    out << " **" << correct << " / " << present << " (" << Fixed(100.0 * correct / std::max(present, 1), 1)
        << " %)** |";
  }
  out << "\n| false positives per frame |";
  for (const auto& [label, run] : runs) {
    out << ' ' << Fixed(static_cast<double>(false_positives[label]) / std::max<size_t>(run.frames.size(), 1), 2)
        << " |";
  }
  out << '\n';
  return out.str();
}

std::string TimingTable(const Run& run) {
  std::ostringstream out;
  out << "| stage | median ms per frame |\n|---|---:|\n";
  for (const char* stage : {"extract", "describe", "match", "ransac", "verify", "refine", "total"}) {
    const auto found = run.stage_ms.find(stage);
    if (found != run.stage_ms.end()) out << "| " << stage << " | " << Fixed(Median(found->second), 1) << " |\n";
  }
  return out.str();
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  using namespace ecv;
  using namespace ecv::bench;
  std::string db, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  int limit = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--db") == 0) db = argv[i + 1];
    if (std::strcmp(argv[i], "--results") == 0) results = argv[i + 1];
    if (std::strcmp(argv[i], "--frames") == 0) limit = std::atoi(argv[i + 1]);
  }
  if (db.empty()) {
    std::cerr << "usage: recognize_bench --db LIB.sqlite [--results FILE] [--frames N]\n"
                 "  (build the library with scripts/build_ycbv_library LIB.sqlite --views 40 --distance 0.9)\n";
    return 2;
  }
  try {
    LibraryLoadOptions load;
    load.build_matchers = false;
    const ModelLibrary library = ModelLibrary::Load(db, load);
    std::vector<EvalModel> models;
    for (const LibraryModel& model : library.models()) models.push_back(EvalModelFromRecord(model.record));
    const std::vector<std::string> frames = YcbvFrames(ECV_DATA_DIR, limit);

    std::map<std::string, Run> runs;
    RecognizerOptions options;
    runs["ECV + RANSAC + ICP"] = RunRecognizer(library, options, frames, models, "icp");
    options.refine = false;
    runs["ECV + RANSAC (no ICP)"] = RunRecognizer(library, options, frames, models, "no icp");

    std::ostringstream markdown;
    markdown << "Library: " << library.models().size() << " textured YCB meshes, " << library.NumViews() << " views (`"
             << db << "`); " << frames.size()
             << " YCB-Video frames (videos 0000-0002). Correct = ADD < 0.1 x diameter; a false positive is a "
                "detection of a model not in the frame or a wrong pose. Models with a colour matrix (applied to "
                "their colours before matching and in verification): "
             << std::count_if(library.models().begin(), library.models().end(),
                              [](const LibraryModel& model) { return model.color_matrix.has_value(); })
             << ".\n\n"
             << RecallTable(runs) << "\nTime per frame, whole library (ECV + RANSAC + ICP):\n\n"
             << TimingTable(runs["ECV + RANSAC + ICP"]);
    Report(results, "Recognition on YCB-Video (recognize_bench)", CommandLine(argc, argv), markdown.str());
  } catch (const std::exception& error) {
    std::cerr << "recognize_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
