#pragma once

// The flags `ecvpose recognize` and `ecvpose serve` share: the library, the recognizer's options and the stream's,
// and the set-up they describe.

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "modeldb/model_library.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"

namespace ecv::app {

struct RecognizerArgs {
  std::string db;
  std::vector<std::string> models;  ///< --models: only these (empty: all)
  RecognizerOptions options;
  StreamOptions stream;  ///< --track, --search-every
  std::string matcher = "kd-forest";
};

/// Declares --db, --models and the search, tracking and verification flags on `command`.
void AddRecognizerFlags(CLI::App& command, RecognizerArgs* args);

/// The recognizer's options from the flags, checked: InputError naming the flag.
RecognizerOptions RecognizerOptionsFromArgs(const RecognizerArgs& args);

/// A library loaded as the flags say and a recognizer over it (the library first: the recognizer reads it).
struct LoadedRecognizer {
  std::unique_ptr<ModelLibrary> library;
  std::unique_ptr<Recognizer> recognizer;
};

/// Loads the library and makes the recognizer; says on stderr, after `tag` ("recognize", "serve"), what was loaded,
/// how descriptors are matched and which models have no point pair table. InputError for a library without models.
LoadedRecognizer LoadRecognizer(const RecognizerArgs& args, const RecognizerOptions& options, const std::string& tag);

}  // namespace ecv::app
