#pragma once

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "modeldb/model_library.h"
#include "recognize/recognizer_options.h"

namespace ecv {

/// One recognised object.
struct Detection {
  std::string model;
  /// 0..1, higher is surer: depth agreement x appearance (colour correlation and texture edges) of the rendered
  /// model x its fit, contour and continuation factors
  double score = 0.0;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  double inlier_fraction = 0.0;    ///< RANSAC inliers over the visible view primitives
  double fit_error_m = 0.0;        ///< RANSAC mean inlier distance, metres
  int view = -1;                   ///< library view that matched
  double depth_agreement = 0.0;    ///< share of the visible rendered pixels on the scene surface
  double color_agreement = 0.0;    ///< correlation of the rendered colours with the scene's on those, 0..1
  double surface_error_m = 0.0;    ///< mean |rendered - scene depth| on those, metres
  double contour_agreement = 0.0;  ///< share of the seen outline on a scene depth step (0: none seen)
  double continuation = 0.0;       ///< share of the judged outline across which the scene's surface runs on
  double visible_fraction = 0.0;   ///< share of the rendered pixels the scene can show (not hidden, with depth)
  /// Of the rendered model's texture edges on those, the share the scene shows (0: none predicted) ...
  double edge_agreement = 0.0;
  int edge_pixels = 0;   ///< ... and how many were predicted
  bool tracked = false;  ///< found from a prior (the previous frame's pose), without RANSAC
  /// Frames it has been followed since a search of its model last found it (0: a search found it in this frame);
  /// TrackingOptions::confirm_every.
  int frames_followed = 0;
  /// A later search found it again on its surface (TrackingOptions::confirm_first); a tracked detection keeps its
  /// prior's.
  bool confirmed = false;
  /// Where its pose came from: kContext (view ranking and RANSAC) or kPpf (point pair features); a tracked
  /// detection keeps its first detection's.
  HypothesisSource hypothesis = HypothesisSource::kContext;
};

/// Detections of one frame and where the time went.
struct RecognitionResult {
  std::vector<Detection> detections;  ///< best score first, at most max_instances per model, overlaps suppressed
  /// Per stage: extract, describe, track, match, ransac, refine, verify, total (a stage not run is absent).
  std::map<std::string, double> timings_ms;
  int scene_primitives = 0;
  /// Per model searched in the frame (not only tracked): the library views RANSAC ran on.
  std::map<std::string, int> views_tried;
  /// With a search beside the tracking (StreamOptions::search_beside): how many frames before this one the frame lay
  /// whose search's detections joined this frame's priors; -1: none did.
  int searched_frames_ago = -1;
};

/// One library view as view ranking saw it in a frame.
struct RankedView {
  int view = -1;  ///< index among the model's views
  int score = 0;  ///< ConsistentSetSize of its ranking correspondences
  /// Its ranking correspondences: a view primitive (object frame) and its nearest scene primitive by descriptor
  /// (camera frame).
  std::vector<std::pair<Primitive, Primitive>> correspondences;
};

/// The detections JSON that `ecvpose recognize --out-json` writes: {"detections": [{"model", "score",
/// "camera_from_object", "inlier_fraction", "fit_error", "view", ..., "tracked", "confirmed", "hypothesis"}],
/// "timings_ms": {stage: ms}, ...}, with "searched_frames_ago" when a search beside the tracking joined the frame.
nlohmann::json RecognitionToJson(const RecognitionResult& result);

/// The detections of such JSON (model, score, camera_from_object, hypothesis); throws InputError naming `source`
/// and the field when one is missing or malformed.
std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source);

/// A frame's descriptors as the recognizer computes them from its `primitives`: the library's `descriptor`
/// settings with at most options.scene_max_neighbours neighbours per context, and every n-th primitive a source
/// so that at most options.scene_max_descriptors are described; on options.ransac.threads threads. `surface`: the
/// frame's surface, for a library whose descriptors use the surface context (DescriptorShape::kSurface).
Descriptors ComputeSceneDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& descriptor,
                                    const RecognizerOptions& options, const SurfaceSamples* surface = nullptr);

/// What a tracking frame (Recognizer::Recognize with priors) searches for, by view ranking and RANSAC, besides
/// following its priors.
enum class SearchScope {
  kAllModels,  ///< every model whose prior fails or that has none: a full detection frame
  /// Only the models whose prior failed or fell below TrackingOptions::min_follow_score (a lost track is looked for at
  /// once) or whose track is due for confirmation (TrackingOptions::confirm_every); models without a prior are not
  /// looked for. When every prior passes and none is due, the frame's primitives are not even
  /// extracted. RecognitionStream alternates it with full frames to follow known objects at a fraction of the cost
  /// and still pick up new ones every N frames.
  kLostTracks,
  /// No model is searched, not even for confirmation: the priors are followed, nothing else (RecognitionStream's
  /// tracking when the search runs beside it, StreamOptions::search_beside).
  kPriorsOnly,
};

/// Finds the library's models in RGB-D frames. Owns an offscreen renderer (for verification) with the
/// models' meshes, loaded from the paths stored in the library. One Recognizer per thread.
class Recognizer {
 public:
  Recognizer(const ModelLibrary& library, const RecognizerOptions& options = {});
  ~Recognizer();
  Recognizer(const Recognizer&) = delete;
  Recognizer& operator=(const Recognizer&) = delete;

  RecognitionResult Recognize(const RgbdFrame& frame);

  /// Tracking, for frames of a stream (beyond the paper): each prior (a detection of the previous frame) that scored
  /// at least tracking.min_follow_score is first tried at its pose, refined by ICP and verified as any detection;
  /// when it passes, its model skips view ranking and RANSAC in this frame, unless the track is due for confirmation
  /// (tracking.confirm_every). A model's priors are all tried and compete on score (KeepBestFollowed): a search's
  /// detection given beside a track of the same object confirms it. Which of the other models are searched: see
  /// SearchScope.
  RecognitionResult Recognize(const RgbdFrame& frame, const std::vector<Detection>& priors,
                              SearchScope scope = SearchScope::kAllModels);

  /// View ranking alone, for studying it: every model's views as Recognize ranks them in `frame`, best first
  /// (RANSAC tries the first views_per_model of them).
  std::map<std::string, std::vector<RankedView>> RankViews(const RgbdFrame& frame);

  /// With point pair hypotheses (RecognizerOptions::point_pairs): per model that has no point pair table, because
  /// its mesh is too small, flat or coarse for point pairs, a line naming it and why; such a model is found by the
  /// context alone.
  std::vector<std::string> PointPairWarnings() const;

  /// `frame`'s colour image with each detected model rendered at its pose in red, outlined, with its name.
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ecv
