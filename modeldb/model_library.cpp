#include "modeldb/model_library.h"

#include <chrono>
#include <stdexcept>

#include "core/error.h"
#include "core/parallel.h"
#include "core/timing.h"

namespace ecv {
namespace {

// Builds every view's matcher; views are shared out to `threads` workers.
void BuildMatchers(std::vector<LibraryModel>* models, const LibraryLoadOptions& options) {
  std::vector<std::pair<size_t, size_t>> jobs;  // (model, view)
  for (size_t m = 0; m < models->size(); ++m) {
    (*models)[m].matchers.resize((*models)[m].record.views.size());
    for (size_t v = 0; v < (*models)[m].record.views.size(); ++v) jobs.emplace_back(m, v);
  }
  ParallelFor(jobs.size(), options.threads, [&](size_t job) {
    LibraryModel& model = (*models)[jobs[job].first];
    const ModelView& view = model.record.views[jobs[job].second];
    model.matchers[jobs[job].second] =
        std::make_unique<DescriptorMatcher>(view.primitives, view.descriptors, options.match);
  });
}

}  // namespace

void LibraryLoadOptions::Check() const {
  match.Check();
  CheckThreadCount("library load options", threads);
}

ModelLibrary ModelLibrary::Load(const ModelDatabase& database, const LibraryLoadOptions& options) {
  options.Check();
  ModelLibrary library;
  auto start = std::chrono::steady_clock::now();
  for (StoredModel& stored : database.LoadModels(options.names)) {
    library.models_.push_back({std::move(stored.record), std::move(stored.color_matrix), {}});
  }
  if (!library.models_.empty()) library.features_ = library.models_.front().record.features;
  library.timings_.read_ms = MillisecondsSince(start);
  start = std::chrono::steady_clock::now();
  if (options.build_matchers) BuildMatchers(&library.models_, options);
  library.timings_.index_ms = MillisecondsSince(start);
  start = std::chrono::steady_clock::now();
  if (options.build_library_index) library.BuildLibraryIndex(options.match);
  library.timings_.library_index_ms = MillisecondsSince(start);
  return library;
}

void ModelLibrary::BuildLibraryIndex(const MatchOptions& options) {
  std::vector<Primitive> primitives;  // every view's, one after another: the index's train set
  Descriptors all;
  std::vector<cv::Mat> values;
  for (size_t m = 0; m < models_.size(); ++m) {
    const std::vector<ModelView>& views = models_[m].record.views;
    for (size_t v = 0; v < views.size(); ++v) {
      const int offset = static_cast<int>(primitives.size());
      for (const int primitive : views[v].descriptors.primitive) all.primitive.push_back(offset + primitive);
      if (views[v].descriptors.values.rows > 0) values.push_back(views[v].descriptors.values);
      for (size_t p = 0; p < views[v].primitives.size(); ++p) {
        primitives.push_back(views[v].primitives[p]);
        index_origin_.push_back({static_cast<int>(m), static_cast<int>(v), static_cast<int>(p)});
      }
    }
  }
  if (values.empty()) {
    all.values.create(0, kDescriptorSize, CV_32F);
  } else {
    cv::vconcat(values, all.values);
  }
  library_index_ = std::make_unique<DescriptorMatcher>(primitives, all, options);
}

std::vector<LibraryMatch> ModelLibrary::MatchLibrary(const std::vector<Primitive>& query_primitives,
                                                     const Descriptors& query) const {
  if (!library_index_) throw std::logic_error("ModelLibrary::MatchLibrary: loaded without build_library_index");
  std::vector<LibraryMatch> matches;
  for (const DescriptorMatch& match : library_index_->Match(query_primitives, query)) {
    const std::array<int, 3>& origin = index_origin_[static_cast<size_t>(match.train)];
    matches.push_back({match.query, origin[0], origin[1], origin[2], match.distance, match.rank});
  }
  return matches;
}

ModelLibrary ModelLibrary::Load(const std::string& path, const LibraryLoadOptions& options) {
  const ModelDatabase database(path, OpenMode::kReadOnly);
  return Load(database, options);
}

const LibraryModel* ModelLibrary::Find(const std::string& name) const {
  for (const LibraryModel& model : models_) {
    if (model.record.name == name) return &model;
  }
  return nullptr;
}

int ModelLibrary::NumViews() const {
  int views = 0;
  for (const LibraryModel& model : models_) views += static_cast<int>(model.record.views.size());
  return views;
}

long long ModelLibrary::NumDescriptors() const {
  long long descriptors = 0;
  for (const LibraryModel& model : models_) descriptors += model.record.NumDescriptors();
  return descriptors;
}

}  // namespace ecv
