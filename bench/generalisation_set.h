#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "io/frame_io.h"
#include "render/renderer.h"
#include "scenes/composites.h"
#include "scenes/rendered_scenes.h"

namespace ecv::bench {

/// Which half of the generalisation set: settings are chosen on the first, figures quoted from the second.
enum class SplitHalf { kChoosing, kReporting };

/// "choosing" or "reporting".
const char* SplitHalfName(SplitHalf half);

/// The fixed split of the real frames: by video. Backdrops of the rendered scenes are cut from the choosing videos.
std::vector<std::string> SplitVideos(SplitHalf half);

/// The `index`-th generation seed (0-based) of `half`: odd seeds choose, even seeds report.
uint32_t SplitSeed(SplitHalf half, int index);

/// Another object of a frame, for telling where a false positive lies.
struct SceneObjectInfo {
  std::string name;
  Eigen::Vector3d position;  ///< camera frame, metres
};

/// One frame of the set with what the report sorts it by.
struct BenchFrame {
  std::string set;        ///< "rendered", "composite" or "cast"
  std::string condition;  ///< the light, the placement or the cast
  std::string stream;     ///< frames of one stream in order (a real video under one cast); "" for single frames
  std::string name;       ///< unique, for logs
  LoadedFrame frame;      ///< ground truth: every modelled object in view
  /// Per ground-truth object: true when its visible surface is plain (little texture; BenchPlainGradient).
  std::vector<bool> plain;
  /// Every object in view, modelled or not (clutter, objects of no library).
  std::vector<SceneObjectInfo> objects;
};

/// Mean Sobel gradient magnitude of grey (0..1 per pixel) under which an object's visible pixels count as plain.
constexpr double kPlainGradient = 0.035;

/// Per ground-truth object of `truth`, whether its pixels in `frame` (`object_masks[i]`, CV_8UC1, 255 on the
/// object; empty if unknown) are plain: mean grey gradient within the mask eroded by 2 px below kPlainGradient.
std::vector<bool> PlainObjects(const cv::Mat& color, const std::vector<cv::Mat>& object_masks);

/// The cast lights of the set: each a name and the change of the frames' colours.
std::vector<std::pair<std::string, ColorCast>> SetCasts();

/// `count` rendered scenes of `half` (seeds SplitSeed(half, 0 .. count - 1)); condition: the light's colour
/// ("warm", "cool", "neutral" by its red against blue gain) and "dark" when its strength is below 0.7.
std::vector<BenchFrame> RenderedFrames(Renderer& renderer, const std::vector<SceneAsset>& assets,
                                       const std::vector<MeshId>& mesh_ids, const Backdrops& backdrops, SplitHalf half,
                                       int count);

/// `count` composites of `half` from `sources` (every real frame): half of them a look-alike placed beside the
/// object it is confused with (condition "beside a look-alike"), the others an object of one video anywhere on the
/// table of another ("another room").
std::vector<BenchFrame> CompositeFrames(const std::vector<SourceFrame>& sources, SplitHalf half, int count);

/// Every `step`-th real frame of each of `half`'s videos under each of SetCasts() (condition: the cast's name; one
/// stream per video and cast).
std::vector<BenchFrame> CastFrames(const std::vector<SourceFrame>& sources, SplitHalf half, int step = 1);

}  // namespace ecv::bench
