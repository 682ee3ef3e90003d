// Model pre-selection (issue 69): does ranking every model by its best view in a quick ranking (recognize --preselect
// N: 100 descriptors a view, 32 checks; --rows 200 --checks 0 is the search's own ranking) put the models that are
// in a frame among the N the recognizer then searches? On the 30 YCB-Video frames, each present object's rank among the
// library's models, with libraries of growing size: distractors that outrank present objects are what a larger library
// costs. No RANSAC, no verification: a ranking change is judged here in minutes before the end-to-end runs of
// recognize_bench.
//
//   scripts/build_ycb_library /tmp/ycb16.sqlite --objects ycbv16 --views 40 --distance 0.9
//   scripts/build_ycb_library /tmp/ycb78.sqlite --views 40 --distance 0.9
//   preselect_bench --db /tmp/ycb16.sqlite --db /tmp/ycb78.sqlite [--rows N] [--checks N] [--csv ranks.csv]
//                   [--results bench/RESULTS.md]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "bench_util.h"
#include "core/timing.h"
#include "io/frame_io.h"
#include "modeldb/model_library.h"
#include "recognize/recognizer.h"

namespace ecv::bench {
namespace {

const std::vector<int> kShortLists = {4, 8, 12, 16, 24};

// Each present object's rank in one library (0: first), by object and by video; the ranking's time per frame.
struct LibraryRun {
  std::string name;
  int models = 0;
  std::map<std::string, std::vector<int>> ranks;  // by object
  std::map<std::string, std::vector<int>> video_ranks;
  std::vector<double> ms;
};

// Models in the order Preselect keeps them: larger best view score, then library order.
std::vector<std::string> Ranked(const std::map<std::string, int>& best, const std::vector<std::string>& library_order) {
  std::vector<std::string> order = library_order;
  std::stable_sort(order.begin(), order.end(),
                   [&](const std::string& a, const std::string& b) { return best.at(a) > best.at(b); });
  return order;
}

// Each model's view scores (RankedView::score, its ranking's consistent set), best first.
std::map<std::string, std::vector<int>> ViewScores(Recognizer* recognizer, const RgbdFrame& frame) {
  std::map<std::string, std::vector<int>> scores;
  for (const auto& [model, views] : recognizer->RankViews(frame)) {
    std::vector<int>& model_scores = scores[model];
    for (const RankedView& view : views) model_scores.push_back(view.score);
  }
  return scores;
}

LibraryRun Run(const std::string& db, const RecognizerOptions& options, const std::vector<LoadedFrame>& frames,
               std::ofstream* csv) {
  const ModelLibrary library = ModelLibrary::Load(db);
  Recognizer recognizer(library, options);
  LibraryRun run;
  run.name = db.substr(db.find_last_of('/') + 1);
  run.models = static_cast<int>(library.models().size());
  std::vector<std::string> names;
  for (const LibraryModel& model : library.models()) names.push_back(model.record.name);
  for (const LoadedFrame& frame : frames) {
    const Clock::time_point start = Clock::now();
    const std::map<std::string, std::vector<int>> all = ViewScores(&recognizer, frame.rgbd);
    run.ms.push_back(MillisecondsSince(start));
    std::map<std::string, int> evidence;  // each model's best view score
    for (const auto& [model, scores] : all) evidence[model] = scores.empty() ? 0 : scores.front();
    const std::vector<std::string> order = Ranked(evidence, names);
    std::string video = std::to_string(frame.scene_id);
    video.insert(0, 4 - std::min<size_t>(4, video.size()), '0');
    std::map<std::string, bool> present;
    for (const GroundTruth& truth : frame.ground_truth) {
      const auto found = std::find(order.begin(), order.end(), truth.object_name);
      if (found == order.end()) continue;
      const auto rank = static_cast<int>(found - order.begin());
      run.ranks[truth.object_name].push_back(rank);
      run.video_ranks[video].push_back(rank);
      present[truth.object_name] = true;
    }
    if (csv != nullptr && csv->is_open()) {
      for (size_t r = 0; r < order.size(); ++r) {
        *csv << run.name << "," << frame.rgbd.name << "," << order[r] << "," << (present[order[r]] ? 1 : 0) << "," << r
             << "," << evidence.at(order[r]);
        for (const int score : all.at(order[r])) *csv << "," << score;
        *csv << "\n";
      }
    }
    std::cerr << "preselect_bench: " << run.name << " " << frame.rgbd.name << " " << Fixed(run.ms.back(), 0) << " ms\n";
  }
  return run;
}

// "found in the first N" cells of one row of ranks.
std::string ShortListCells(const std::vector<int>& ranks) {
  std::ostringstream cells;
  for (const int n : kShortLists) {
    cells << " | " << std::count_if(ranks.begin(), ranks.end(), [n](int rank) { return rank < n; });
  }
  return cells.str();
}

std::string Table(const std::vector<LibraryRun>& runs) {
  std::ostringstream table;
  table << "| library | object | present | median rank";
  for (const int n : kShortLists) table << " | in the first " << n;
  table << " |\n|---|---|---:|---:";
  for (size_t i = 0; i < kShortLists.size(); ++i) table << "|---:";
  table << "|\n";
  for (const LibraryRun& run : runs) {
    std::vector<int> all;
    const auto row = [&](const std::string& label, const std::vector<int>& ranks, bool bold) {
      std::vector<double> values(ranks.begin(), ranks.end());
      const std::string b = bold ? "**" : "";
      table << "| " << b << run.name << " (" << run.models << ")" << b << " | " << b << label << b << " | "
            << ranks.size() << " | " << Fixed(Median(values), 0) << ShortListCells(ranks) << " |\n";
    };
    for (const auto& [object, ranks] : run.ranks) {
      row(object, ranks, false);
      all.insert(all.end(), ranks.begin(), ranks.end());
    }
    for (const auto& [video, ranks] : run.video_ranks) row("video " + video, ranks, false);
    row("all", all, true);
  }
  return table.str();
}

int Main(int argc, char** argv) {
  std::vector<std::string> dbs;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md", csv_path;
  RecognizerOptions options;
  options.threads = 2;
  // The quick ranking of Preselect unless --rows and --checks say otherwise (200 and 0: the search's own).
  options.ranking.max_correspondences = options.preselect.rows;
  options.ranking.checks = options.preselect.checks;
  CLI::App app{
      "preselect_bench: the model pre-selection against the ground truth: where does it rank the models in "
      "the frame? No RANSAC, no verification.",
      "preselect_bench"};
  app.add_option("--db", dbs, "Model libraries, smallest first")->required();
  app.add_option("--threads", options.threads, "Threads")->capture_default_str();
  app.add_option("--rows", options.ranking.max_correspondences, "Descriptors of each view ranked")
      ->capture_default_str();
  app.add_option("--checks", options.ranking.checks, "Descriptors compared per ranking query (0: matching's)")
      ->capture_default_str();
  app.add_option("--csv", csv_path,
                 "Also write every model's rank per frame (library, frame, model, present, rank, "
                 "best view score)");
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  std::vector<LoadedFrame> frames;
  for (const std::string& prefix : YcbvFramePrefixes(ECV_DATA_DIR)) frames.push_back(LoadYcbvFrame(prefix));
  std::ofstream csv;
  if (!csv_path.empty()) {
    csv.open(csv_path);
    csv << "library,frame,model,present,rank,consistent\n";
  }
  std::vector<LibraryRun> runs;
  for (const std::string& db : dbs) runs.push_back(Run(db, options, frames, &csv));
  std::ostringstream markdown;
  markdown << "The " << frames.size() << " YCB-Video frames; " << options.threads << " threads, seed "
           << options.ransac.seed
           << ". Each model ranked by its best view's score (the consistent set of its ranking correspondences: "
           << options.ranking.max_correspondences << " descriptors a view, " << options.RankingChecks()
           << " checks per query; `recognize --preselect N`: " << RecognizerOptions().preselect.rows << " and "
           << RecognizerOptions().preselect.checks
           << "); rank 0 is first; \"in the first N\": present objects that it would search.\n\n"
           << Table(runs) << "\nRanking time per frame (describing the scene, ranking every view), median ms:";
  for (const LibraryRun& run : runs) markdown << " " << run.name << " " << Fixed(Median(run.ms), 0) << ";";
  markdown << "\n";
  ReportSection(results, "Model pre-selection (preselect_bench)", CommandLine(argc, argv), markdown.str());
  return 0;
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  try {
    return ecv::bench::Main(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << "preselect_bench: " << error.what() << "\n";
    return 1;
  }
}
