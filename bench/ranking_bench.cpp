// View ranking (issue 9): do the views the recognizer tries first hold right correspondences? Each library view
// of each model is ranked as Recognize ranks it (Recognizer::RankViews: ConsistentSetSize of the nearest scene
// descriptor of 200 of the view's descriptors), on the 30 YCB-Video frames. A ranking correspondence is right
// when the ground-truth pose puts its view primitive within 1.5 cm of its scene primitive; a view is good with 6
// or more right ones (RANSAC then has a chance). Also: the consistent set the ranking could find among the right
// correspondences alone, and the scores of models that are not in the frame (the noise the right view must
// stand out of). No RANSAC, no verification: a ranking change is judged here in a minute before the
// end-to-end runs of recognize_bench. With --lmo, the LM-O frame of recognize_bench instead (its library).
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   ranking_bench --db /tmp/ycbv.sqlite [--seed 1] [--ranking-checks N] [--results bench/RESULTS.md]
//   scripts/build_lmo_library /tmp/lmo.sqlite --views 40 --distance 1.0
//   ranking_bench --db /tmp/lmo.sqlite --lmo

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "bench_util.h"
#include "core/timing.h"
#include "io/frame_io.h"
#include "modeldb/model_library.h"
#include "recognize/recognizer.h"
#include "recognize/scoring.h"

namespace ecv::bench {
namespace {

constexpr float kRightM = 0.015F;  // as RANSAC's 1 cm inlier threshold plus the ground truth's own error
constexpr int kGoodView = 6;

// One view of a present object, judged against the ground truth.
struct JudgedView {
  int rank = 0;
  int score = 0;
  int right = 0;         // right ranking correspondences
  int right_clique = 0;  // ConsistentSetSize over the right ones alone
};

JudgedView Judge(const RankedView& view, int rank, const Eigen::Isometry3f& camera_from_object,
                 const ConsistencyOptions& consistency) {
  JudgedView judged{rank, view.score, 0, 0};
  std::vector<Primitive> object, scene;
  for (const auto& [object_primitive, scene_primitive] : view.correspondences) {
    if ((camera_from_object * object_primitive.position - scene_primitive.position).norm() >= kRightM) continue;
    object.push_back(object_primitive);
    scene.push_back(scene_primitive);
  }
  judged.right = static_cast<int>(object.size());
  std::vector<Correspondence> pairs(object.size());
  for (size_t i = 0; i < pairs.size(); ++i) pairs[i] = {static_cast<int>(i), static_cast<int>(i)};
  judged.right_clique = ConsistentSetSize(object, scene, pairs, consistency);
  return judged;
}

// What ranking did for one model over the frames where it is present.
struct ModelTally {
  int objects = 0, with_good_view = 0, good_first = 0, good_tried = 0;
  std::vector<double> most_right, clique_of_most_right, top_score, best_good_score, absent_top_score;
};

// The 30 YCB-Video frames, or the LM-O frame of recognize_bench.
std::vector<LoadedFrame> Frames(bool lmo) {
  if (lmo) return {LmoFrame(ECV_DATA_DIR)};
  std::vector<LoadedFrame> frames;
  for (const std::string& prefix : YcbvFramePrefixes(ECV_DATA_DIR)) frames.push_back(LoadYcbvFrame(prefix));
  return frames;
}

std::string Run(const ModelLibrary& library, const RecognizerOptions& options, const std::vector<LoadedFrame>& frames,
                std::vector<double>* ms) {
  Recognizer recognizer(library, options);
  std::map<std::string, ModelTally> tallies;
  std::map<std::string, double> diameters;
  for (const LibraryModel& model : library.models()) diameters[model.record.name] = model.record.diameter_m;
  for (const LoadedFrame& frame : frames) {
    const Clock::time_point start = Clock::now();
    const std::map<std::string, std::vector<RankedView>> ranked = recognizer.RankViews(frame.rgbd);
    ms->push_back(MillisecondsSince(start));
    std::set<std::string> present;
    for (const GroundTruth& truth : frame.ground_truth) {
      const auto views = ranked.find(truth.object_name);
      if (views == ranked.end()) continue;
      present.insert(truth.object_name);
      ModelTally& tally = tallies[truth.object_name];
      ConsistencyOptions consistency = options.ranking.consistency;
      consistency.max_distance_m = diameters[truth.object_name];
      std::vector<JudgedView> judged;
      for (size_t rank = 0; rank < views->second.size(); ++rank) {
        judged.push_back(
            Judge(views->second[rank], static_cast<int>(rank), truth.camera_from_object.cast<float>(), consistency));
      }
      ++tally.objects;
      if (judged.empty()) continue;
      const auto most = std::max_element(judged.begin(), judged.end(),
                                         [](const JudgedView& a, const JudgedView& b) { return a.right < b.right; });
      tally.most_right.push_back(most->right);
      tally.clique_of_most_right.push_back(most->right_clique);
      tally.top_score.push_back(judged.front().score);
      const auto good =
          std::find_if(judged.begin(), judged.end(), [](const JudgedView& view) { return view.right >= kGoodView; });
      if (good == judged.end()) continue;
      ++tally.with_good_view;
      tally.good_first += good->rank == 0 ? 1 : 0;
      tally.good_tried += good->rank < options.views_per_model ? 1 : 0;
      tally.best_good_score.push_back(good->score);
    }
    for (const auto& [name, views] : ranked) {
      if (present.count(name) == 0 && !views.empty()) tallies[name].absent_top_score.push_back(views.front().score);
    }
    std::cerr << "ranking_bench: " << frame.rgbd.name << "\n";
  }

  std::ostringstream table;
  table << "| model | objects | with a good view | good view ranked first | good view among the first "
        << options.views_per_model
        << " | most right, median | their consistent set, median | top score, median | best good view's score, "
           "median | top score where absent, median |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  auto median = [](const std::vector<double>& values) { return values.empty() ? "-" : Fixed(Median(values), 0); };
  ModelTally all;
  for (const auto& [name, tally] : tallies) {
    table << "| " << name << " | " << tally.objects << " | " << tally.with_good_view << " | " << tally.good_first
          << " | " << tally.good_tried << " | " << median(tally.most_right) << " | "
          << median(tally.clique_of_most_right) << " | " << median(tally.top_score) << " | "
          << median(tally.best_good_score) << " | " << median(tally.absent_top_score) << " |\n";
    all.objects += tally.objects;
    all.with_good_view += tally.with_good_view;
    all.good_first += tally.good_first;
    all.good_tried += tally.good_tried;
  }
  table << "| **all** | **" << all.objects << "** | **" << all.with_good_view << "** | **" << all.good_first
        << "** | **" << all.good_tried << "** | | | | | |\n";
  return table.str();
}

int Main(int argc, char** argv) {
  std::string db, results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  RecognizerOptions options;
  options.threads = 1;
  bool lmo = false;
  CLI::App app{
      "ranking_bench: view ranking against the ground truth: do the library views the recognizer tries "
      "first hold right correspondences? No RANSAC, no verification.",
      "ranking_bench"};
  app.add_option("--db", db, "Model library: the 7 YCB-Video models, or with --lmo the LM-O models")->required();
  app.add_flag("--lmo", lmo, "Rank on the LM-O frame instead of the 30 YCB-Video frames");
  app.add_option("--seed", options.ransac.seed, "Seed that picks each view's ranking descriptors")
      ->capture_default_str();
  app.add_option("--ranking-checks", options.ranking.checks,
                 "Descriptors compared per query when ranking (0: as many as matching)")
      ->capture_default_str();
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.footer(
      "Libraries:\n  scripts/build_ycbv_library YCBV_LIB.sqlite --views 40 --distance 0.9\n"
      "  scripts/build_lmo_library LMO_LIB.sqlite --views 40 --distance 1.0 (with --lmo)");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  const ModelLibrary library = ModelLibrary::Load(db);
  std::vector<double> ms;
  const std::string table = Run(library, options, Frames(lmo), &ms);
  std::ostringstream markdown;
  markdown << "Library `" << db << "` (" << library.models().size() << " models), the " << ms.size()
           << (lmo ? " LM-O frame (scene 000002, image 3)" : " YCB-Video frames") << ", seed " << options.ransac.seed
           << " (it picks each view's " << options.ranking.max_correspondences << " ranking descriptors, "
           << options.ranking.checks << " checks per query; 0: as matching, " << options.match.checks
           << "), one thread. Right = the ground truth puts the view primitive within " << kRightM * 100.0F
           << " cm of its scene primitive; good view = " << kGoodView
           << " or more right. Score = the ranking's consistent-set size. Median ms per frame for describing the "
              "scene and ranking every view: "
           << Fixed(Median(ms), 0) << ".\n\n"
           << table;
  ReportSection(results, lmo ? "View ranking on LM-O (ranking_bench)" : "View ranking on YCB-Video (ranking_bench)",
                CommandLine(argc, argv), markdown.str());
  return 0;
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  try {
    return ecv::bench::Main(argc, argv);
  } catch (const std::exception& error) {
    std::cerr << "ranking_bench: " << error.what() << "\n";
    return 1;
  }
}
