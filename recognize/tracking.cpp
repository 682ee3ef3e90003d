#include "recognize/tracking.h"

#include <algorithm>

namespace ecv {

void AddInstance(Verified verified, int stride, const cv::Size& image_size, ModelInFrame* model) {
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
        confirm_every > 0 && std::any_of(model.instances.begin(), model.instances.end(), [&](const Verified& instance) {
          return instance.detection.frames_followed >= (instance.detection.confirmed ? confirm_every : confirm_first);
        });
    if (due) {
      model.to_confirm = std::move(model.instances);
      model.instances.clear();
      model.covered = cv::Mat();
    }
    model.search = due || (static_cast<int>(model.instances.size()) < max_instances &&
                           (scope == SearchScope::kAllModels || model.lost));
    count += model.search ? 1 : 0;
  }
  return count;
}

void MergeConfirmation(const cv::Size& image_size, double max_overlap, int max_instances, int stride,
                       ModelInFrame* model) {
  if (model->to_confirm.empty()) return;
  std::vector<Verified> candidates = std::move(model->to_confirm);
  model->to_confirm.clear();
  for (Verified& searched : model->instances) candidates.push_back(std::move(searched));
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Verified& a, const Verified& b) { return a.detection.score > b.detection.score; });
  model->instances.clear();
  model->covered = cv::Mat();
  for (Verified& candidate : candidates) {
    Verified* same_surface = nullptr;
    for (Verified& kept : model->instances) {
      if (SharedFraction(candidate.surface, kept.surface, image_size) > max_overlap) same_surface = &kept;
    }
    if (same_surface != nullptr) {
      if (same_surface->detection.tracked != candidate.detection.tracked) {
        same_surface->detection.frames_followed = 0;
        same_surface->detection.confirmed = true;
      }
      continue;
    }
    if (static_cast<int>(model->instances.size()) < max_instances) {
      AddInstance(std::move(candidate), stride, image_size, model);
    }
  }
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
