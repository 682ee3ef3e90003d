#include "app/recognize_flags.h"

#include <algorithm>
#include <iomanip>
#include <iostream>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/byte_neighbours.h"
#include "core/timing.h"
#include "recognize/settings_flags.h"

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

}  // namespace

void AddRecognizerFlags(CLI::App& command, RecognizerArgs* args) {
  AddDbOption(command, &args->db, "Model library (SQLite), from `ecvpose modeldb build`");
  command.add_option("--models", args->models, "Only these models of the library (default: all)");
  args->options.threads = app::AllCores();
  AddSettingFlags(command, args);
  command
      .add_flag_callback(
          "--settings-json",
          [] {
            std::cout << SettingTableJson() << '\n';
            throw CLI::Success();
          },
          "The settings table as JSON (for the tests)")
      ->group("");
}

RecognizerOptions RecognizerOptionsFromArgs(const RecognizerArgs& args) {
  if (args.options.match.index == MatchIndex::kBytes && !ByteNeighbours::CpuHasVnni()) {
    std::cerr << "warning: --matcher bytes without AVX-512 VNNI on this CPU: matching about 20x slower than the "
                 "kd-forest\n";
  }
  args.options.Check();
  return args.options;
}

LoadedRecognizer LoadRecognizer(const RecognizerArgs& args, const RecognizerOptions& options, const std::string& tag) {
  LibraryLoadOptions load;
  load.names = args.models;
  load.build_matchers = false;  // the scene is indexed, the views are queried
  LoadedRecognizer loaded;
  loaded.library = std::make_unique<ModelLibrary>(ModelLibrary::Load(args.db, load));
  const ModelLibrary& library = *loaded.library;
  RequireModels(library, args.db);
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
