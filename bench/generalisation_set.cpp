#include "generalisation_set.h"

#include <algorithm>
#include <iostream>
#include <map>
#include <random>

#include <opencv2/imgproc.hpp>

namespace ecv::bench {
namespace {

// The look-alikes of YCB-Video that real frames show: the object cut, and the one it is placed beside.
const std::vector<std::pair<std::string, std::string>> kLookAlikes = {
    {"009_gelatin_box", "010_potted_meat_can"}, {"009_gelatin_box", "008_pudding_box"},
    {"008_pudding_box", "009_gelatin_box"},     {"010_potted_meat_can", "009_gelatin_box"},
    {"036_wood_block", "003_cracker_box"},      {"061_foam_brick", "010_potted_meat_can"},
};

std::string VideoOf(const std::string& prefix) {
  const size_t slash = prefix.rfind('/');
  const size_t before = prefix.rfind('/', slash - 1);
  return prefix.substr(before + 1, slash - before - 1);
}

std::string FrameOf(const std::string& prefix) {
  return prefix.substr(prefix.rfind('/') + 1);
}

bool HasObject(const LoadedFrame& frame, const std::string& name) {
  return std::any_of(frame.ground_truth.begin(), frame.ground_truth.end(),
                     [&](const GroundTruth& truth) { return truth.object_name == name; });
}

std::vector<SceneObjectInfo> ObjectsOf(const std::vector<GroundTruth>& truth) {
  std::vector<SceneObjectInfo> objects;
  for (const GroundTruth& object : truth)
    objects.push_back({object.object_name, object.camera_from_object.translation()});
  return objects;
}

// Per ground-truth object, the pixels of its YCB-Video class in `labels` (CV_8UC1 class indices).
std::vector<cv::Mat> ClassMasks(const cv::Mat& labels, const std::vector<GroundTruth>& truth) {
  std::vector<cv::Mat> masks;
  for (const GroundTruth& object : truth) masks.push_back(labels == object.object_id);
  return masks;
}

}  // namespace

const char* SplitHalfName(SplitHalf half) {
  return half == SplitHalf::kChoosing ? "choosing" : "reporting";
}

std::vector<std::string> SplitVideos(SplitHalf half) {
  // 0002 holds the most objects and three of the grey ones: settings are chosen on it; 0000 and 0001 report.
  if (half == SplitHalf::kChoosing) return {"0002"};
  return {"0000", "0001"};
}

uint32_t SplitSeed(SplitHalf half, int index) {
  return static_cast<uint32_t>(2 * index + (half == SplitHalf::kChoosing ? 1 : 2));
}

std::vector<bool> PlainObjects(const cv::Mat& color, const std::vector<cv::Mat>& object_masks) {
  cv::Mat grey, gx, gy, magnitude;
  cv::cvtColor(color, grey, cv::COLOR_RGB2GRAY);
  grey.convertTo(grey, CV_32F, 1.0 / 255.0);
  cv::Sobel(grey, gx, CV_32F, 1, 0, 3, 0.125);
  cv::Sobel(grey, gy, CV_32F, 0, 1, 3, 0.125);
  cv::magnitude(gx, gy, magnitude);
  std::vector<bool> plain;
  for (const cv::Mat& mask : object_masks) {
    cv::Mat inner;
    if (!mask.empty()) cv::erode(mask, inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(5, 5)));
    plain.push_back(!inner.empty() && cv::countNonZero(inner) > 0 && cv::mean(magnitude, inner)[0] < kPlainGradient);
  }
  return plain;
}

std::vector<std::pair<std::string, ColorCast>> SetCasts() {
  ColorCast own, warm, cool, dark, gamma, dark_warm;
  warm.rgb_gain = Eigen::Vector3d(1.4, 1.0, 0.75);
  cool.rgb_gain = Eigen::Vector3d(0.75, 1.0, 1.35);
  dark.rgb_gain = Eigen::Vector3d::Constant(0.5);
  gamma.gamma = 1.6;
  dark_warm.rgb_gain = Eigen::Vector3d(0.7, 0.5, 0.4);
  return {{"own light", own},
          {"warm (R x1.4, B x0.75)", warm},
          {"cool (R x0.75, B x1.35)", cool},
          {"dark (x0.5)", dark},
          {"gamma 1.6", gamma},
          {"dark and warm (R x0.7, G x0.5, B x0.4)", dark_warm}};
}

std::vector<BenchFrame> RenderedFrames(Renderer& renderer, const std::vector<SceneAsset>& assets,
                                       const std::vector<MeshId>& mesh_ids, const Backdrops& backdrops, SplitHalf half,
                                       int count) {
  std::vector<BenchFrame> frames;
  for (int i = 0; i < count; ++i) {
    const uint32_t seed = SplitSeed(half, i);
    RenderedScene scene = GenerateRenderedScene(renderer, assets, mesh_ids, backdrops, seed);
    const Eigen::Vector3d& gain = scene.light_gain;
    std::string condition = gain[0] > 1.15 * gain[2] ? "warm" : gain[2] > 1.15 * gain[0] ? "cool" : "neutral";
    if (gain.mean() < 0.7) condition += ", dark";
    BenchFrame bench{"rendered", condition, "", "rendered/" + std::to_string(seed), std::move(scene.frame), {}, {}};
    std::vector<cv::Mat> masks;
    for (const GroundTruth& truth : bench.frame.ground_truth) {
      cv::Mat mask = cv::Mat::zeros(scene.labels.size(), CV_8UC1);
      for (size_t o = 0; o < scene.objects.size(); ++o) {
        if (scene.objects[o].name == truth.object_name) mask = scene.labels == static_cast<int>(o + 1);
      }
      masks.push_back(mask);
    }
    bench.plain = PlainObjects(bench.frame.rgbd.color, masks);
    for (const PlacedObject& object : scene.objects) {
      bench.objects.push_back({object.name, object.camera_from_object.translation()});
    }
    std::cerr << "\rrendered scenes (" << SplitHalfName(half) << "): " << i + 1 << " of " << count << std::flush;
    frames.push_back(std::move(bench));
  }
  std::cerr << '\n';
  return frames;
}

std::vector<BenchFrame> CompositeFrames(const std::vector<SourceFrame>& sources, SplitHalf half, int count) {
  std::vector<BenchFrame> frames;
  CompositeOptions options;
  for (int i = 0; i < count; ++i) {
    const uint32_t seed = SplitSeed(half, i);
    std::mt19937 random(seed);
    const auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(random); };
    Composite composite;
    bool made = false;
    const bool look_alike = i % 2 == 0;
    for (int attempt = 0; attempt < 100 && !made; ++attempt) {
      std::string object, beside;
      const SourceFrame* source = nullptr;
      const SourceFrame* target = nullptr;
      if (look_alike) {
        const auto& [cut, neighbour] = kLookAlikes[pick(kLookAlikes.size())];
        object = cut;
        beside = neighbour;
        std::vector<const SourceFrame*> with_cut, with_neighbour;
        for (const SourceFrame& frame : sources) {
          if (HasObject(frame.frame, cut)) with_cut.push_back(&frame);
          if (HasObject(frame.frame, neighbour) && !HasObject(frame.frame, cut)) with_neighbour.push_back(&frame);
        }
        if (with_cut.empty() || with_neighbour.empty()) continue;
        source = with_cut[pick(with_cut.size())];
        target = with_neighbour[pick(with_neighbour.size())];
      } else {
        source = &sources[pick(sources.size())];
        target = &sources[pick(sources.size())];
        if (VideoOf(source->prefix) == VideoOf(target->prefix) || source->frame.ground_truth.empty()) continue;
        object = source->frame.ground_truth[pick(source->frame.ground_truth.size())].object_name;
        if (HasObject(target->frame, object)) continue;
      }
      made = MakeComposite(*source, object, *target, beside, seed * 131U + static_cast<uint32_t>(attempt), options,
                           &composite);
    }
    if (!made) continue;
    BenchFrame bench{"composite",
                     look_alike ? "beside a look-alike" : "another room",
                     "",
                     "composite/" + std::to_string(seed) + " " + composite.object_name + " from " +
                         VideoOf(composite.source_prefix) + "/" + FrameOf(composite.source_prefix) + " into " +
                         VideoOf(composite.target_prefix) + "/" + FrameOf(composite.target_prefix),
                     std::move(composite.frame),
                     {},
                     {}};
    bench.plain = PlainObjects(bench.frame.rgbd.color, ClassMasks(composite.labels, bench.frame.ground_truth));
    bench.objects = ObjectsOf(bench.frame.ground_truth);
    std::cerr << "\rcomposites (" << SplitHalfName(half) << "): " << i + 1 << " of " << count << std::flush;
    frames.push_back(std::move(bench));
  }
  std::cerr << '\n';
  return frames;
}

std::vector<BenchFrame> CastFrames(const std::vector<SourceFrame>& sources, SplitHalf half, int step) {
  const std::vector<std::string> videos = SplitVideos(half);
  std::vector<BenchFrame> frames;
  for (const auto& [name, cast] : SetCasts()) {
    std::map<std::string, int> taken;  // per video: frames seen
    for (const SourceFrame& source : sources) {
      const std::string video = VideoOf(source.prefix);
      if (std::find(videos.begin(), videos.end(), video) == videos.end()) continue;
      if (taken[video]++ % std::max(step, 1) != 0) continue;
      LoadedFrame frame{WithColorCast(source.frame.rgbd, cast), source.frame.ground_truth, source.frame.scene_id,
                        source.frame.image_id};
      BenchFrame bench{
          "cast", name, video + ", " + name, video + "/" + FrameOf(source.prefix) + ", " + name, std::move(frame),
          {},     {}};
      // Plain by the frame's own light: a cast does not make a printed side plain.
      bench.plain = PlainObjects(source.frame.rgbd.color, ClassMasks(source.labels, source.frame.ground_truth));
      bench.objects = ObjectsOf(source.frame.ground_truth);
      frames.push_back(std::move(bench));
    }
  }
  return frames;
}

}  // namespace ecv::bench
