#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "core/frame.h"
#include "ecv/matching.h"
#include "modeldb/model_library.h"
#include "registration/icp.h"
#include "registration/ransac.h"

namespace ecv {

/// Settings of the online recognizer (DESIGN.md "Pose estimation"; paper Sect. III and IV-C).
struct RecognizerOptions {
  MatchOptions match;  ///< k is set to 2 internally (nearest and second nearest, for the view votes)
  /// RANSAC per model view; the paper's test (t_poly 0.25, eps 1 cm, 50 % of the visible object points).
  RansacOptions ransac = DefaultRansac();
  /// Views per model tried with RANSAC, those with the most distinctive matches (ratio test) first.
  int views_per_model = 3;
  double ratio_test = 0.9;  ///< a match votes for its view when nearest / second-nearest distance is below
  /// Vote with one index over all models' views (one query per scene descriptor, faster for many models)
  /// instead of one index per model. On the 30 YCB-Video frames with 6 models it found 15 of 60 objects
  /// against 24 of 60 per model (the ratio test across models drops votes), so it is off by default.
  bool library_wide_votes = false;
  int dense_stride_px = 2;  ///< scene depth points for the inlier count and ICP: every n-th pixel
  bool refine = true;       ///< point-to-plane ICP of accepted poses against the scene
  IcpOptions icp;
  /// Verification by rendering the model at the pose: of its pixels with a scene depth that are not hidden
  /// behind a nearer scene surface, the share within `depth_tolerance_m` of the scene ...
  double depth_tolerance_m = 0.015;
  /// ... and, of those, the share whose colour (through the model's colour matrix) lies within
  /// `color_tolerance` (RGB distance in [0, 1] units) of the scene's. score = depth share * colour share.
  double color_tolerance = 0.2;
  double min_score = 0.25;            ///< detections below are dropped
  double min_visible_fraction = 0.1;  ///< of the model's rendered pixels that the scene can show
  /// Apply a model's stored colour matrix (when it has one) to its view colours before matching (the views'
  /// descriptors are recomputed once, when the Recognizer is made) and to its rendered colours in verification.
  bool use_color_matrix = true;

  static RansacOptions DefaultRansac();
  /// Throws InputError on values outside their ranges.
  void Check() const;
};

/// One recognised object (the JSON of DESIGN.md "Interfaces").
struct Detection {
  std::string model;
  double score = 0.0;  ///< 0..1, higher is surer: depth agreement x colour agreement of the rendered model
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();
  double inlier_fraction = 0.0;   ///< RANSAC inliers over the visible view primitives
  double fit_error_m = 0.0;       ///< RANSAC mean inlier distance, metres
  int view = -1;                  ///< library view that matched
  double depth_agreement = 0.0;   ///< share of the visible rendered pixels on the scene surface
  double color_agreement = 0.0;   ///< share of those with the model's colour
  double visible_fraction = 0.0;  ///< share of the rendered pixels the scene can show (not hidden, with depth)
};

/// Detections of one frame and where the time went.
struct RecognitionResult {
  std::vector<Detection> detections;         ///< best score first, at most one per model
  std::map<std::string, double> timings_ms;  ///< per stage: extract, describe, match, ransac, refine, verify, total
  int scene_primitives = 0;
};

/// The detections JSON of DESIGN.md "Interfaces": {"detections": [{"model", "score", "camera_from_object",
/// "inlier_fraction", "fit_error", "view", ...}], "timings_ms": {stage: ms}}.
nlohmann::json RecognitionToJson(const RecognitionResult& result);

/// The detections of such JSON (model, score, camera_from_object); throws InputError naming `source` and the
/// field when one is missing or malformed.
std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source);

/// Finds the library's models in RGB-D frames. Owns an offscreen renderer (for verification) with the
/// models' meshes, loaded from the paths stored in the library. One Recognizer per thread.
class Recognizer {
 public:
  Recognizer(const ModelLibrary& library, const RecognizerOptions& options = {});
  ~Recognizer();
  Recognizer(const Recognizer&) = delete;
  Recognizer& operator=(const Recognizer&) = delete;

  RecognitionResult Recognize(const RgbdFrame& frame);

  /// `frame`'s colour image with each detected model rendered at its pose in red, outlined, with its name.
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ecv
