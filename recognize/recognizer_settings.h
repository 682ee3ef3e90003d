#pragma once

// The recognizer's settings in one table: per setting its name, type, range, help text and the field of
// RecognizerOptions or StreamOptions it reads and writes. The flags of `ecvpose recognize` and `serve`, the keywords
// of the Python Recognizer and the flags of the benches are made from it, so a row added in recognizer_settings.cpp
// appears in each; docs/how-it-works.md's tuning table needs the row too (tests/recognize/recognizer_settings.py).

#include <cstdint>
#include <functional>
#include <string>
#include <variant>
#include <vector>

#include "modeldb/model_library.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer_options.h"

namespace ecv {

/// What the settings table reads and writes: the recognizer's options and the stream's.
struct RecognizerSettings {
  RecognizerOptions options;
  StreamOptions stream;  ///< track, search_every, search_beside
};

enum class SettingType {
  kCount,   ///< a whole number, held as int64_t
  kNumber,  ///< a real number, held as double
  kFlag,    ///< on or off, held as bool
  kChoice,  ///< one of the setting's choices, held as std::string
};

/// A setting's value, of the alternative its type names.
using SettingValue = std::variant<int64_t, double, bool, std::string>;

/// One row of the table.
struct Setting {
  /// The CLI flag without "--" ("views-per-model"); the Python keyword is the same with '_' for '-'.
  std::string name;
  SettingType type = SettingType::kNumber;
  double min = 0.0;  ///< kCount, kNumber: the range, inclusive; max may be infinite
  double max = 0.0;
  std::vector<std::string> choices;  ///< kChoice: the names taken
  std::string help;                  ///< the CLI flag's help text
  /// kFlag: on by default, and the CLI flag is --no-NAME, which turns it off (--NAME turns an off flag on).
  bool negated = false;
  std::vector<std::string> aliases;  ///< further CLI names (without "--"), hidden from the help: old spellings
  std::function<SettingValue(const RecognizerSettings&)> get;
  std::function<void(const SettingValue&, RecognizerSettings*)> put;  ///< takes a checked value

  std::string Flag() const;     ///< "--views-per-model"; "--no-icp" for a negated flag
  std::string Keyword() const;  ///< "views_per_model", "icp"
  /// What a value must be: "a whole number of at least 1", "a number in [0, 1]", "context, ppf or both".
  std::string Expected() const;
  /// Its value in default-constructed settings.
  SettingValue Default() const { return get(RecognizerSettings()); }
  /// `text` read as the setting's type and checked; InputError "<what>: expected <Expected()>, got <text>".
  SettingValue Parse(const std::string& text, const std::string& what) const;
  /// Throws InputError naming `what` when `value` is not of the setting's type or lies outside its range.
  void Check(const SettingValue& value, const std::string& what) const;
  /// Checks `value` (naming `what`) and writes it into `settings`.
  void Set(const SettingValue& value, const std::string& what, RecognizerSettings* settings) const;
  /// "10", "0.3", "true", "context": as the CLI takes it (flags: "true" or "false").
  std::string Format(const SettingValue& value) const;
};

/// Every setting, in the order the CLI's help lists them.
const std::vector<Setting>& RecognizerSettingTable();

/// The setting called `name` (its CLI name, or the Python keyword), or nullptr.
const Setting* FindSetting(const std::string& name);

/// RecognizerOptions::Check and StreamOptions::Check: what the table's ranges cannot see (settings that depend on
/// each other, fields with no row).
void CheckSettings(const RecognizerSettings& settings);

/// Throws InputError naming `library_path` when `library` has no model: there is nothing to recognise.
void RequireModels(const ModelLibrary& library, const std::string& library_path);

}  // namespace ecv
