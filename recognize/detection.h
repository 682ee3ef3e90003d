#pragma once

// What the recognizer returns: detections with their evidence, per frame with its timings.

#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "ecv/primitives.h"
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
  int edge_pixels = 0;  ///< ... and how many were predicted
  /// Geometric evidence (VerifyOptions, not yet in the score): the share of the visible rendered surface the scene's
  /// points and normals confirm; ...
  double explained_surface = 0.0;
  double free_space_violation = 0.0;  ///< ... the share where the scene is seen far behind it; ...
  double occluding_contour = 0.0;     ///< ... the share of the seen outline where the scene steps back behind it, ...
  double creased_contour = 0.0;       ///< ... and where, not stepping back, the scene's surface turns
  /// With the learned acceptance: its probability that the pose is right (-1: not computed).
  double acceptance = -1.0;
  bool tracked = false;  ///< found from a prior (the previous frame's pose), without RANSAC
  /// Frames it has been followed since a search of its model last found it (0: a search found it in this frame);
  /// TrackingOptions::confirm_every.
  int frames_followed = 0;
  /// A later search found it again on its surface (TrackingOptions::confirm_first); a tracked detection keeps its
  /// prior's.
  bool confirmed = false;
  /// Where its pose came from: kContext (view ranking and RANSAC) or kPpf (point pair features); a tracked
  /// detection keeps its first detection's.
  HypothesisSource hypothesis_source = HypothesisSource::kContext;
  /// False for a pose the acceptance rejected that is reported all the same: the best a target model had
  /// (Recognizer::RecognizeTargets).
  bool accepted = true;
};

/// A pose the acceptance (min_score, min_visible_fraction) judged, with its evidence, and the verdict.
struct JudgedPose {
  Detection detection;
  bool accepted = false;
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
  /// With RecognizerOptions::keep_judged: each model's best pose for each instance searched for, and each prior
  /// followed, before overlaps are suppressed; per model in library order.
  std::vector<JudgedPose> judged;
  /// With RecognizerOptions::keep_verified: every pose verified in the frame (RANSAC's, refined, turned, point pairs',
  /// followed priors'), as verification scored it, by model in library order, then best score first.
  std::vector<Detection> verified;
};

/// One library view as view ranking saw it in a frame.
struct RankedView {
  int view = -1;  ///< index among the model's views
  int score = 0;  ///< ConsistentSetSize of its ranking correspondences
  /// Its ranking correspondences: a view primitive (object frame) and its nearest scene primitive by descriptor
  /// (camera frame).
  std::vector<std::pair<Primitive, Primitive>> correspondences;
};

}  // namespace ecv
