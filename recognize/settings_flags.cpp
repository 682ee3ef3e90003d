#include "recognize/settings_flags.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "core/error.h"

namespace ecv {
namespace {

// "INT", "FLOAT", "TEXT": the value's type in the help.
const char* TypeName(SettingType type) {
  switch (type) {
    case SettingType::kCount: return "INT";
    case SettingType::kNumber: return "FLOAT";
    case SettingType::kFlag: return "BOOL";
    case SettingType::kChoice: return "TEXT";
  }
  return "TEXT";
}

const char* TypeWord(SettingType type) {
  switch (type) {
    case SettingType::kCount: return "count";
    case SettingType::kNumber: return "number";
    case SettingType::kFlag: return "flag";
    case SettingType::kChoice: return "choice";
  }
  return "choice";
}

// The range or the choices in the help, after the type: "[0 - 1]", "{context,ppf,both}"; "" for a lower bound only.
std::string Description(const Setting& setting) {
  std::ostringstream out;
  if (setting.type == SettingType::kChoice) {
    out << '{';
    for (size_t i = 0; i < setting.choices.size(); ++i) out << (i > 0 ? "," : "") << setting.choices[i];
    out << '}';
  } else if ((setting.type == SettingType::kCount || setting.type == SettingType::kNumber) &&
             std::isfinite(setting.max)) {
    out << '[' << setting.min << " - " << setting.max << ']';
  }
  return out.str();
}

nlohmann::json JsonValue(const SettingValue& value) {
  if (const auto* count = std::get_if<int64_t>(&value)) return *count;
  if (const auto* number = std::get_if<double>(&value)) return *number;
  if (const auto* flag = std::get_if<bool>(&value)) return *flag;
  return std::get<std::string>(value);
}

}  // namespace

CLI::Validator SettingCheck(const Setting& setting) {
  const Setting* row = &setting;  // the table's rows live as long as the program
  return CLI::Validator(
      [row](std::string& text) {
        try {
          row->Parse(text, row->name);
        } catch (const InputError&) {
          return "expected " + row->Expected() + ", got " + text;
        }
        return std::string();
      },
      Description(setting));
}

void AddSettingFlags(CLI::App& command, RecognizerSettings* settings, const std::vector<std::string>& except,
                     const std::string& group) {
  for (const Setting& setting : RecognizerSettingTable()) {
    if (std::find(except.begin(), except.end(), setting.name) != except.end()) continue;
    const Setting* row = &setting;
    CLI::Option* option = nullptr;
    if (setting.type == SettingType::kFlag) {
      option = command.add_flag_function(
          setting.Flag(), [row, settings](int64_t) { row->Set(!row->negated, row->Flag(), settings); }, setting.help);
    } else {
      option = command
                   .add_option_function<std::string>(
                       setting.Flag(),
                       [row, settings](const std::string& text) {
                         row->Set(row->Parse(text, row->Flag()), row->Flag(), settings);
                       },
                       setting.help)
                   ->type_name(TypeName(setting.type))
                   ->check(SettingCheck(setting))
                   ->default_str(setting.Format(setting.get(*settings)));
    }
    if (!group.empty()) option->group(group);
    for (const std::string& alias : setting.aliases) {
      // Hidden, so CLI11 would leave its name out of a check's message: the callback names it.
      const auto set_alias = [row, settings, flag = "--" + alias](const std::string& text) {
        try {
          row->Set(row->Parse(text, flag), flag, settings);
        } catch (const InputError& error) {
          throw CLI::ValidationError(error.what());
        }
      };
      command.add_option_function<std::string>("--" + alias, set_alias)->group("");
    }
  }
}

const Setting& TableSetting(const std::string& name) {
  const Setting* setting = FindSetting(name);
  if (setting == nullptr) throw std::logic_error("the recognizer's settings have no setting '" + name + "'");
  return *setting;
}

std::string SettingTableJson() {
  nlohmann::json table = nlohmann::json::array();
  for (const Setting& setting : RecognizerSettingTable()) {
    nlohmann::json row = {{"name", setting.name},
                          {"flag", setting.Flag()},
                          {"keyword", setting.Keyword()},
                          {"type", TypeWord(setting.type)},
                          {"default", JsonValue(setting.Default())},
                          {"expected", setting.Expected()},
                          {"help", setting.help},
                          {"aliases", setting.aliases}};
    if (setting.type == SettingType::kCount || setting.type == SettingType::kNumber) {
      row["min"] = setting.min;
      row["max"] = std::isfinite(setting.max) ? nlohmann::json(setting.max) : nlohmann::json();
    }
    if (setting.type == SettingType::kChoice) row["choices"] = setting.choices;
    table.push_back(row);
  }
  return table.dump(1);
}

}  // namespace ecv
