// discriminative_bench: the paper's Fig. 7 on real data. For view pairs with known relative pose, the
// fraction of nearest-neighbour descriptor matches whose points lie within 1 cm after alignment
// (Sect. IV-A), for the ECV context descriptor and peers on exactly the same pairs, with the score of
// random matching and the ceiling. Also the ablations that set the descriptor's defaults, a bar chart and
// a picture of matches. Writes to bench/RESULTS.md and bench/figures/.
//
//   discriminative_bench [--results FILE] [--figures DIR] [--ablations-only] [--variants TEXT]
//                        [--library-distance M] [--headlight]

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <stdexcept>
#include <tuple>

#include <opencv2/imgcodecs.hpp>

#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_util.h"
#include "core/timing.h"
#include "discriminative_data.h"
#include "ecv/matching.h"
#include "io/frame_io.h"
#include "peer_descriptors.h"
#include "peer_descriptors_cv.h"

namespace ecv::bench {
namespace {

constexpr double kTrueMatch = 0.01;  // metres

struct PairScore {
  double score = 0.0, random = 0.0, ceiling = 0.0;
  int hypotheses = 0;
  double describe_ms = 0.0;  // ECV only: both views' descriptors
};

// Expected score of matching at random and the ceiling (share with any true partner within 1 cm) of
// `query` positions against `train` positions after alignment: {random, ceiling}.
std::pair<double, double> ChanceAndCeiling(const std::vector<Eigen::Vector3f>& query,
                                           const std::vector<Eigen::Vector3f>& train,
                                           const Eigen::Isometry3d& train_from_query) {
  if (query.empty() || train.empty()) return {0.0, 0.0};
  const Eigen::Isometry3f transform = train_from_query.cast<float>();
  const float squared = static_cast<float>(kTrueMatch * kTrueMatch);
  double random = 0.0;
  int with_partner = 0;
  for (const Eigen::Vector3f& point : query) {
    const Eigen::Vector3f moved = transform * point;
    int partners = 0;
    for (const Eigen::Vector3f& other : train) partners += (moved - other).squaredNorm() < squared ? 1 : 0;
    with_partner += partners > 0 ? 1 : 0;
    random += static_cast<double>(partners) / static_cast<double>(train.size());
  }
  const double n = static_cast<double>(query.size());
  return {random / n, with_partner / n};
}

// Nearest-neighbour matching (exact) of valid rows and the paper's score, with random and ceiling.
PairScore ScoreKeypoints(const KeypointDescriptors& query, const KeypointDescriptors& train,
                         const Eigen::Isometry3d& train_from_query) {
  PairScore result;
  std::vector<int> query_rows, train_rows;
  for (size_t i = 0; i < query.valid.size(); ++i) {
    if (query.valid[i]) query_rows.push_back(static_cast<int>(i));
  }
  for (size_t i = 0; i < train.valid.size(); ++i) {
    if (train.valid[i]) train_rows.push_back(static_cast<int>(i));
  }
  if (query_rows.empty() || train_rows.empty()) return result;
  cv::Mat query_values(static_cast<int>(query_rows.size()), query.values.cols, query.values.type());
  cv::Mat train_values(static_cast<int>(train_rows.size()), train.values.cols, train.values.type());
  for (size_t i = 0; i < query_rows.size(); ++i)
    query.values.row(query_rows[i]).copyTo(query_values.row(static_cast<int>(i)));
  for (size_t i = 0; i < train_rows.size(); ++i)
    train.values.row(train_rows[i]).copyTo(train_values.row(static_cast<int>(i)));
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(query.binary ? cv::NORM_HAMMING : cv::NORM_L2).match(query_values, train_values, matches);

  const Eigen::Isometry3f transform = train_from_query.cast<float>();
  const float squared = static_cast<float>(kTrueMatch * kTrueMatch);
  int true_matches = 0;
  for (const cv::DMatch& match : matches) {
    const Eigen::Vector3f moved =
        transform * query.positions[static_cast<size_t>(query_rows[static_cast<size_t>(match.queryIdx)])];
    const Eigen::Vector3f& matched =
        train.positions[static_cast<size_t>(train_rows[static_cast<size_t>(match.trainIdx)])];
    true_matches += (moved - matched).squaredNorm() < squared ? 1 : 0;
  }
  result.hypotheses = static_cast<int>(matches.size());
  result.score = true_matches / static_cast<double>(matches.size());
  std::vector<Eigen::Vector3f> query_positions, train_positions;
  for (const int q : query_rows) query_positions.push_back(query.positions[static_cast<size_t>(q)]);
  for (const int t : train_rows) train_positions.push_back(train.positions[static_cast<size_t>(t)]);
  std::tie(result.random, result.ceiling) = ChanceAndCeiling(query_positions, train_positions, train_from_query);
  return result;
}

// The extracted primitives of both views of a pair (cached: every method uses the same keypoints): those
// on the object's pixels, or every one of the train frame for a cluttered pair.
struct PairPrimitives {
  std::vector<Primitive> query, train;
};

PairPrimitives Extract(const ViewPair& pair, const EcvOptions& options) {
  return {ExtractPrimitives(pair.query.rgbd, options, pair.query.mask).primitives,
          ExtractPrimitives(pair.train.rgbd, options, pair.clutter ? cv::Mat() : pair.train.mask).primitives};
}

// The pixels a peer's train keypoints and descriptors draw on: the object's, or the whole frame for a cluttered
// pair.
cv::Mat TrainSupport(const ViewPair& pair) {
  return pair.clutter ? cv::Mat(pair.train.mask.size(), CV_8UC1, cv::Scalar(255)) : pair.train.mask;
}

// ECV context descriptors matched with ecvpose's own matcher.
PairScore ScoreEcv(const ViewPair& pair, const PairPrimitives& primitives, const DescriptorOptions& descriptor,
                   const MatchOptions& matching) {
  const Clock::time_point start = Clock::now();
  // The surface context's support: the pixels the peers use.
  const SurfaceSamples query_surface = DescriptorSurface(pair.query.rgbd, descriptor, pair.query.mask);
  const SurfaceSamples train_surface = DescriptorSurface(pair.train.rgbd, descriptor, TrainSupport(pair));
  const Descriptors query = ComputeDescriptors(primitives.query, descriptor, 1, 1, &query_surface);
  const Descriptors train = ComputeDescriptors(primitives.train, descriptor, 1, 1, &train_surface);
  PairScore result;
  result.describe_ms = MillisecondsSince(start);
  if (query.primitive.empty() || train.primitive.empty()) return result;
  const DescriptorMatcher matcher(primitives.train, train, matching);
  const CorrespondenceScore score = ScoreCorrespondences(
      primitives.query, primitives.train, matcher.Match(primitives.query, query), pair.TrainFromQuery(), kTrueMatch);
  result.score = score.Score();
  result.hypotheses = score.hypotheses;
  // Random and ceiling over the described primitives (the same keypoints as the peers at ECV keypoints).
  std::vector<Eigen::Vector3f> query_positions, train_positions;
  for (const int i : query.primitive) query_positions.push_back(primitives.query[static_cast<size_t>(i)].position);
  for (const int i : train.primitive) train_positions.push_back(primitives.train[static_cast<size_t>(i)].position);
  std::tie(result.random, result.ceiling) = ChanceAndCeiling(query_positions, train_positions, pair.TrainFromQuery());
  return result;
}

std::vector<Eigen::Vector3f> Positions(const std::vector<Primitive>& primitives) {
  std::vector<Eigen::Vector3f> positions;
  for (const Primitive& p : primitives) positions.push_back(p.position);
  return positions;
}

using Method = std::function<PairScore(const ViewPair&, const PairPrimitives&)>;

std::vector<std::pair<std::string, Method>> Methods() {
  std::vector<std::pair<std::string, Method>> methods;
  methods.emplace_back("ECV context, all pairs, r 2.5 cm",
                       [](const ViewPair& pair, const PairPrimitives& p) { return ScoreEcv(pair, p, {}, {}); });
  methods.emplace_back("ECV source pairs, 4 shells, r 4.5 cm (library default)",
                       [](const ViewPair& pair, const PairPrimitives& p) {
                         return ScoreEcv(pair, p, DescriptorOptions::SourceShells(), {});
                       });
  methods.emplace_back("ECV surface context, 4 shells, r 4.5 cm, mixed matching",
                       [](const ViewPair& pair, const PairPrimitives& p) {
                         MatchOptions mixed;
                         mixed.structure_specific = false;
                         return ScoreEcv(pair, p, DescriptorOptions::SurfaceShells(), mixed);
                       });
  auto add_pcl = [&](PclDescriptor descriptor, double radius_m, const std::string& suffix) {
    methods.emplace_back(
        std::string(ToString(descriptor)) + " @ECV" + suffix,
        [descriptor, radius_m](const ViewPair& pair, const PairPrimitives& p) {
          return ScoreKeypoints(
              ComputePclDescriptors(pair.query.rgbd, pair.query.mask, Positions(p.query), descriptor, radius_m),
              ComputePclDescriptors(pair.train.rgbd, TrainSupport(pair), Positions(p.train), descriptor, radius_m),
              pair.TrainFromQuery());
        });
  };
  for (const PclDescriptor descriptor :
       {PclDescriptor::kFpfh, PclDescriptor::kShot, PclDescriptor::kShotColor, PclDescriptor::kSpinImage}) {
    add_pcl(descriptor, 0.025, "");
  }
  for (const PclDescriptor descriptor : {PclDescriptor::kFpfh, PclDescriptor::kShot, PclDescriptor::kShotColor})
    add_pcl(descriptor, 0.045, " r 4.5 cm");
  for (const ImageDescriptor descriptor : {ImageDescriptor::kSift, ImageDescriptor::kOrb}) {
    methods.emplace_back(std::string(ToString(descriptor)) + " @ECV",
                         [descriptor](const ViewPair& pair, const PairPrimitives& p) {
                           return ScoreKeypoints(ComputeImageDescriptorsAt(pair.query.rgbd, p.query, descriptor, 24.0F),
                                                 ComputeImageDescriptorsAt(pair.train.rgbd, p.train, descriptor, 24.0F),
                                                 pair.TrainFromQuery());
                         });
    methods.emplace_back(std::string(ToString(descriptor)) + " own keypoints", [descriptor](const ViewPair& pair,
                                                                                            const PairPrimitives&) {
      return ScoreKeypoints(ComputeImageDescriptorsOwn(pair.query.rgbd, pair.query.mask, descriptor),
                            ComputeImageDescriptorsOwn(pair.train.rgbd, TrainSupport(pair), descriptor),
                            pair.TrainFromQuery());
    });
  }
  return methods;
}

std::string Percent(double value) {
  return Fixed(100.0 * value, 1);
}

// Per set: a table with one row per object (mean over its pairs) and one column per method.
std::string SetTable(const std::string& set, const std::vector<ViewPair>& pairs,
                     const std::vector<std::string>& method_names, const std::vector<std::vector<PairScore>>& scores) {
  std::map<std::string, std::vector<size_t>> by_object;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (pairs[i].set == set) by_object[pairs[i].object].push_back(i);
  }
  std::string table = "### Set: " + set + "\n\n| object | pairs |";
  for (const std::string& name : method_names) table += " " + name + " |";
  table += " random (ECV kp) | ceiling (ECV kp) |\n|---|---:|";
  for (size_t m = 0; m < method_names.size() + 2; ++m) table += "---:|";
  table += "\n";
  std::vector<double> mean(method_names.size() + 2, 0.0);
  for (const auto& [object, indices] : by_object) {
    table += "| " + object + " | " + std::to_string(indices.size()) + " |";
    for (size_t m = 0; m < method_names.size() + 2; ++m) {
      double sum = 0.0;
      for (const size_t i : indices) {
        sum += m < method_names.size()    ? scores[i][m].score
               : m == method_names.size() ? scores[i][0].random
                                          : scores[i][0].ceiling;
      }
      table += " " + Percent(sum / static_cast<double>(indices.size())) + " |";
      mean[m] += sum / static_cast<double>(indices.size()) / static_cast<double>(by_object.size());
    }
    table += "\n";
  }
  table += "| **mean** | |";
  for (const double value : mean) table += " **" + Percent(value) + "** |";
  return table + "\n\n";
}

// Writes a BGR image; a path that cannot be written ends the run with its name (cv::imwrite only returns false).
void WriteImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image, {cv::IMWRITE_JPEG_QUALITY, 85})) {
    throw std::runtime_error("discriminative_bench: cannot write the figure " + path);
  }
}

// Bar chart of the mean score per method and set, random matching as a grey tick (BGR image for imwrite).
// ECV's variants in reds, the peers in blue-green to ochre (BGR).
cv::Scalar MethodColor(const std::string& name, size_t index) {
  if (name.rfind("ECV", 0) == 0) return index == 0 ? cv::Scalar(60, 60, 160) : cv::Scalar(40, 40, 230);
  return {170 - 10.0 * static_cast<double>(index), 140, 60 + 12.0 * static_cast<double>(index)};
}

cv::Mat BarChart(const std::vector<ViewPair>& pairs, const std::vector<std::string>& names,
                 const std::vector<std::vector<PairScore>>& scores) {
  const std::vector<std::string>& sets = kPairSets;
  const int bar = 14, gap = 30, height = 300, top = 40, left = 50;
  const int group = static_cast<int>(names.size()) * bar;
  const int legend = 40 + 14 * static_cast<int>(names.size());
  cv::Mat canvas(top + height + legend, left + static_cast<int>(sets.size()) * (group + gap) + 20, CV_8UC3,
                 cv::Scalar::all(255));
  for (int percent = 0; percent <= 100; percent += 20) {
    const int y = top + height - height * percent / 100;
    cv::line(canvas, {left - 5, y}, {canvas.cols - 10, y}, cv::Scalar::all(225));
    cv::putText(canvas, std::to_string(percent) + "%", {5, y + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(80));
  }
  for (size_t s = 0; s < sets.size(); ++s) {
    const int x0 = left + static_cast<int>(s) * (group + gap);
    for (size_t m = 0; m < names.size(); ++m) {
      double sum = 0.0, random = 0.0;
      int count = 0;
      for (size_t i = 0; i < pairs.size(); ++i) {
        if (pairs[i].set != sets[s]) continue;
        sum += scores[i][m].score;
        random += scores[i][m].random;
        ++count;
      }
      const double mean = count > 0 ? sum / count : 0.0;
      const int x = x0 + static_cast<int>(m) * bar;
      const cv::Scalar color = MethodColor(names[m], m);
      cv::rectangle(canvas, {x + 1, top + height - static_cast<int>(height * mean)}, {x + bar - 2, top + height}, color,
                    cv::FILLED);
      const int random_y = top + height - static_cast<int>(height * (count > 0 ? random / count : 0.0));
      cv::line(canvas, {x, random_y}, {x + bar - 1, random_y}, cv::Scalar::all(60), 2);
    }
    cv::putText(canvas, sets[s], {x0, top + height + 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar::all(0));
  }
  for (size_t m = 0; m < names.size(); ++m) {
    const cv::Scalar color = MethodColor(names[m], m);
    const int y = top + height + 40 + static_cast<int>(m) * 14;
    cv::rectangle(canvas, {left, y - 9}, {left + 10, y}, color, cv::FILLED);
    cv::putText(canvas, names[m], {left + 16, y}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(0));
  }
  cv::putText(canvas, "True NN matches within 1 cm (grey: random)", {left, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar::all(0));
  return canvas;
}

// The paper's Fig. 6: 25 random ECV matches of one pair, green when true, red when false (BGR image).
cv::Mat MatchPicture(const ViewPair& pair, const PairPrimitives& primitives) {
  const DescriptorOptions options = DescriptorOptions::SourceShells();  // the library default
  const Descriptors query = ComputeDescriptors(primitives.query, options);
  const Descriptors train = ComputeDescriptors(primitives.train, options);
  const DescriptorMatcher matcher(primitives.train, train);
  std::vector<DescriptorMatch> matches = matcher.Match(primitives.query, query);
  std::mt19937 random(5);
  std::shuffle(matches.begin(), matches.end(), random);
  cv::Mat left, right, canvas;
  cv::cvtColor(pair.query.rgbd.color, left, cv::COLOR_RGB2BGR);
  cv::cvtColor(pair.train.rgbd.color, right, cv::COLOR_RGB2BGR);
  cv::hconcat(left, right, canvas);
  const Eigen::Isometry3f train_from_query = pair.TrainFromQuery().cast<float>();
  for (size_t k = 0; k < std::min<size_t>(25, matches.size()); ++k) {
    const Primitive& q = primitives.query[static_cast<size_t>(matches[k].query)];
    const Primitive& t = primitives.train[static_cast<size_t>(matches[k].train)];
    const bool correct = (train_from_query * q.position - t.position).norm() < kTrueMatch;
    const cv::Scalar color = correct ? cv::Scalar(60, 220, 60) : cv::Scalar(40, 40, 230);
    const cv::Point a(cvRound(q.pixel.x()), cvRound(q.pixel.y()));
    const cv::Point b(cvRound(t.pixel.x()) + left.cols, cvRound(t.pixel.y()));
    cv::line(canvas, a, b, color, 1, cv::LINE_AA);
    cv::circle(canvas, a, 3, color, cv::FILLED, cv::LINE_AA);
    cv::circle(canvas, b, 3, color, cv::FILLED, cv::LINE_AA);
  }
  cv::putText(canvas, pair.object + ": " + pair.query.name + " (left) vs real " + pair.train.name + "; green = true",
              {10, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar::all(255), 1, cv::LINE_AA);
  return canvas;
}

// One ECV variant of the ablation study.
struct Variant {
  std::string name;
  EcvOptions extraction;
  DescriptorOptions descriptor;
  MatchOptions matching;
};

std::vector<Variant> Variants() {
  std::vector<Variant> variants;
  auto add = [&](const std::string& name, const std::function<void(Variant&)>& change) {
    Variant variant{name, {}, {}, {}};
    change(variant);
    variants.push_back(variant);
  };
  add("**field defaults** (all pairs, 2.5 cm; libraries use source pairs, 4 shells, 4.5 cm)", [](Variant&) {});
  add("paper's descriptor: signed, hard bins, L2, structure-specific", [](Variant& v) {
    v.descriptor.unsigned_segments = false;
    v.descriptor.soft_binning = false;
    v.descriptor.hellinger = false;
    v.matching.structure_specific = true;
  });
  add("unsigned segment directions",
      [](Variant& v) { v.descriptor.unsigned_segments = !DescriptorOptions{}.unsigned_segments; });
  add("soft binning", [](Variant& v) { v.descriptor.soft_binning = !DescriptorOptions{}.soft_binning; });
  add("Hellinger distance", [](Variant& v) { v.descriptor.hellinger = !DescriptorOptions{}.hellinger; });
  add("mixed matching (not structure-specific)",
      [](Variant& v) { v.matching.structure_specific = !MatchOptions{}.structure_specific; });
  add("grey-world colour balance",
      [](Variant& v) { v.descriptor.balance_colors = !DescriptorOptions{}.balance_colors; });
  add("shape only (no colour histograms)", [](Variant& v) { v.descriptor.use_color = false; });
  add("radius 0.015 m", [](Variant& v) { v.descriptor.radius_m = 0.015; });
  add("radius 0.035 m", [](Variant& v) { v.descriptor.radius_m = 0.035; });
  add("at most 32 neighbours (spread)", [](Variant& v) { v.descriptor.max_neighbours = 32; });
  add("at most 64 neighbours (spread)", [](Variant& v) { v.descriptor.max_neighbours = 64; });
  add("wavelength 6 px", [](Variant& v) { v.extraction.monogenic.wavelength_px = 6; });
  add("wavelength 8 px", [](Variant& v) { v.extraction.monogenic.wavelength_px = 8; });
  add("wavelength 16 px", [](Variant& v) { v.extraction.monogenic.wavelength_px = 16; });
  add("grid spacing 6 px", [](Variant& v) { v.extraction.grid_spacing_px = 6; });
  add("grid spacing 7 px", [](Variant& v) { v.extraction.grid_spacing_px = 7; });
  add("grid spacing 10 px", [](Variant& v) { v.extraction.grid_spacing_px = 10; });
  add("min magnitude 0.01", [](Variant& v) { v.extraction.min_magnitude = 0.01; });
  add("min magnitude 0.04", [](Variant& v) { v.extraction.min_magnitude = 0.04; });
  add("max edge variance 0.15", [](Variant& v) { v.extraction.max_edge_variance = 0.15; });
  add("max edge variance 0.35", [](Variant& v) { v.extraction.max_edge_variance = 0.35; });
  add("no edge NMS", [](Variant& v) { v.extraction.edge_nms = false; });
  // Issue 5's descriptor variants: source pairs (O(k)), closeness weights, radial shells, and appearance
  // (RGB log ratios; the paper's future work, monogenic magnitude and orientation).
  auto source = [&](const std::string& name, int shells, double radius_m, const std::function<void(Variant&)>& more) {
    add("source pairs" + name, [&](Variant& v) {
      v.descriptor.pairs = DescriptorPairs::kSource;
      v.descriptor.shells = shells;
      v.descriptor.radius_m = radius_m;
      more(v);
    });
  };
  const auto nothing = [](Variant&) {};
  const auto log_ratios = [](Variant& v) { v.descriptor.appearance = DescriptorAppearance::kRgbLogRatio; };
  const auto monogenic = [](Variant& v) { v.descriptor.appearance = DescriptorAppearance::kMonogenic; };
  add("closeness weight 0.5", [](Variant& v) { v.descriptor.closeness_weight = 0.5; });
  add("closeness weight 1", [](Variant& v) { v.descriptor.closeness_weight = 1.0; });
  add("RGB log ratios", log_ratios);
  add("monogenic appearance", monogenic);
  add("2 shells (all pairs)", [](Variant& v) { v.descriptor.shells = 2; });
  source(" {s, n}", 1, 0.025, nothing);
  source(", closeness weight 0.5", 1, 0.025, [](Variant& v) { v.descriptor.closeness_weight = 0.5; });
  source(", RGB log ratios", 1, 0.025, log_ratios);
  source(", monogenic appearance", 1, 0.025, monogenic);
  source(", radius 0.035 m", 1, 0.035, nothing);
  for (const int shells : {2, 4}) {
    for (const double radius : {0.025, 0.035, 0.045, 0.055, 0.065}) {
      source(", " + std::to_string(shells) + " shells, radius " + Fixed(radius, 3) + " m", shells, radius, nothing);
    }
  }
  source(", 2 shells, radius 0.035 m, RGB log ratios", 2, 0.035, log_ratios);
  source(", 2 shells, radius 0.035 m, monogenic", 2, 0.035, monogenic);
  source(", 2 shells, radius 0.035 m, hard bins", 2, 0.035, [](Variant& v) { v.descriptor.soft_binning = false; });
  source(", 2 shells, radius 0.035 m, closeness weight 0.5", 2, 0.035,
         [](Variant& v) { v.descriptor.closeness_weight = 0.5; });
  source(", 4 shells, radius 0.045 m, RGB log ratios", 4, 0.045, log_ratios);
  source(", 4 shells, radius 0.045 m, monogenic", 4, 0.045, monogenic);
  source(", 4 shells, radius 0.045 m, grey-world colour balance", 4, 0.045,
         [](Variant& v) { v.descriptor.balance_colors = true; });
  source(", 4 shells, radius 0.045 m, mixed matching", 4, 0.045,
         [](Variant& v) { v.matching.structure_specific = false; });
  source(", 4 shells, radius 0.045 m, unsigned segments", 4, 0.045,
         [](Variant& v) { v.descriptor.unsigned_segments = true; });
  // The surface context (DescriptorShape::kSurface): a hybrid whose shape histograms come from the depth image's
  // surface in a local reference frame, the colour ones from the primitives.
  auto surface = [&](const std::string& name, double radius, double weight, bool mixed, bool color) {
    source(", 4 shells, radius " + Fixed(radius, 3) + " m, surface context" + name, 4, radius, [=](Variant& v) {
      v.descriptor.shape = DescriptorShape::kSurface;
      v.descriptor.surface_weight = weight;
      v.descriptor.use_color = color;
      v.matching.structure_specific = !mixed;
    });
  };
  surface("", 0.045, 2.0, false, true);
  surface(", mixed matching", 0.045, 2.0, true, true);
  surface(", mixed matching, weight 1", 0.045, 1.0, true, true);
  surface(", mixed matching, weight 4", 0.045, 4.0, true, true);
  surface(", mixed matching, no colour", 0.045, 2.0, true, false);
  surface(", mixed matching", 0.035, 2.0, true, true);
  surface(", mixed matching", 0.055, 2.0, true, true);
  return variants;
}

// True when `filter` is empty or one of its '|'-separated parts occurs in `name`.
bool MatchesFilter(const std::string& name, const std::string& filter) {
  if (filter.empty()) return true;
  size_t start = 0;
  while (start <= filter.size()) {
    const size_t end = std::min(filter.find('|', start), filter.size());
    if (end > start && name.find(filter.substr(start, end - start)) != std::string::npos) return true;
    start = end + 1;
  }
  return false;
}

bool SameExtraction(const EcvOptions& a, const EcvOptions& b) {
  return a.monogenic.wavelength_px == b.monogenic.wavelength_px && a.grid_spacing_px == b.grid_spacing_px &&
         a.min_magnitude == b.min_magnitude && a.max_edge_variance == b.max_edge_variance && a.edge_nms == b.edge_nms;
}

// A dense close-up frame (YCB-Video 0000/000001, whole image) for the descriptor time.
RgbdFrame DenseFrame() {
  return LoadYcbvFrame(std::string(ECV_DATA_DIR) + "/ycbv_subset/Example-Scenes/0000/000001").rgbd;
}

std::vector<Primitive> DenseFramePrimitives(const EcvOptions& options) {
  return ExtractPrimitives(DenseFrame(), options).primitives;
}

// Mean ECV score of each variant per set, on the tuning pairs (videos 0000, 0001) and the held-out ones,
// with the descriptor time per view of the pairs and of the dense frame.
std::string AblationTable(const std::vector<ViewPair>& pairs, const std::vector<PairPrimitives>& default_primitives,
                          const std::string& filter) {
  const std::vector<Primitive> dense = DenseFramePrimitives({});
  std::string table =
      "### Ablations of the ECV context descriptor (mean score %, tuning = videos 0000 and 0001, held out = 0002)\n\n"
      "mean per object: as the set tables above (each object's mean over its pairs, then the mean over the objects); "
      "in clutter: the recognition pairs matched against every primitive of the real frame, their contexts among all "
      "of them; describe ms/view: mean over the views cut to their object; dense frame: YCB-Video 0000/000001, whole "
      "image (" +
      std::to_string(dense.size()) +
      " primitives with the default extraction).\n\n"
      "| variant | recognition, mean per object | hard, mean per object | recognition tuning | recognition held out | "
      "in clutter tuning | in clutter held out | hard (held out) | easy tuning | easy held out | "
      "describe ms/view | describe ms, dense frame |\n"
      "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const Variant& variant : Variants()) {
    if (!MatchesFilter(variant.name, filter)) continue;
    std::map<std::string, std::pair<double, int>> sums;                              // key: set + tuning/held-out
    std::map<std::string, std::map<std::string, std::pair<double, int>>> by_object;  // set -> object -> sum, count
    const bool same_extraction = SameExtraction(variant.extraction, EcvOptions{});
    double describe_ms = 0.0;  // of the views cut to the object
    int described_views = 0;
    for (size_t i = 0; i < pairs.size(); ++i) {
      const PairPrimitives primitives = same_extraction ? default_primitives[i] : Extract(pairs[i], variant.extraction);
      const PairScore score = ScoreEcv(pairs[i], primitives, variant.descriptor, variant.matching);
      if (!pairs[i].clutter) {
        describe_ms += score.describe_ms;
        described_views += 2;
      }
      auto& [sum, count] = sums[pairs[i].set + (pairs[i].held_out ? "/held" : "/tune")];
      sum += score.score;
      ++count;
      auto& [object_sum, object_count] = by_object[pairs[i].set][pairs[i].object];
      object_sum += score.score;
      ++object_count;
    }
    // The main tables' figure: the mean over objects of each object's mean over its pairs.
    auto object_mean = [&](const std::string& set) {
      double total = 0.0;
      for (const auto& [object, sum_count] : by_object[set]) {
        total += sum_count.first / sum_count.second;
        if (std::getenv("ECV_PER_OBJECT") != nullptr) {
          std::cerr << set << " " << object << " " << Percent(sum_count.first / sum_count.second) << "\n";
        }
      }
      return by_object[set].empty() ? std::string("") : Percent(total / static_cast<double>(by_object[set].size()));
    };
    const std::vector<Primitive> dense_primitives = same_extraction ? dense : DenseFramePrimitives(variant.extraction);
    const RgbdFrame dense_frame = DenseFrame();
    const Clock::time_point start = Clock::now();  // the surface context's sampling counts too
    const SurfaceSamples surface = DescriptorSurface(dense_frame, variant.descriptor);
    ComputeDescriptors(dense_primitives, variant.descriptor, 1, 1, &surface);
    const double dense_ms = MillisecondsSince(start);
    auto mean = [&](const std::string& key) {
      const auto found = sums.find(key);
      return found == sums.end() ? std::string("") : Percent(found->second.first / found->second.second);
    };
    table += "| " + variant.name + " | " + object_mean("recognition") + " | " + object_mean("hard") + " | " +
             mean("recognition/tune") + " | " + mean("recognition/held") + " | " + mean("recognition in clutter/tune") +
             " | " + mean("recognition in clutter/held") + " | " + mean("hard/held") + " | " + mean("easy/tune") +
             " | " + mean("easy/held") + " | " + Fixed(describe_ms / std::max(described_views, 1), 1) + " | " +
             Fixed(dense_ms, 0) + " |\n";
    std::cerr << '.' << std::flush;
  }
  return table + "\n";
}

}  // namespace
}  // namespace ecv::bench

int main(int argc, char** argv) {
  using namespace ecv::bench;
  std::string results = std::string(ECV_SOURCE_DIR) + "/bench/RESULTS.md";
  std::string figures = std::string(ECV_SOURCE_DIR) + "/bench/figures";
  bool ablations_only = false;
  std::string variant_filter;     // only ablation variants whose name contains one of its '|'-separated parts
  double library_distance_m = 0;  // 0: library views as close as the object fits the image
  ecv::Shading shading = ecv::Shading::kUnlit;  // of the library renders
  CLI::App app{
      "discriminative_bench: correspondence score of the ECV context descriptor and its peers on real view "
      "pairs with known relative pose (paper Fig. 7), and the descriptor's ablations.",
      "discriminative_bench"};
  app.add_option("--results", results, "Markdown file whose section of this bench the report replaces")
      ->capture_default_str();
  app.add_option("--figures", figures, "Directory the bar chart and the picture of matches are written to")
      ->capture_default_str();
  app.add_flag("--ablations-only", ablations_only,
               "Only the ablation table, printed: no peers, no figures, the results file left alone");
  app.add_option("--variants", variant_filter,
                 "Only the ablation variants whose name contains one of these '|'-separated parts (default: all)");
  app.add_option("--library-distance", library_distance_m,
                 "Distance in metres of the library views from the object (0: as close as the object fits the image)")
      ->capture_default_str();
  app.add_flag_callback(
      "--headlight", [&shading] { shading = ecv::Shading::kHeadlight; },
      "Render the library views with headlight shading (default: unlit)");
  if (const auto exit_code = ParseCommandLine(app, argc, argv)) return *exit_code;
  std::cerr << "rendering and loading view pairs...\n";
  const std::vector<ecv::bench::ViewPair> pairs = LoadViewPairs(ECV_DATA_DIR, library_distance_m, shading);
  const auto methods = Methods();
  std::vector<std::string> names;
  for (const auto& [name, method] : methods) names.push_back(name);

  std::vector<std::vector<PairScore>> scores(pairs.size());
  std::vector<PairPrimitives> primitives;
  for (size_t i = 0; i < pairs.size(); ++i) {
    primitives.push_back(Extract(pairs[i], {}));
    if (!ablations_only) {
      for (const auto& [name, method] : methods) scores[i].push_back(method(pairs[i], primitives.back()));
    }
    std::cerr << "\rpair " << i + 1 << "/" << pairs.size() << std::flush;
  }
  std::cerr << '\n';
  const std::string ablations = AblationTable(pairs, primitives, variant_filter);
  std::cerr << '\n';
  if (ablations_only) {  // a quick look: the full run's section of RESULTS.md holds the table
    std::cout << ablations;
    return 0;
  }
  std::string report =
      "Correspondence score (paper Sect. IV-A): % of nearest-neighbour matches whose points lie within 1 cm after "
      "ground-truth alignment, mean per object, on real YCB-Video frames. Peers run at the ECV keypoints (\"@ECV\", "
      "radius 0.025 m, support = the object's pixels) or at their own keypoints lifted to 3D. \"Recognition in "
      "clutter\" "
      "repeats the recognition pairs against the whole real frame: every keypoint of the frame is a candidate match "
      "and "
      "the support (an ECV context's neighbours, a PCL descriptor's points) takes in the clutter, as in a recognition "
      "scene. SURF is not in Debian's "
      "OpenCV (no xfeatures2d), so it is absent. random = expected score of matching at random; ceiling = share of "
      "query keypoints with any true partner within 1 cm.\n\n";
  for (const std::string& set : kPairSets) {
    report += SetTable(set, pairs, names, scores);
  }
  report += ablations;
  report += "![bar chart](figures/descriptor_scores.png)\n\n![matches](figures/descriptor_matches.jpg)\n\n";
  std::filesystem::create_directories(figures);
  WriteImage(figures + "/descriptor_scores.png", BarChart(pairs, names, scores));
  for (size_t i = 0; i < pairs.size(); ++i) {  // a recognition pair of the cracker box
    if (pairs[i].set == "recognition" && pairs[i].object == "003_cracker_box") {
      cv::Mat picture = MatchPicture(pairs[i], primitives[i]);
      cv::resize(picture, picture, cv::Size(), 0.75, 0.75, cv::INTER_AREA);
      WriteImage(figures + "/descriptor_matches.jpg", picture);
      break;
    }
  }
  ReportSection(results, "Discriminative power of descriptors (paper Fig. 7)", CommandLine(argc, argv), report);
  return 0;
}
