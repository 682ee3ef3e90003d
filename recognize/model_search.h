#pragma once

// One model's search in one frame: view ranking, matching, RANSAC per view, verification and ICP of the best
// poses. Internal to the recognizer.

#include <functional>
#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "modeldb/model_record.h"
#include "recognize/detection.h"
#include "recognize/scene.h"

namespace ecv {

/// A pose hypothesis of a model from one of its views.
struct Hypothesis {
  int view = -1;
  RansacResult ransac;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A verified pose: the detection, the frame pixels (at dense_stride_px) where its rendered surface lies on the
/// scene's, which overlap suppression compares, and the rendered depth, from which ICP takes the model's surface.
struct VerifiedPose {
  Detection detection;
  /// The score without the continuation factor, by which the search chooses among coarse poses: before ICP a pose is
  /// often a few pixels off, and its outline then lies on its own object's surface.
  double search_score = 0.0;
  std::vector<cv::Point> surface;
  cv::Mat depth;
};

/// Renders, measures and scores a pose of the searched model (Recognizer's verification).
using VerifyPose = std::function<VerifiedPose(const Hypothesis&)>;

/// A model view ranked by its consistent correspondences; once tried, its RANSAC pose, verified.
struct ViewCandidate {
  int view = -1;
  int score = 0;
  /// The nearest scene primitive of each of its descriptors once `matched`; before, of its ranking subset only.
  std::vector<Correspondence> correspondences;
  bool matched = false;
  bool tried = false;  ///< RANSAC ran on it (and `verified` is its pose, if any)
  std::optional<Hypothesis> hypothesis;
  std::optional<VerifiedPose> verified;
};

/// Searches one model in one scene. Holds references only: `record`, `options`, `scene` must outlive it.
class ModelSearch {
 public:
  /// `ransac_threads`: threads of each RANSAC (the models share the recognizer's workers out).
  ModelSearch(const ModelRecord& record, const RecognizerOptions& options, const Scene& scene, VerifyPose verify,
              int ransac_threads);

  /// The model's views, best ranked first, each with the correspondences of its ranking subset of descriptors.
  std::vector<ViewCandidate> RankViews() const;

  /// The model's best pose over its best `count` views in `ranked` (fewer once one is good enough, or when the
  /// first `give_up_after` show none at give_up_below_score; 0: never give up): RANSAC per view, each pose verified
  /// (once per view and frame, kept in `ranked`); of those not lying mostly (max_overlap) on `covered` pixels, the
  /// best and its turned rival refined by ICP and verified again, the better kept. Adds stage times.
  std::optional<VerifiedPose> BestPose(int count, int give_up_after, const cv::Mat& covered,
                                       std::vector<ViewCandidate>* ranked, StageTimes* times) const;

  /// Point-to-plane ICP of the model's surface as rendered at the pose (`rendered_depth`, at dense_stride_px)
  /// against the scene points near it; the pose is kept when ICP fails.
  void Refine(const cv::Mat& rendered_depth, Hypothesis* hypothesis) const;

 private:
  struct RowSplit {
    std::vector<int> ranking, rest;
  };
  RowSplit RankingRows(size_t view) const;
  std::vector<Correspondence> Correspondences(const ModelView& view, const Descriptors& descriptors,
                                              int checks = 0) const;
  void Match(ViewCandidate* candidate) const;
  void Try(ViewCandidate* candidate, StageTimes* times) const;
  const ViewCandidate* TurnedRival(const std::vector<ViewCandidate>& ranked, int count, const ViewCandidate& best,
                                   const cv::Mat& covered) const;
  ConsistencyOptions Consistency() const;

  const ModelRecord& record_;
  const RecognizerOptions& options_;
  const Scene& scene_;
  VerifyPose verify_;
  int ransac_threads_;
};

/// Marks on `covered` (CV_8UC1, the frame's size) the pixels of a verified surface sampled every `stride` pixels,
/// with the gaps between the samples closed.
void CoverSurface(const std::vector<cv::Point>& surface, int stride, cv::Mat* covered);

/// The share of a verified surface's pixels that are non-zero on `covered` (0 when either is empty).
double CoveredShare(const std::vector<cv::Point>& surface, const cv::Mat& covered);

}  // namespace ecv
