#include "recognize/tracking.h"

#include <algorithm>

namespace ecv {

void AddInstance(VerifiedPose verified, int stride, const cv::Size& image_size, ModelInFrame* model) {
  if (model->covered.empty()) model->covered = cv::Mat::zeros(image_size, CV_8UC1);
  CoverSurface(verified.surface, stride, &model->covered);
  model->instances.push_back(std::move(verified));
}

std::vector<ModelInFrame> AssignPriors(const std::vector<Detection>& priors,
                                       const std::vector<std::string>& model_names, const TrackingOptions& tracking) {
  std::vector<ModelInFrame> models(model_names.size());
  for (const Detection& prior : priors) {
    const auto name = std::find(model_names.begin(), model_names.end(), prior.model);
    if (name == model_names.end()) continue;
    ModelInFrame& model = models[static_cast<size_t>(name - model_names.begin())];
    if (prior.score >= tracking.min_follow_score) {
      model.priors.push_back(&prior);
    } else {
      model.lost = true;
    }
  }
  return models;
}

int ChooseModels(SearchScope scope, const TrackingOptions& tracking, int max_instances,
                 std::vector<ModelInFrame>* models) {
  const int confirm_every = tracking.confirm_every;
  const int confirm_first = tracking.confirm_first > 0 ? tracking.confirm_first : confirm_every;
  int count = 0;
  for (ModelInFrame& model : *models) {
    const bool due =
        scope != SearchScope::kPriorsOnly && confirm_every > 0 &&
        std::any_of(model.instances.begin(), model.instances.end(), [&](const VerifiedPose& instance) {
          return instance.detection.frames_followed >= (instance.detection.confirmed ? confirm_every : confirm_first);
        });
    if (due) {
      model.to_confirm = std::move(model.instances);
      model.instances.clear();
      model.covered = cv::Mat();
    }
    model.search = due || (static_cast<int>(model.instances.size()) < max_instances &&
                           (scope == SearchScope::kAllModels || (scope == SearchScope::kLostTracks && model.lost)));
    count += model.search ? 1 : 0;
  }
  return count;
}

void KeepBestFollowed(std::vector<Followed> followed, const cv::Size& image_size, double max_overlap, int max_instances,
                      int stride, ModelInFrame* model) {
  std::stable_sort(followed.begin(), followed.end(), [](const Followed& a, const Followed& b) {
    return a.verified.detection.score > b.verified.detection.score;
  });
  std::vector<bool> kept_from_search;  // per instance
  for (Followed& candidate : followed) {
    size_t same_surface = model->instances.size();
    for (size_t k = 0; k < model->instances.size(); ++k) {
      if (SharedFraction(candidate.verified.surface, model->instances[k].surface, image_size) > max_overlap) {
        same_surface = k;
      }
    }
    if (same_surface < model->instances.size()) {
      Detection& kept = model->instances[same_surface].detection;
      if (kept_from_search[same_surface] != candidate.from_search) {
        kept.frames_followed = std::min(kept.frames_followed, candidate.verified.detection.frames_followed);
        kept.confirmed = true;
      }
      continue;
    }
    if (static_cast<int>(model->instances.size()) < max_instances) {
      kept_from_search.push_back(candidate.from_search);
      AddInstance(std::move(candidate.verified), stride, image_size, model);
    }
  }
}

void MergeConfirmation(const cv::Size& image_size, double max_overlap, int max_instances, int stride,
                       ModelInFrame* model) {
  if (model->to_confirm.empty()) return;
  std::vector<Followed> candidates;  // the tracks, then the search's instances (from_search)
  for (VerifiedPose& track : model->to_confirm) candidates.push_back({std::move(track), false});
  for (VerifiedPose& searched : model->instances) candidates.push_back({std::move(searched), true});
  model->to_confirm.clear();
  model->instances.clear();
  model->covered = cv::Mat();
  KeepBestFollowed(std::move(candidates), image_size, max_overlap, max_instances, stride, model);
}

double SharedFraction(const std::vector<cv::Point>& surface, const std::vector<cv::Point>& other,
                      const cv::Size& image_size) {
  if (surface.empty()) return 0.0;
  cv::Mat mask = cv::Mat::zeros(image_size, CV_8UC1);
  for (const cv::Point& p : other) mask.at<uchar>(p) = 1;
  const auto shared =
      std::count_if(surface.begin(), surface.end(), [&](const cv::Point& p) { return mask.at<uchar>(p) != 0; });
  return static_cast<double>(shared) / static_cast<double>(surface.size());
}

}  // namespace ecv
