#include "recognize/recognizer_settings.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <type_traits>
#include <utility>

#include "core/error.h"
#include "core/parallel.h"

namespace ecv {
namespace {

constexpr double kNoMax = std::numeric_limits<double>::infinity();

// The type of the field that `field` (a lambda taking the settings) leads to.
template <typename Field>
using FieldType = std::remove_reference_t<decltype(std::declval<Field>()(std::declval<RecognizerSettings&>()))>;

// A row without its range and accessors.
Setting Row(const char* name, SettingType type, const char* help) {
  Setting setting;
  setting.name = name;
  setting.type = type;
  setting.help = help;
  return setting;
}

// A whole-number setting in [min, max], held in the field `field` returns.
template <typename Field>
Setting Count(const char* name, double min, double max, const char* help, Field field) {
  Setting setting = Row(name, SettingType::kCount, help);
  setting.min = min;
  setting.max = max;
  setting.get = [field](const RecognizerSettings& s) -> SettingValue { return static_cast<int64_t>(field(s)); };
  setting.put = [field](const SettingValue& value, RecognizerSettings* s) {
    field(*s) = static_cast<FieldType<Field>>(std::get<int64_t>(value));
  };
  return setting;
}

// A real-number setting in [min, max], held in the field `field` returns.
template <typename Field>
Setting Number(const char* name, double min, double max, const char* help, Field field) {
  Setting setting = Row(name, SettingType::kNumber, help);
  setting.min = min;
  setting.max = max;
  setting.get = [field](const RecognizerSettings& s) -> SettingValue { return static_cast<double>(field(s)); };
  setting.put = [field](const SettingValue& value, RecognizerSettings* s) { field(*s) = std::get<double>(value); };
  return setting;
}

// An on/off setting read by `get` and written by `put` (a field inverted or a factor turned off); `negated`: the CLI
// flag is --no-NAME.
template <typename Get, typename Put>
Setting FlagOf(const char* name, bool negated, const char* help, Get get, Put put) {
  Setting setting = Row(name, SettingType::kFlag, help);
  setting.negated = negated;
  setting.get = [get](const RecognizerSettings& s) -> SettingValue { return static_cast<bool>(get(s)); };
  setting.put = [put](const SettingValue& value, RecognizerSettings* s) { put(*s, std::get<bool>(value)); };
  return setting;
}

// An on/off setting held in the bool field `field` returns.
template <typename Field>
Setting Flag(const char* name, bool negated, const char* help, Field field) {
  return FlagOf(
      name, negated, help, [field](const RecognizerSettings& s) { return field(s); },
      [field](RecognizerSettings& s, bool on) { field(s) = on; });
}

// A setting taking one of `choices`, read by `get` and written by `put` (both with the choice's name).
template <typename Get, typename Put>
Setting Choice(const char* name, std::vector<std::string> choices, const char* help, Get get, Put put) {
  Setting setting = Row(name, SettingType::kChoice, help);
  setting.choices = std::move(choices);
  setting.get = [get](const RecognizerSettings& s) -> SettingValue { return std::string(get(s)); };
  setting.put = [put](const SettingValue& value, RecognizerSettings* s) { put(*s, std::get<std::string>(value)); };
  return setting;
}

// InputError "<what>: expected <the setting's Expected()>, got <text>".
[[noreturn]] void Refuse(const Setting& setting, const std::string& text, const std::string& what) {
  ThrowInputError(what, "", setting.Expected(), text.empty() ? "nothing" : text);
}

std::string FormatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// The rows, in the order of the CLI's help. A field becomes a setting with one row: Count or Number (name, range, help,
// a lambda giving the field), Flag (a bool field; `negated`: on by default, --no-NAME), FlagOf and Choice (a getter and
// a setter, for values that are not a field as they are).

// The search: views, models, hypotheses, threads, refinement.
void AddSearchSettings(std::vector<Setting>* table) {
  table->push_back(Count(
      "views-per-model", 1, kNoMax, "Library views tried with RANSAC per model",
      [](auto& s) -> auto& { return s.options.views_per_model; }));
  table->push_back(Number(
      "good-enough-score", 0, kNoMax,
      "A model's remaining views are skipped once one verifies at this score (0: try them all)",
      [](auto& s) -> auto& { return s.options.good_enough_score; }));
  table->push_back(Count(
      "give-up-after", 0, kNoMax,
      "A model's remaining views are skipped when its first N all verify below --give-up-score:\n"
      "it is taken to be absent (0: try --views-per-model views)",
      [](auto& s) -> auto& { return s.options.give_up_after_views; }));
  table->push_back(Number(
      "give-up-score", 0, kNoMax, "See --give-up-after; a model's best pose below it is not turned (twins)",
      [](auto& s) -> auto& { return s.options.give_up_below_score; }));
  table->push_back(Count(
      "preselect", 0, kNoMax,
      "Search only the N models whose best view ranks highest in a quick ranking of every model's views\n"
      "(100 descriptors a view, 32 checks; meshes loaded on first use): a library of more models costs\n"
      "about what one of N does beyond that ranking (0: search every model)",
      [](auto& s) -> auto& { return s.options.preselect.models; }));
  table->push_back(Count(
      "preselect-shape", 0, kNoMax,
      "With --preselect: also search by point pairs alone the N models left out whose shape best fits\n"
      "the surface no detection explains (a coarse point pair table of each voted there; 0: none)",
      [](auto& s) -> auto& { return s.options.preselect.shape_models; }));
  table->push_back(Count(
      "ranking-checks", 0, kNoMax,
      "Descriptors compared per query when ranking the library's views (0: as many as matching, 128);\n"
      "32 ranks in half the time, less well",
      [](auto& s) -> auto& { return s.options.ranking.checks; }));
  table->push_back(Number(
      "min-score", 0, 1, "Detections below this score are dropped",
      [](auto& s) -> auto& { return s.options.verify.min_score; }));
  table->push_back(Count(
      "max-instances", 1, kNoMax, "Instances of one model looked for per frame (e.g. a bin of identical parts)",
      [](auto& s) -> auto& { return s.options.max_instances; }));
  std::vector<std::string> sources;
  for (const HypothesisSource source : {HypothesisSource::kContext, HypothesisSource::kPpf, HypothesisSource::kBoth}) {
    sources.emplace_back(HypothesisSourceName(source));
  }
  table->push_back(Choice(
      "hypotheses", sources,
      "Where poses come from: context (shape and appearance context descriptors, view ranking and RANSAC),\n"
      "ppf (point pair features of the model's surface: shape alone) or both (point pairs for the models the\n"
      "context does not find: objects that show a plain side)",
      [](const RecognizerSettings& s) { return HypothesisSourceName(s.options.point_pairs.source); },
      [](RecognizerSettings& s, const std::string& name) {
        s.options.point_pairs.source = ParseHypothesisSource(name, "hypotheses");
      }));
  table->push_back(Choice(
      "acceptance", {AcceptanceName(Acceptance::kHandSet), AcceptanceName(Acceptance::kLearned)},
      "How a verified pose becomes a detection: hand (its score at least --min-score) or learned (a model of\n"
      "every evidence term, trained on generated scenes, says it is right; the score is still reported)",
      [](const RecognizerSettings& s) { return AcceptanceName(s.options.acceptance); },
      [](RecognizerSettings& s, const std::string& name) {
        s.options.acceptance = ParseAcceptance(name, "acceptance");
      }));
  table->push_back(Count(
      "seed", 0, kNoMax, "Random seed", [](auto& s) -> auto& { return s.options.ransac.seed; }));
  table->push_back(Count(
      "threads", 1, kMaxThreads,
      "Worker threads for describing the scene and searching the models, one model each (same result for any count)",
      [](auto& s) -> auto& { return s.options.threads; }));
  table->push_back(Flag(
      "icp", true, "Skip the ICP refinement", [](auto& s) -> auto& { return s.options.refine; }));
}

// Tracking objects from frame to frame.
void AddTrackingSettings(std::vector<Setting>* table) {
  table->push_back(Flag(
      "track", false,
      "Try each object first at its pose in the previous frame (refined and verified); objects tracked\n"
      "so skip view ranking and RANSAC",
      [](auto& s) -> auto& { return s.stream.track; }));
  table->push_back(Count(
      "search-every", 1, kNoMax,
      "With --track: models not tracked are searched on every N-th frame only (the first, 1 + N, ...;\n"
      "after a broken frame, the next); in between, the tracked objects are followed and a lost one is\n"
      "searched for at once",
      [](auto& s) -> auto& { return s.stream.search_every; }));
  table->push_back(Flag(
      "search-beside", false,
      "With --track: the search runs on a thread of its own beside the tracking (--threads shared: on 2,\n"
      "one tracks, one searches); each frame only follows the objects it knows, and a finished search's\n"
      "detections join the next frame's (new objects are found a few frames late)",
      [](auto& s) -> auto& { return s.stream.search_beside; }));
  Setting score = Number(
      "track-score", 0, 1,
      "With --track: a detection is followed into the next frame only while it scores at least this,\n"
      "a first detection and a followed one alike",
      [](auto& s) -> auto& { return s.options.tracking.min_follow_score; });
  score.aliases = {"track-start-score"};
  table->push_back(std::move(score));
  table->push_back(Count(
      "confirm-every", 0, kNoMax,
      "With --track: an object followed this many frames since a search last found it has its model\n"
      "searched again; the better of the two poses is kept (0: never)",
      [](auto& s) -> auto& { return s.options.tracking.confirm_every; }));
  table->push_back(Count(
      "confirm-first", 0, kNoMax,
      "With --track: the same for an object no search has found again since the one that first found\n"
      "it (1: in the next frame; 0: as --confirm-every)",
      [](auto& s) -> auto& { return s.options.tracking.confirm_first; }));
}

// Verification, RANSAC's inliers, matching and ICP.
void AddVerifySettings(std::vector<Setting>* table) {
  table->push_back(FlagOf(
      "contour", true,
      "Verify without the contour factor (a pose's outline on the scene's depth steps): for flat objects thinner\n"
      "than 1 cm lying on a surface, or parts packed flush in a tray",
      [](const RecognizerSettings& s) { return s.options.verify.contour_falloff > 0.0; },
      [](RecognizerSettings& s, bool on) {
        s.options.verify.contour_falloff = on ? VerifyOptions().contour_falloff : 0.0;
      }));
  table->push_back(Number(
      "continuation-free", 0, 1,
      "The continuation factor is 1 up to this share of a pose's outline across which the scene's surface\n"
      "runs on, falling to 0 above (see --no-continuation): lower rejects more models covering part of\n"
      "a larger surface, and more objects touching a neighbour flush",
      [](auto& s) -> auto& { return s.options.verify.continuation_free; }));
  table->push_back(FlagOf(
      "continuation", true,
      "Verify without the continuation factor (the scene's surface running on across a pose's outline):\n"
      "for objects packed flush against each other or sunk into a surface",
      [](const RecognizerSettings& s) { return s.options.verify.continuation_falloff > 0.0; },
      [](RecognizerSettings& s, bool on) {
        s.options.verify.continuation_falloff = on ? VerifyOptions().continuation_falloff : 0.0;
      }));
  table->push_back(Number(
      "plain-appearance", 0, 1,
      "The appearance term of a model without texture or vertex colours (a grey CAD mesh), judged by its\n"
      "geometry instead (0: by its colours, as any model)",
      [](auto& s) -> auto& { return s.options.verify.plain_appearance; }));
  table->push_back(Number(
      "edge-weight", 0, 1,
      "Weight of the texture edges against the colour correlation in verification (0: colour alone)",
      [](auto& s) -> auto& { return s.options.verify.edge_weight; }));
  table->push_back(FlagOf(
      "nearest-inliers", false,
      "RANSAC finds an object point's inlier partner by a search among the scene's points in 3D (the paper)\n"
      "instead of among the depth samples around where the point is seen",
      [](const RecognizerSettings& s) { return !s.options.projective_inliers; },
      [](RecognizerSettings& s, bool nearest) { s.options.projective_inliers = !nearest; }));
  table->push_back(Choice(
      "matcher", {"kd-forest", "bytes"},
      "kd-forest (FLANN's randomised kd-trees, approximate: the same matches on every CPU) or bytes\n"
      "(every scene descriptor compared over 7-bit values: nearer neighbours, 2x faster where the CPU\n"
      "has AVX-512 VNNI, 20x slower where it has not)",
      [](const RecognizerSettings& s) { return s.options.match.index == MatchIndex::kBytes ? "bytes" : "kd-forest"; },
      [](RecognizerSettings& s, const std::string& name) {
        s.options.match.index = name == "bytes" ? MatchIndex::kBytes : MatchIndex::kKdForest;
      }));
  table->push_back(Flag(
      "fast-icp", false, "ICP pairs points along the camera's rays (7x faster refinement, finds fewer objects)",
      [](auto& s) -> auto& { return s.options.projective_icp; }));
}

// Settings once reached from C++ only: verification's tolerances, overlaps, rivals, later instances, point pairs.
void AddFurtherSettings(std::vector<Setting>* table) {
  table->push_back(Number(
      "min-visible-fraction", 0, 1,
      "Poses of which the scene can show less than this share (the rest hidden or without depth)\n"
      "are not detections",
      [](auto& s) -> auto& { return s.options.verify.min_visible_fraction; }));
  table->push_back(Number(
      "depth-tolerance", 0.001, 0.1,
      "Metres: a rendered pixel lies on the scene's surface when their depths differ by at most this,\n"
      "and a scene surface further in front hides it",
      [](auto& s) -> auto& { return s.options.verify.depth_tolerance_m; }));
  table->push_back(Number(
      "contour-free", 0, 1,
      "The contour factor is 1 from this share of a pose's seen outline on the scene's depth steps on,\n"
      "falling to 0 below (see --no-contour)",
      [](auto& s) -> auto& { return s.options.verify.contour_free; }));
  table->push_back(Number(
      "max-overlap", 0, 1,
      "A detection lying for more than this share on pixels that a better detection of another model\n"
      "explains is dropped (one surface, one object)",
      [](auto& s) -> auto& { return s.options.max_overlap; }));
  table->push_back(Number(
      "rival-min-ratio", 0, 1,
      "A model's best pose turned more than 90 degrees from its best verified one is refined and verified\n"
      "too when it scored at least this share of the best (0: never); a point pair cluster is refined\n"
      "when it scored this share of the model's best cluster",
      [](auto& s) -> auto& { return s.options.rival_min_ratio; }));
  table->push_back(Flag(
      "twins", true,
      "Do not verify each searched model's best pose turned 180 degrees about the model's principal axes\n"
      "(a box's front and back fit the depth alike: its colours and edges tell them apart)",
      [](auto& s) -> auto& { return s.options.twins.enabled; }));
  table->push_back(Count(
      "later-instance-views", 0, kNoMax,
      "With --max-instances: views tried for each instance after a model's first (0: --views-per-model)",
      [](auto& s) -> auto& { return s.options.later_instance_views; }));
  table->push_back(Count(
      "icp-max-points", 0, kNoMax,
      "ICP takes at most this many points of the model's surface rendered at the pose (0: all)",
      [](auto& s) -> auto& { return s.options.icp_max_points; }));
  table->push_back(Count(
      "ppf-clusters", 1, kNoMax,
      "With --hypotheses ppf or both: the point pair pose clusters verified per model, most votes first",
      [](auto& s) -> auto& { return s.options.point_pairs.clusters; }));
  table->push_back(Number(
      "ppf-reference-spacing", 0.01, 1,
      "With --hypotheses ppf or both: point pair reference points, one per voxel of this share of the\n"
      "model's diameter and differing normal (smaller: more votes, at more time)",
      [](auto& s) -> auto& { return s.options.point_pairs.ppf.reference_spacing; }));
  table->push_back(FlagOf(
      "ppf-keep-plane", false,
      "With --hypotheses ppf or both: the scene's dominant plane (a table top) votes too (default: left out)",
      [](const RecognizerSettings& s) { return !s.options.point_pairs.remove_plane; },
      [](RecognizerSettings& s, bool keep) { s.options.point_pairs.remove_plane = !keep; }));
}

std::vector<Setting> MakeTable() {
  std::vector<Setting> table;
  AddSearchSettings(&table);
  AddTrackingSettings(&table);
  AddVerifySettings(&table);
  AddFurtherSettings(&table);
  return table;
}

}  // namespace

std::string Setting::Flag() const {
  return (negated ? "--no-" : "--") + name;
}

std::string Setting::Keyword() const {
  std::string keyword = name;
  for (char& c : keyword) c = c == '-' ? '_' : c;
  return keyword;
}

std::string Setting::Expected() const {
  const bool bounded = std::isfinite(max);
  switch (type) {
    case SettingType::kCount:
      return "a whole number " +
             (bounded ? "from " + FormatNumber(min) + " to " + FormatNumber(max) : "of at least " + FormatNumber(min));
    case SettingType::kNumber:
      return "a number " +
             (bounded ? "in [" + FormatNumber(min) + ", " + FormatNumber(max) + "]" : ">= " + FormatNumber(min));
    case SettingType::kFlag: return "true or false";
    case SettingType::kChoice: break;
  }
  std::string names;
  for (size_t i = 0; i < choices.size(); ++i) {
    names += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
  }
  return names;
}

SettingValue Setting::Parse(const std::string& text, const std::string& what) const {
  char* end = nullptr;
  errno = 0;
  SettingValue value = text;  // kChoice
  if (type == SettingType::kCount) {
    const long long count = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE) Refuse(*this, text, what);
    value = static_cast<int64_t>(count);
  } else if (type == SettingType::kNumber) {
    const double number = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(number)) Refuse(*this, text, what);
    value = number;
  } else if (type == SettingType::kFlag) {
    if (text != "true" && text != "false") Refuse(*this, text, what);
    value = text == "true";
  }
  Check(value, what);
  return value;
}

void Setting::Check(const SettingValue& value, const std::string& what) const {
  const auto in_range = [&](double x) { return std::isfinite(x) && x >= min && x <= max; };
  bool ok = false;
  switch (type) {
    case SettingType::kCount:
      ok = std::holds_alternative<int64_t>(value) && in_range(static_cast<double>(std::get<int64_t>(value)));
      break;
    case SettingType::kNumber: ok = std::holds_alternative<double>(value) && in_range(std::get<double>(value)); break;
    case SettingType::kFlag: ok = std::holds_alternative<bool>(value); break;
    case SettingType::kChoice:
      ok = std::holds_alternative<std::string>(value) &&
           std::find(choices.begin(), choices.end(), std::get<std::string>(value)) != choices.end();
      break;
  }
  if (!ok) ThrowInputError(what, "", Expected(), Format(value));
}

void Setting::Set(const SettingValue& value, const std::string& what, RecognizerSettings* settings) const {
  Check(value, what);
  put(value, settings);
}

std::string Setting::Format(const SettingValue& value) const {
  if (const auto* count = std::get_if<int64_t>(&value)) return std::to_string(*count);
  if (const auto* number = std::get_if<double>(&value)) return FormatNumber(*number);
  if (const auto* flag = std::get_if<bool>(&value)) return *flag ? "true" : "false";
  return std::get<std::string>(value);
}

const std::vector<Setting>& RecognizerSettingTable() {
  static const std::vector<Setting> table = MakeTable();
  return table;
}

const Setting* FindSetting(const std::string& name) {
  for (const Setting& setting : RecognizerSettingTable()) {
    if (setting.name == name || setting.Keyword() == name) return &setting;
  }
  return nullptr;
}

void CheckSettings(const RecognizerSettings& settings) {
  settings.options.Check();
  settings.stream.Check();
}

void RequireModels(const ModelLibrary& library, const std::string& library_path) {
  if (library.models().empty()) {
    ThrowInputError(library_path, "models", "a library with at least one model (ecvpose modeldb build MESH --db LIB)",
                    "none");
  }
}

}  // namespace ecv
