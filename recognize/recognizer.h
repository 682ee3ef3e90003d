#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/frame.h"
#include "modeldb/model_library.h"
#include "recognize/detection.h"
#include "recognize/recognizer_options.h"

namespace ecv {

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

  /// BOP's localisation task (beyond the paper): only the models of `targets` (name -> instances in the frame, at
  /// least 1) are looked for, each for up to its count of instances whatever RecognizerOptions::max_instances says;
  /// a model that found fewer also reports the best pose its acceptance rejected (Detection::accepted false, after
  /// the accepted ones), so that every target gets an estimate when any pose was verified. Names not in the library
  /// are ignored.
  RecognitionResult RecognizeTargets(const RgbdFrame& frame, const std::map<std::string, int>& targets);

  /// View ranking alone, for studying it: every model's views as Recognize ranks them in `frame`, best first
  /// (RANSAC tries the first views_per_model of them).
  std::map<std::string, std::vector<RankedView>> RankViews(const RgbdFrame& frame);

  /// With point pair hypotheses (RecognizerOptions::point_pairs): per model that has no point pair table, because
  /// its mesh is too small, flat or coarse for point pairs, a line naming it and why; such a model is found by the
  /// context alone. (A library's stored points are made a table when first needed: one refused then, under options
  /// other than the library's, is listed from then on.)
  std::vector<std::string> PointPairWarnings() const;

  /// `frame`'s colour image with each detected model rendered at its pose in red, outlined, with its name.
  cv::Mat DrawDetections(const RgbdFrame& frame, const std::vector<Detection>& detections);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ecv
