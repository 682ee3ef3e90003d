// The recognizer's settings table: each row reads and writes a field of its own, every value of its range is one the
// options' checks accept, values outside it are refused naming the flag and what was expected, and the CLI11 flags
// made from it set the options.

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/recognizer_settings.h"
#include "recognize/settings_flags.h"

namespace ecv {
namespace {

// A valid value of `setting` other than its default.
SettingValue OtherValue(const Setting& setting) {
  const SettingValue initial = setting.Default();
  switch (setting.type) {
    case SettingType::kFlag: return !std::get<bool>(initial);
    case SettingType::kChoice:
      return setting.choices.front() == std::get<std::string>(initial) ? setting.choices.back()
                                                                       : setting.choices.front();
    case SettingType::kCount: {
      const auto low = static_cast<int64_t>(setting.min);
      return low != std::get<int64_t>(initial) ? low : low + 1;
    }
    case SettingType::kNumber: break;
  }
  const double number = std::get<double>(initial);
  if (setting.min != number) return setting.min;
  return std::isfinite(setting.max) ? 0.5 * (setting.min + setting.max) : number + 1.0;
}

// What `setting.Parse(text, setting.Flag())` refuses with ("no error" when it accepts it).
std::string Refusal(const Setting& setting, const std::string& text) {
  try {
    setting.Parse(text, setting.Flag());
  } catch (const InputError& error) {
    return error.what();
  }
  return "no error";
}

TEST(RecognizerSettings, EachRowWritesTheFieldItReadsAndNoOther) {
  const std::vector<Setting>& table = RecognizerSettingTable();
  for (const Setting& setting : table) {
    RecognizerSettings settings;
    const SettingValue value = OtherValue(setting);
    setting.Set(value, setting.name, &settings);
    EXPECT_EQ(setting.get(settings), value) << setting.name;
    for (const Setting& other : table) {
      if (&other != &setting) {
        EXPECT_EQ(other.get(settings), other.Default()) << setting.name << " moved " << other.name;
      }
    }
  }
}

TEST(RecognizerSettings, EveryValueOfARangeIsOneTheOptionsAccept) {
  for (const Setting& setting : RecognizerSettingTable()) {
    std::vector<SettingValue> values;
    if (setting.type == SettingType::kCount) {
      values.emplace_back(static_cast<int64_t>(setting.min));
      if (std::isfinite(setting.max)) values.emplace_back(static_cast<int64_t>(setting.max));
    } else if (setting.type == SettingType::kNumber) {
      values.emplace_back(setting.min);
      if (std::isfinite(setting.max)) values.emplace_back(setting.max);
    } else if (setting.type == SettingType::kFlag) {
      values = {true, false};
    } else {
      values.assign(setting.choices.begin(), setting.choices.end());
    }
    for (const SettingValue& value : values) {
      RecognizerSettings settings;
      settings.stream.track = true;  // a search every n-th frame needs it
      setting.Set(value, setting.name, &settings);
      EXPECT_NO_THROW(CheckSettings(settings)) << setting.name << " = " << setting.Format(value);
    }
    EXPECT_NO_THROW(setting.Check(setting.Default(), setting.name)) << setting.name;
    if (setting.type == SettingType::kFlag) {
      EXPECT_EQ(setting.negated, std::get<bool>(setting.Default())) << setting.name;
    }
  }
}

TEST(RecognizerSettings, ValuesOutsideTheirRangeAreRefusedNamingTheFlag) {
  const Setting& views = *FindSetting("views-per-model");
  EXPECT_EQ(Refusal(views, "0"), "--views-per-model: expected a whole number of at least 1, got 0");
  EXPECT_EQ(Refusal(views, "2.5"), "--views-per-model: expected a whole number of at least 1, got 2.5");
  EXPECT_EQ(Refusal(views, ""), "--views-per-model: expected a whole number of at least 1, got nothing");
  EXPECT_EQ(Refusal(*FindSetting("threads"), "257"), "--threads: expected a whole number from 1 to 256, got 257");
  EXPECT_EQ(Refusal(*FindSetting("track-score"), "1.5"), "--track-score: expected a number in [0, 1], got 1.5");
  EXPECT_EQ(Refusal(*FindSetting("give-up-score"), "nan"), "--give-up-score: expected a number >= 0, got nan");
  EXPECT_EQ(Refusal(*FindSetting("hypotheses"), "shape"), "--hypotheses: expected context, ppf or both, got shape");
  EXPECT_EQ(Refusal(*FindSetting("search-every"), "1"), "no error");
  EXPECT_THROW(views.Check(3.0, "views_per_model"), InputError);  // a number where a whole number belongs
  EXPECT_EQ(FindSetting("views_per_model"), &views);
  EXPECT_EQ(FindSetting("no-such-setting"), nullptr);
  EXPECT_EQ(FindSetting("icp")->Flag(), "--no-icp");
  EXPECT_EQ(FindSetting("nearest-inliers")->Flag(), "--nearest-inliers");
  EXPECT_EQ(FindSetting("fast-icp")->Keyword(), "fast_icp");
}

TEST(SettingFlags, ParsedFlagsSetTheOptionsAndBadValuesAreUsageErrorsNamingTheFlag) {
  CLI::App app;
  RecognizerSettings settings;
  AddSettingFlags(app, &settings);
  app.parse(
      "--views-per-model 3 --no-icp --no-contour --nearest-inliers --hypotheses both --matcher bytes "
      "--track --search-every 4 --track-start-score 0.4 --depth-tolerance 0.02 --ppf-keep-plane");
  EXPECT_EQ(settings.options.views_per_model, 3);
  EXPECT_FALSE(settings.options.refine);
  EXPECT_EQ(settings.options.verify.contour_falloff, 0.0);
  EXPECT_FALSE(settings.options.projective_inliers);
  EXPECT_EQ(settings.options.point_pairs.source, HypothesisSource::kBoth);
  EXPECT_EQ(settings.options.match.index, MatchIndex::kBytes);
  EXPECT_TRUE(settings.stream.track);
  EXPECT_EQ(settings.stream.search_every, 4);
  EXPECT_EQ(settings.options.tracking.min_follow_score, 0.4);
  EXPECT_EQ(settings.options.verify.depth_tolerance_m, 0.02);
  EXPECT_FALSE(settings.options.point_pairs.remove_plane);
  EXPECT_NO_THROW(CheckSettings(settings));
  const auto usage_error = [](const std::string& arguments) {
    CLI::App other;
    RecognizerSettings ignored;
    AddSettingFlags(other, &ignored);
    try {
      other.parse(arguments);
    } catch (const CLI::ParseError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(usage_error("--views-per-model 0"), "--views-per-model: expected a whole number of at least 1, got 0");
  EXPECT_EQ(usage_error("--track-start-score 2"), "--track-start-score: expected a number in [0, 1], got 2");
  EXPECT_EQ(usage_error("--matcher flann"), "--matcher: expected kd-forest or bytes, got flann");
}

TEST(SettingFlags, ABenchFlagTakesSeveralValuesEachCheckedByTheTable) {
  CLI::App app;
  std::vector<int> every;
  std::vector<std::string> sources;
  AddSettingValues(app, "confirm-every", &every, "one run each");
  AddSettingValues(app, "hypotheses", &sources, "one run each");
  app.parse("--confirm-every 2 0 7 --hypotheses ppf both");
  EXPECT_EQ(every, (std::vector<int>{2, 0, 7}));
  EXPECT_EQ(sources, (std::vector<std::string>{"ppf", "both"}));
  CLI::App other;
  AddSettingValues(other, "confirm-every", &every, "one run each");
  EXPECT_THROW(other.parse("--confirm-every 2 -1"), CLI::ValidationError);
  EXPECT_THROW(AddSettingValues(other, "no-such-setting", &every, ""), std::logic_error);
}

}  // namespace
}  // namespace ecv
