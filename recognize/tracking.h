#pragma once

// The state of each model in one frame and the tracking rules on it: which priors are followed, which models are
// searched, and how a confirming search's instances and the tracks it set aside are merged. No rendering: the
// recognizer verifies, these functions decide.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "recognize/detection.h"
#include "recognize/model_search.h"
#include "recognize/recognizer_options.h"

namespace ecv {

/// One model in one frame: the priors to follow, the instances found so far (tracked, then searched) and the scene
/// pixels their surfaces cover, and whether it is still to be searched by view ranking and RANSAC.
struct ModelInFrame {
  std::vector<const Detection*> priors;
  std::vector<VerifiedPose> instances;
  cv::Mat covered;    ///< CV_8UC1 of the frame's size once an instance is added: its surfaces (CoverSurface)
  bool lost = false;  ///< seen before: a prior failed or scored too low to follow
  bool search = false;
  /// Tracked instances due for confirmation, set aside while their model is searched as if it had no priors.
  std::vector<VerifiedPose> to_confirm;
  std::vector<JudgedPose> judged;             ///< with RecognizerOptions::keep_judged: the poses its acceptance judged
  int max_instances = 1;                      ///< instances looked for in this frame (a search stops at as many)
  std::optional<VerifiedPose> best_rejected;  ///< the best-scoring pose its acceptance turned down
};

/// Adds `verified` to `model`'s instances and its surface (sampled every `stride` pixels) to the covered pixels.
void AddInstance(VerifiedPose verified, int stride, const cv::Size& image_size, ModelInFrame* model);

/// Each model's priors to follow (models in the order of `model_names`), in their order. A prior below
/// tracking.min_follow_score is not followed but makes its model `lost`: it was seen, so even a frame that searches
/// only for lost tracks searches for it. Priors of models not named are ignored.
std::vector<ModelInFrame> AssignPriors(const std::vector<Detection>& priors,
                                       const std::vector<std::string>& model_names, const TrackingOptions& tracking);

/// An instance followed from a prior (Recognizer's Track), and whether that prior was a search's detection rather than
/// a track: one followed from the previous frame's search, or from a search that ran beside the tracking.
struct Followed {
  VerifiedPose verified;
  bool from_search = false;
};

/// Makes `model`'s instances (it has none yet) the best of those followed from its priors: best first, each kept
/// unless it lies mostly (`max_overlap`) on a kept one's surface, up to `max_instances`, so that a search's detection
/// given as a prior beside a track competes with it on score. A kept one on whose surface one of the other kind lay (a
/// track and a search's detection) is confirmed (Detection::confirmed), its frames_followed the smaller of theirs.
void KeepBestFollowed(std::vector<Followed> followed, const cv::Size& image_size, double max_overlap, int max_instances,
                      int stride, ModelInFrame* model);

/// Marks the models to search in this frame: those with fewer than `max_instances` instances (under kLostTracks only
/// lost ones, under kPriorsOnly none), and those with a track due for confirmation (followed tracking.confirm_every
/// frames, or tracking.confirm_first while no search has confirmed it; never under kPriorsOnly), whose tracked
/// instances are set aside meanwhile. Returns their count.
int ChooseModels(SearchScope scope, const TrackingOptions& tracking, int max_instances,
                 std::vector<ModelInFrame>* models);

/// A confirming search's instances and the tracked ones it set aside compete on score: best first, each kept unless
/// it lies mostly (`max_overlap`) on a kept one's surface, up to `max_instances`. A kept track that a searched
/// instance lay on is confirmed (Detection::confirmed; its count starts again); a track the search did not find
/// keeps counting, so its model is searched again in the next frame. Nothing to do for a model without tracks set
/// aside.
void MergeConfirmation(const cv::Size& image_size, double max_overlap, int max_instances, int stride,
                       ModelInFrame* model);

/// The share of `surface`'s pixels that `other` covers too (0 for an empty surface).
double SharedFraction(const std::vector<cv::Point>& surface, const std::vector<cv::Point>& other,
                      const cv::Size& image_size);

}  // namespace ecv
