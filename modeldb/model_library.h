#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ecv/matching.h"
#include "modeldb/model_database.h"

namespace ecv {

/// What to load from a library for recognition.
struct LibraryLoadOptions {
  std::vector<std::string> names;  ///< models to load; empty = all
  bool build_matchers = true;      ///< build a DescriptorMatcher per view (train = that view's descriptors)
  /// Also build one index over the descriptors of every view of every model (MatchLibrary): one query finds
  /// the nearest library descriptors whatever the library's size, e.g. to vote for candidate models and views.
  bool build_library_index = false;
  MatchOptions match;  ///< settings of those matchers
  int threads = 1;     ///< threads building the matchers (1 to kMaxThreads)

  void Check() const;
};

/// One model ready for recognition.
struct LibraryModel {
  ModelRecord record;                             ///< views with primitives (object frame), descriptors
  std::optional<ColorMatrixRecord> color_matrix;  ///< c_scene = A c_model, if calibrated
  /// One per view, train = the view's primitives and descriptors (empty without build_matchers).
  std::vector<std::unique_ptr<DescriptorMatcher>> matchers;
};

/// Time of a load, milliseconds.
struct LibraryLoadTimings {
  double read_ms = 0.0;           ///< reading the rows (one transaction)
  double index_ms = 0.0;          ///< building the per-view matchers
  double library_index_ms = 0.0;  ///< building the index over the whole library
};

/// A query descriptor matched into the whole library.
struct LibraryMatch {
  int query = -1;      ///< index into the query primitives
  int model = -1;      ///< index into ModelLibrary::models()
  int view = -1;       ///< index into that model's views
  int primitive = -1;  ///< index into that view's primitives
  float distance = 0.0F;
  int rank = 0;  ///< 0 for the nearest, 1 for the second, ...
};

/// The models of a library loaded once, with their matching indices, for the recognizer. Read-only after
/// loading: several threads may query the matchers at once.
class ModelLibrary {
 public:
  /// Loads from an open database.
  static ModelLibrary Load(const ModelDatabase& database, const LibraryLoadOptions& options = {});
  /// Opens `path` read-only and loads from it.
  static ModelLibrary Load(const std::string& path, const LibraryLoadOptions& options = {});

  const std::vector<LibraryModel>& models() const { return models_; }
  /// The model called `name`; nullptr when it was not loaded.
  const LibraryModel* Find(const std::string& name) const;
  /// Settings to extract scene features with (those the models were built with); defaults for no models.
  const FeatureSettings& feature_settings() const { return features_; }
  const LibraryLoadTimings& timings() const { return timings_; }

  int NumViews() const;
  long long NumDescriptors() const;

  /// The `match.k` nearest library descriptors (over every view of every model; of the same primitive type
  /// when structure-specific) of each query descriptor. Throws std::logic_error unless loaded with
  /// build_library_index.
  std::vector<LibraryMatch> MatchLibrary(const std::vector<Primitive>& query_primitives,
                                         const Descriptors& query) const;

 private:
  void BuildLibraryIndex(const MatchOptions& options);

  std::vector<LibraryModel> models_;
  std::unique_ptr<DescriptorMatcher> library_index_;
  std::vector<std::array<int, 3>> index_origin_;  // (model, view, primitive) of each row of the library index
  FeatureSettings features_;
  LibraryLoadTimings timings_;
};

}  // namespace ecv
