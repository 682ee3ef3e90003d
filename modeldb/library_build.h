#pragma once

#include <functional>
#include <string>
#include <vector>

#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"

namespace ecv {

/// What BuildLibrary says as it goes; any of them may be left empty.
struct LibraryBuildReporter {
  /// A model's build starts: its source and its place among them, 1..count.
  std::function<void(const ModelSource& source, int number, int count)> started;
  std::function<void(const ModelSource& source, const BuildProgress& progress)> progress;  ///< after each view
  /// The model is stored: what was built and how the library took it.
  std::function<void(const ModelSource& source, const BuildResult& built, const AddModelResult& added)> stored;
  /// The model could not be built or stored; `message` names the file and what was wrong.
  std::function<void(const ModelSource& source, const std::string& message)> failed;
};

/// The models BuildLibrary stored, and those it could not.
struct LibraryBuildSummary {
  std::vector<std::string> built;   ///< names
  std::vector<std::string> failed;  ///< names
};

/// Builds each of `sources` (BuildModel) and stores it in the library at `db_path`, created if missing and opened
/// before any rendering, so that a bad path fails at once (InputError or SqlError). Each model is stored in one
/// transaction and replaces a model of its name; one that fails (a bad mesh or texture, a library that refuses it,
/// any other exception of its build, such as running out of memory) is reported and the others are still built.
LibraryBuildSummary BuildLibrary(const std::string& db_path, const std::vector<ModelSource>& sources,
                                 const ModelBuildOptions& options, const LibraryBuildReporter& reporter = {});

/// What MergeLibraries says as it goes.
struct LibraryMergeReporter {
  /// A model was copied: its name, the library it came from, and its place among them, 1..count.
  std::function<void(const std::string& model, const std::string& shard, int number, int count)> copied;
};

/// Copies every model of the libraries `shard_paths` (e.g. the parts of a build split by `modeldb build --shard`)
/// into the library at `out_path`, created if missing: in name order, each model in one transaction with its colour
/// matrix, so that the result holds the same models, views, descriptors and content digests as one build of them
/// all. Checked before anything is written, each an InputError naming the libraries: every shard opens as a library
/// of the current schema; all have the same feature settings (as `out_path`, if it holds models); no model is in two
/// shards; `out_path` is none of them. A model of that name in `out_path` is replaced. Returns the models copied.
int MergeLibraries(const std::string& out_path, const std::vector<std::string>& shard_paths,
                   const LibraryMergeReporter& reporter = {});

}  // namespace ecv
