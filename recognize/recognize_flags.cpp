#include "recognize/recognize_flags.h"

#include <algorithm>
#include <iomanip>
#include <iostream>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/byte_neighbours.h"
#include "core/error.h"
#include "core/timing.h"

namespace ecv::app {
namespace {

// Says on stderr how the meshes were loaded and how descriptors are matched.
void ReportSetup(const ModelLibrary& library, const RecognizerOptions& options, double setup_ms,
                 const std::string& tag) {
  const auto stored = std::count_if(library.models().begin(), library.models().end(),
                                    [](const LibraryModel& model) { return !model.record.mesh_blob.empty(); });
  std::cerr << tag << ": meshes loaded for verification (" << stored << " stored in the library, "
            << library.models().size() - static_cast<size_t>(stored) << " from mesh files; " << setup_ms << " ms)\n";
  std::cerr << tag << ": descriptors matched by ";
  if (options.match.index == MatchIndex::kBytes) {
    std::cerr << "bytes (" << (ByteNeighbours::CpuHasVnni() ? "AVX-512 VNNI" : "plain loop") << ", exact)\n";
  } else {
    std::cerr << "kd-forest (" << options.match.trees << " trees, " << options.match.checks << " checks; view ranking "
              << options.RankingChecks() << ")\n";
  }
}

// The flags of the search: views, models, threads.
void AddSearchFlags(CLI::App& command, RecognizerOptions& options) {
  command.add_option("--views-per-model", options.views_per_model, "Library views tried with RANSAC per model")
      ->capture_default_str();
  command
      .add_option("--good-enough-score", options.good_enough_score,
                  "A model's remaining views are skipped once one verifies at this score (0: try them all)")
      ->capture_default_str();
  command
      .add_option("--give-up-after", options.give_up_after_views,
                  "A model's remaining views are skipped when its first N all verify below --give-up-score:\n"
                  "it is taken to be absent (0: try --views-per-model views)")
      ->capture_default_str();
  command.add_option("--give-up-score", options.give_up_below_score, "See --give-up-after")->capture_default_str();
  command
      .add_option(
          "--preselect", options.preselect.models,
          "Search only the N models that a quick look at every 4th view (100 descriptors each) scores best:\n"
          "for large libraries, about half the time with 6 of 16 models, at some loss of recall (0: every model)")
      ->capture_default_str();
  command
      .add_option("--ranking-checks", options.ranking.checks,
                  "Descriptors compared per query when ranking the library's views (0: as many as matching, 128);\n"
                  "32 ranks in half the time, less well")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command.add_option("--min-score", options.verify.min_score, "Detections below this score are dropped")
      ->capture_default_str();
  command
      .add_option("--max-instances", options.max_instances,
                  "Instances of one model looked for per frame (e.g. a bin of identical parts)")
      ->capture_default_str();
  command
      .add_option_function<std::string>(
          "--hypotheses",
          [o = &options](const std::string& name) {
            o->point_pairs.source = ParseHypothesisSource(name, "--hypotheses");
          },
          "Where poses come from: context (shape and appearance context descriptors, view ranking and RANSAC),\n"
          "ppf (point pair features of the model's surface: shape alone) or both (point pairs for the models the\n"
          "context does not find: objects that show a plain side)")
      ->default_str(HypothesisSourceName(options.point_pairs.source))
      ->check(CLI::IsMember({"context", "ppf", "both"}));
  command.add_option("--seed", options.ransac.seed, "Random seed")->capture_default_str();
  command
      .add_option("--threads", options.ransac.threads,
                  "Worker threads for describing the scene and searching the models, one model each (same result for "
                  "any count)")
      ->capture_default_str()
      ->check(ThreadCount());
  command.add_flag(
      "--no-icp", [o = &options](int64_t) { o->refine = false; }, "Skip the ICP refinement");
}

// The stream flags: tracking objects from frame to frame.
void AddTrackingFlags(CLI::App& command, RecognizerArgs* args) {
  command.add_flag("--track", args->stream.track,
                   "Try each object first at its pose in the previous frame (refined and verified); objects tracked\n"
                   "so skip view ranking and RANSAC");
  command
      .add_option("--search-every", args->stream.search_every,
                  "With --track: models not tracked are searched on every N-th frame only (the first, 1 + N, ...;\n"
                  "after a broken frame, the next); in between, the tracked objects are followed and a lost one is\n"
                  "searched for at once")
      ->capture_default_str();
  command
      .add_option("--track-score", args->options.tracking.min_follow_score,
                  "With --track: a detection is followed into the next frame only while it scores at least this,\n"
                  "a first detection and a followed one alike")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  command.add_option("--track-start-score", args->options.tracking.min_follow_score)
      ->group("")  // its old name
      ->check(CLI::Range(0.0, 1.0));
  command
      .add_option("--confirm-every", args->options.tracking.confirm_every,
                  "With --track: an object followed this many frames since a search last found it has its model\n"
                  "searched again; the better of the two poses is kept (0: never)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  command
      .add_option("--confirm-first", args->options.tracking.confirm_first,
                  "With --track: the same for an object no search has found again since the one that first found\n"
                  "it (1: in the next frame; 0: as --confirm-every)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
}

// The flags of verification, RANSAC's inliers, matching and ICP.
void AddVerifyFlags(CLI::App& command, RecognizerArgs* args) {
  RecognizerOptions& options = args->options;
  command.add_flag(
      "--no-contour", [o = &options](int64_t) { o->verify.contour_falloff = 0.0; },
      "Verify without the contour factor (a pose's outline on the scene's depth steps): for flat objects thinner\n"
      "than 1 cm lying on a surface, or parts packed flush in a tray");
  command
      .add_option("--edge-weight", options.verify.edge_weight,
                  "Weight of the texture edges against the colour correlation in verification (0: colour alone)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  command.add_flag(
      "--nearest-inliers", [o = &options](int64_t) { o->projective_inliers = false; },
      "RANSAC finds an object point's inlier partner by a search among the scene's points in 3D (the paper)\n"
      "instead of among the depth samples around where the point is seen");
  command
      .add_option("--matcher", args->matcher,
                  "kd-forest (FLANN's randomised kd-trees, approximate: the same matches on every CPU) or bytes\n"
                  "(every scene descriptor compared over 7-bit values: nearer neighbours, 2x faster where the CPU\n"
                  "has AVX-512 VNNI, 20x slower where it has not)")
      ->check(CLI::IsMember({"kd-forest", "bytes"}))
      ->capture_default_str();
  command.add_flag("--fast-icp", options.projective_icp,
                   "ICP pairs points along the camera's rays (7x faster refinement, finds fewer objects)");
}

}  // namespace

void AddRecognizerFlags(CLI::App& command, RecognizerArgs* args) {
  AddDbOption(command, &args->db, "Model library (SQLite), from `ecvpose modeldb build`");
  command.add_option("--models", args->models, "Only these models of the library (default: all)");
  args->options.ransac.threads = app::AllCores();
  AddSearchFlags(command, args->options);
  AddTrackingFlags(command, args);
  AddVerifyFlags(command, args);
}

RecognizerOptions RecognizerOptionsFromArgs(const RecognizerArgs& args) {
  RecognizerOptions options = args.options;
  if (args.matcher == "bytes") {
    options.match.index = MatchIndex::kBytes;
    if (!ByteNeighbours::CpuHasVnni()) {
      std::cerr << "warning: --matcher bytes without AVX-512 VNNI on this CPU: matching about 20x slower than the "
                   "kd-forest\n";
    }
  }
  options.Check();
  if (args.stream.search_every < 1)
    ThrowInputError("--search-every", "", "a whole number of at least 1", std::to_string(args.stream.search_every));
  return options;
}

LoadedRecognizer LoadRecognizer(const RecognizerArgs& args, const RecognizerOptions& options, const std::string& tag) {
  LibraryLoadOptions load;
  load.names = args.models;
  load.build_matchers = false;  // the scene is indexed, the views are queried
  LoadedRecognizer loaded;
  loaded.library = std::make_unique<ModelLibrary>(ModelLibrary::Load(args.db, load));
  const ModelLibrary& library = *loaded.library;
  if (library.models().empty()) {
    ThrowInputError(args.db, "models", "a library with at least one model (ecvpose modeldb build MESH --db LIB)",
                    "none");
  }
  std::cerr << tag << ": " << library.models().size() << " models, " << library.NumViews() << " views from " << args.db
            << " (" << std::fixed << std::setprecision(0) << library.timings().read_ms << " ms)\n";
  const Clock::time_point setup = Clock::now();
  loaded.recognizer = std::make_unique<Recognizer>(library, options);
  ReportSetup(library, options, MillisecondsSince(setup), tag);
  for (const std::string& warning : loaded.recognizer->PointPairWarnings()) {
    std::cerr << tag << ": warning: " << warning << '\n';
  }
  return loaded;
}

}  // namespace ecv::app
