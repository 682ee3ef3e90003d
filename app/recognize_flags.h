#pragma once

// The flags `ecvpose recognize` and `ecvpose serve` share: the library, the recognizer's options and the stream's,
// and the set-up they describe.

#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "modeldb/model_library.h"
#include "recognize/recognizer.h"
#include "recognize/recognizer_settings.h"

namespace ecv::app {

/// The library and the settings table's flags (the recognizer's options and the stream's, as RecognizerSettings).
struct RecognizerArgs : RecognizerSettings {
  std::string db;
  std::vector<std::string> models;  ///< --models: only these (empty: all)
};

/// Declares --db, --models and a flag per setting of the table (recognizer_settings.h) on `command`; --threads
/// defaults to every core. The hidden --settings-json prints the table as JSON and exits.
void AddRecognizerFlags(CLI::App& command, RecognizerArgs* args);

/// The recognizer's options from the flags, checked (their ranges by the table as they are parsed, the rest by
/// RecognizerOptions::Check).
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
