#pragma once

// The settings table (recognizer_settings.h) as CLI11 flags: those of `ecvpose recognize` and `serve`, and the
// benches'. A flag's check, help and default all come from the table's row.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "recognize/recognizer_settings.h"

namespace ecv {

/// The check of a flag's text against `setting`'s type and range: "expected <Expected()>, got <text>" (CLI11 puts
/// the flag's name first).
CLI::Validator SettingCheck(const Setting& setting);

/// Declares on `command` the flag of each setting of the table but those named in `except`, and its hidden old
/// spellings: a parsed value goes into `settings`, whose values the help shows as the defaults. `group`: the help's
/// heading over them (empty: the command's other options').
void AddSettingFlags(CLI::App& command, RecognizerSettings* settings, const std::vector<std::string>& except = {},
                     const std::string& group = "");

/// The setting called `name`; std::logic_error for a name the table lacks (a program's mistake).
const Setting& TableSetting(const std::string& name);

/// Declares the flag of the setting `name` as taking several values into `values`, each checked as the table says: for
/// a bench that runs once per value (`help` says what it does). The help shows the table's default. T: int, uint64_t
/// or std::string, as the setting holds.
template <typename T>
CLI::Option* AddSettingValues(CLI::App& command, const std::string& name, std::vector<T>* values,
                              const std::string& help) {
  const Setting& setting = TableSetting(name);
  return command.add_option(setting.Flag(), *values, help)
      ->check(SettingCheck(setting))
      ->default_str(setting.Format(setting.Default()));
}

/// The table as a JSON array, one object per setting: name, flag, keyword, type, default, min and max (null:
/// none) or choices, expected, help and aliases. What `ecvpose recognize --settings-json` prints for the tests.
std::string SettingTableJson();

}  // namespace ecv
