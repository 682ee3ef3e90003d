// Descriptor matching as the recognizer does it (issue 9): the context descriptors of each library view (a seeded
// 200-row subset, as view ranking takes) matched into the index over a real YCB-Video frame's descriptors, segments
// against segments and texlets against texlets. ecvpose's KdForest against OpenCV's FLANN (the same randomised
// kd-trees, a row per leaf) in the same run, and OpenCV's brute-force matcher as the exact reference. Quality:
// how often the exact nearest neighbour is found, and the mean ratio of the found distance to the exact one.
//
//   scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9
//   matching_bench --db /tmp/ycbv.sqlite [--frames N] [--results bench/RESULTS.md]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <numeric>
#include <random>
#include <string>

#include <opencv2/features2d.hpp>

#include "bench_util.h"
#include "core/byte_neighbours.h"
#include "core/timing.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "modeldb/model_library.h"
#include "recognize/recognizer.h"
#include "recognize/scene.h"

namespace ecv::bench {
namespace {

constexpr int kRankingRows = 200;

struct Matcher {
  std::string name;
  MatchOptions options;
  bool vnni = true;  // ByteNeighbours may take AVX-512 VNNI where the CPU has it
};

// One matcher's tally over the frames.
struct Tally {
  double build_ms = 0.0, search_ms = 0.0;
  long long queries = 0, exact_found = 0;
  double distance_ratio_sum = 0.0;
};

// The matchers compared: FLANN at the recognizer's former setting and more checks, the KdForest at several.
std::vector<Matcher> Matchers() {
  std::vector<Matcher> matchers;
  auto add = [&](MatchIndex index, int trees, int leaf_size, int checks) {
    Matcher matcher;
    matcher.options = RecognizerOptions::DefaultMatch();
    matcher.options.index = index;
    matcher.options.trees = trees;
    matcher.options.leaf_size = leaf_size;
    matcher.options.checks = checks;
    matcher.name = index == MatchIndex::kFlann
                       ? "OpenCV FLANN, " + std::to_string(trees) + " trees"
                       : "KdForest, " + std::to_string(trees) + " trees, leaves of " + std::to_string(leaf_size);
    matcher.name += ", " + std::to_string(checks) + " checks";
    matchers.push_back(matcher);
  };
  for (const int checks : {32, 64, 128}) add(MatchIndex::kFlann, 4, 1, checks);
  for (const int checks : {32, 64, 128}) add(MatchIndex::kKdForest, 2, 8, checks);
  for (const int checks : {64, 128}) add(MatchIndex::kKdForest, 4, 8, checks);
  // Both of ByteNeighbours' kernels where the CPU has VNNI; the plain loop alone where it has not.
  for (const bool vnni : {true, false}) {
    if (vnni && !ByteNeighbours::CpuHasVnni()) continue;
    Matcher matcher;
    matcher.options = RecognizerOptions::DefaultMatch();
    matcher.options.index = MatchIndex::kBytes;
    matcher.vnni = vnni;
    matcher.name = std::string("ByteNeighbours (every row, 7-bit values), ") + (vnni ? "AVX-512 VNNI" : "plain loop");
    matchers.push_back(matcher);
  }
  return matchers;
}

// A seeded random 200 rows of every library view, as one query set: as many as the ranking takes, though not
// the same rows (the recognizer draws them per view and seed).
std::pair<std::vector<Primitive>, Descriptors> RankingQueries(const ModelLibrary& library) {
  std::vector<Primitive> primitives;
  Descriptors queries;
  std::mt19937_64 random(1);
  for (const LibraryModel& model : library.models()) {
    for (const ModelView& view : model.record.views) {
      std::vector<int> rows(static_cast<size_t>(view.descriptors.values.rows));
      std::iota(rows.begin(), rows.end(), 0);
      std::shuffle(rows.begin(), rows.end(), random);
      rows.resize(std::min(rows.size(), static_cast<size_t>(kRankingRows)));
      for (const int row : rows) {
        queries.values.push_back(view.descriptors.values.row(row));
        queries.primitive.push_back(static_cast<int>(primitives.size()));
        primitives.push_back(
            view.primitives[static_cast<size_t>(view.descriptors.primitive[static_cast<size_t>(row)])]);
      }
    }
  }
  return {primitives, queries};
}

// The scene's primitives and descriptors as the recognizer makes them (its neighbour and descriptor caps).
std::pair<std::vector<Primitive>, Descriptors> SceneDescriptors(const ModelLibrary& library, const RgbdFrame& frame) {
  const FeatureSettings& settings = library.feature_settings();
  std::vector<Primitive> primitives = ExtractPrimitives(frame, settings.ecv).primitives;
  RecognizerOptions options;
  options.threads = 1;
  Descriptors descriptors = ComputeSceneDescriptors(primitives, settings.descriptor, options);
  return {std::move(primitives), std::move(descriptors)};
}

// The exact nearest scene descriptor's distance for each query (OpenCV's brute force, per primitive type), in
// the order DescriptorMatcher lists its matches; and its time.
std::vector<float> ExactDistances(const std::vector<Primitive>& scene, const Descriptors& scene_descriptors,
                                  const std::vector<Primitive>& query, const Descriptors& queries, double* ms) {
  std::vector<float> distances;
  const Clock::time_point start = Clock::now();
  for (const PrimitiveType type : {PrimitiveType::kSegment, PrimitiveType::kTexlet}) {
    cv::Mat train, query_rows;
    for (int row = 0; row < scene_descriptors.values.rows; ++row) {
      if (scene[static_cast<size_t>(scene_descriptors.primitive[static_cast<size_t>(row)])].type == type) {
        train.push_back(scene_descriptors.values.row(row));
      }
    }
    for (int row = 0; row < queries.values.rows; ++row) {
      if (query[static_cast<size_t>(queries.primitive[static_cast<size_t>(row)])].type == type) {
        query_rows.push_back(queries.values.row(row));
      }
    }
    if (train.empty() || query_rows.empty()) continue;
    std::vector<cv::DMatch> matches;
    cv::BFMatcher(cv::NORM_L2).match(query_rows, train, matches);
    for (const cv::DMatch& match : matches) distances.push_back(match.distance);
  }
  *ms += MillisecondsSince(start);
  return distances;
}

// Builds `matcher` over the scene, matches the queries, and adds time and quality against `exact` to `tally`.
void Measure(const Matcher& matcher, const std::vector<Primitive>& scene, const Descriptors& scene_descriptors,
             const std::vector<Primitive>& query, const Descriptors& queries, const std::vector<float>& exact,
             Tally* tally) {
  Clock::time_point start = Clock::now();
  const DescriptorMatcher index(scene, scene_descriptors, matcher.options);
  tally->build_ms += MillisecondsSince(start);
  ByteNeighbours::AllowVnni(matcher.vnni);
  start = Clock::now();
  const std::vector<DescriptorMatch> matches = index.Match(query, queries);
  tally->search_ms += MillisecondsSince(start);
  ByteNeighbours::AllowVnni(true);
  if (matches.size() != exact.size()) throw std::logic_error(matcher.name + ": not one match per query");
  // The float distance to the row found (ByteNeighbours reports the quantised one). A query's row is its
  // primitive's index (RankingQueries); a scene primitive's row is looked up.
  std::vector<int> scene_row(scene.size(), -1);
  for (size_t row = 0; row < scene_descriptors.primitive.size(); ++row) {
    scene_row[static_cast<size_t>(scene_descriptors.primitive[row])] = static_cast<int>(row);
  }
  for (size_t i = 0; i < matches.size(); ++i) {
    ++tally->queries;
    const float distance = static_cast<float>(
        cv::norm(queries.values.row(matches[i].query),
                 scene_descriptors.values.row(scene_row[static_cast<size_t>(matches[i].train)]), cv::NORM_L2));
    // Float sums in another order: equal within a relative 1e-5.
    tally->exact_found += distance <= exact[i] * (1.0F + 1e-5F) ? 1 : 0;
    tally->distance_ratio_sum += exact[i] > 0.0F ? distance / exact[i] : 1.0;
  }
}

std::string Table(const std::vector<Matcher>& matchers, const std::vector<Tally>& tallies, const Tally& exact,
                  int frames) {
  const double reference_us = 1000.0 * tallies[0].search_ms / static_cast<double>(tallies[0].queries);
  std::string table =
      "| matcher | index build, ms per frame | search, us per query | time / FLANN's at 32 checks | exact neighbour "
      "found | distance / exact, mean |\n|---|---:|---:|---:|---:|---:|\n";
  const double exact_us = 1000.0 * exact.search_ms / static_cast<double>(tallies[0].queries);
  table += "| OpenCV BFMatcher (exact) | - | " + Fixed(exact_us, 2) + " | " + Fixed(exact_us / reference_us, 2) +
           " | 100 % | 1.000 |\n";
  for (size_t m = 0; m < matchers.size(); ++m) {
    const Tally& tally = tallies[m];
    const double us = 1000.0 * tally.search_ms / static_cast<double>(tally.queries);
    table += "| " + matchers[m].name + " | " + Fixed(tally.build_ms / frames, 1) + " | " + Fixed(us, 2) + " | " +
             Fixed(us / reference_us, 2) + " | " +
             Fixed(100.0 * static_cast<double>(tally.exact_found) / static_cast<double>(tally.queries), 1) + " % | " +
             Fixed(tally.distance_ratio_sum / static_cast<double>(tally.queries), 3) + " |\n";
  }
  return table;
}

struct Settings {
  std::string db;
  int frames = 30;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
};

std::string Run(const Settings& settings) {
  const ModelLibrary library = ModelLibrary::Load(settings.db);
  const auto [query, queries] = RankingQueries(library);
  const std::vector<Matcher> matchers = Matchers();
  std::vector<Tally> tallies(matchers.size());
  Tally exact;
  std::vector<std::string> prefixes = YcbvFramePrefixes(ECV_DATA_DIR);
  // Every k-th frame when fewer are asked for, so that all three videos are in.
  const size_t step = std::max<size_t>(1, prefixes.size() / static_cast<size_t>(settings.frames));
  int frames = 0;
  for (size_t f = 0; f < prefixes.size() && frames < settings.frames; f += step) {
    const auto [scene, scene_descriptors] = SceneDescriptors(library, LoadYcbvFrame(prefixes[f]).rgbd);
    const std::vector<float> exact_distances =
        ExactDistances(scene, scene_descriptors, query, queries, &exact.search_ms);
    for (size_t m = 0; m < matchers.size(); ++m) {
      Measure(matchers[m], scene, scene_descriptors, query, queries, exact_distances, &tallies[m]);
    }
    std::cerr << "\rframe " << ++frames << "/" << settings.frames << std::flush;
  }
  std::cerr << '\n';
  std::string markdown = "Library `" + settings.db + "` (" + std::to_string(library.models().size()) + " models, " +
                         std::to_string(library.NumViews()) + " views; " + std::to_string(queries.values.rows) +
                         " queries: up to " + std::to_string(kRankingRows) + " descriptors of each view), " +
                         std::to_string(frames) +
                         " YCB-Video frames, one thread. The recognizer's exact_below (100) applies: a frame's "
                         "segments and texlets are each searched approximately. Exact neighbour found: the float "
                         "distance to the row found equals the brute-force one.\n\n";
  return markdown + Table(matchers, tallies, exact, frames);
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  ecv::bench::Settings settings;
  CLI::App app{
      "matching_bench: descriptor matching as the recognizer does it, library views into a real frame: "
      "ecvpose's KdForest and ByteNeighbours against OpenCV's FLANN and brute force (time, exact "
      "neighbours found).",
      "matching_bench"};
  app.add_option("--db", settings.db, "Model library whose views are matched")->required();
  app.add_option("--frames", settings.frames, "YCB-Video frames, spread over the three videos")
      ->check(ecv::bench::AtLeastOne())
      ->capture_default_str();
  app.add_option("--results", settings.results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.footer("Library:\n  scripts/build_ycbv_library /tmp/ycbv.sqlite --views 40 --distance 0.9");
  if (const auto exit_code = ecv::bench::ParseCommandLine(app, argc, argv)) return *exit_code;
  try {
    const std::string table = ecv::bench::Run(settings);
    ecv::bench::ReportSection(settings.results, "Descriptor matching: KdForest and FLANN (matching_bench)",
                              ecv::bench::CommandLine(argc, argv), table);
  } catch (const std::exception& error) {
    std::cerr << "matching_bench: " << error.what() << '\n';
    return 1;
  }
  return 0;
}
