// `ecvpose recognize --db lib.sqlite FRAME`: finds the library's objects in an RGB-D frame.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/byte_neighbours.h"
#include "core/error.h"
#include "core/pose.h"
#include "core/timing.h"
#include "io/atomic_file.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"

namespace ecv::app {
namespace {

struct RecognizeArgs {
  std::string db;
  std::vector<std::string> models;
  FrameSpec frame;
  std::string sequence;
  RecognizerOptions options;
  std::string out_json;
  std::string out_bop;
  int scene_id = -1, image_id = -1;
  std::string overlay;
  StreamOptions stream;
  std::string matcher = "kd-forest";
};

// BOP object id of a model: the number in "obj_000005", or the YCB-Video class index of "003_cracker_box".
int BopObjectId(const std::string& model) {
  if (model.rfind("obj_", 0) == 0) return std::stoi(model.substr(4));
  for (int id = 1; id <= 21; ++id) {
    if (YcbvClassName(id) == model) return id;
  }
  ThrowInputError(model, "model name", "obj_NNNNNN or a YCB-Video class name, for the BOP obj_id");
}

// Scene and image ids of a frame: from the flags, or from a YCB-Video prefix ".../0001/000007" or a BOP
// image "SCENE_DIR:ID".
std::pair<int, int> BopIds(const std::string& frame, int scene_id, int image_id) {
  namespace fs = std::filesystem;
  if (scene_id >= 0 && image_id >= 0) return {scene_id, image_id};
  const size_t colon = frame.rfind(':');
  try {
    if (colon != std::string::npos) {
      return {std::stoi(fs::path(frame.substr(0, colon)).filename().string()), std::stoi(frame.substr(colon + 1))};
    }
    return {std::stoi(fs::path(frame).parent_path().filename().string()),
            std::stoi(fs::path(frame).filename().string())};
  } catch (const std::exception&) {
    ThrowInputError(frame, "scene and image ids", "--scene-id and --image-id, or a YCB-Video or BOP frame name");
  }
}

// One BOP CSV row per detection: scene_id,im_id,obj_id,score,R (9, row-major),t (mm),time (s).
void AppendBopRows(std::ostream& out, int scene_id, int image_id, const RecognitionResult& result) {
  for (const Detection& d : result.detections) {
    const Eigen::Matrix3d r = d.camera_from_object.linear();
    const Eigen::Vector3d t = d.camera_from_object.translation() * 1000.0;
    out << scene_id << ',' << image_id << ',' << BopObjectId(d.model) << ',' << d.score << ',';
    for (int i = 0; i < 9; ++i) out << (i > 0 ? " " : "") << r(i / 3, i % 3);
    out << ',' << t.x() << ' ' << t.y() << ' ' << t.z() << ',' << result.timings_ms.at("total") / 1000.0 << '\n';
  }
}

void PrintDetections(const LoadedFrame& loaded, const RecognitionResult& result) {
  std::cout << std::fixed << std::setprecision(2) << loaded.rgbd.name << ": " << result.detections.size()
            << " detections (" << result.scene_primitives << " scene primitives)\n";
  for (const Detection& d : result.detections) {
    std::cout << "  " << std::left << std::setw(24) << d.model << std::right << " score " << d.score << " (depth "
              << d.depth_agreement << ", colour " << d.color_agreement << ", edges " << d.edge_agreement << " of "
              << d.edge_pixels << ", fit " << std::setprecision(1) << 1000.0 * d.surface_error_m << " mm"
              << std::setprecision(2) << ", outline " << d.contour_agreement << "), inliers " << d.inlier_fraction
              << ", view " << d.view << ", " << HypothesisSourceName(d.hypothesis) << (d.tracked ? ", tracked" : "")
              << ", t = [" << std::setprecision(3) << d.camera_from_object.translation().transpose() << "] m"
              << std::setprecision(2) << '\n';
    for (const GroundTruth& truth : loaded.ground_truth) {
      if (truth.object_name != d.model) continue;
      std::cout << "    vs ground truth: " << std::setprecision(1)
                << TranslationDistance(d.camera_from_object, truth.camera_from_object) * 1000.0 << " mm, "
                << RotationAngle(d.camera_from_object, truth.camera_from_object) * 180.0 / M_PI << " deg\n"
                << std::setprecision(2);
    }
  }
  std::cout << "time:" << std::setprecision(1);
  for (const auto& [stage, ms] : result.timings_ms) std::cout << ' ' << stage << ' ' << ms << " ms";
  std::cout << '\n';
}

// The recognizer's options from the flags, checked.
RecognizerOptions OptionsFromArgs(const RecognizeArgs& args) {
  RecognizerOptions options = args.options;
  if (args.matcher == "bytes") {
    options.match.index = MatchIndex::kBytes;
    if (!ByteNeighbours::CpuHasVnni()) {
      std::cerr << "recognize: warning: --matcher bytes without AVX-512 VNNI on this CPU: matching about 20x slower "
                   "than the kd-forest\n";
    }
  }
  options.Check();
  if (!args.sequence.empty() && (!args.frame.positional.empty() || args.frame.color_path.size() > 0)) {
    ThrowInputError("recognize", "--sequence", "either a sequence or one frame, not both");
  }
  if (args.stream.track && args.sequence.empty()) {
    ThrowInputError("recognize", "--track", "a --sequence to track along");
  }
  if (args.stream.search_every < 1) ThrowInputError("recognize", "--search-every", "at least 1");
  if (args.stream.search_every > 1 && !args.stream.track) {
    ThrowInputError("recognize", "--search-every", "--track as well");
  }
  return options;
}

// Says on stderr how the meshes were loaded and how descriptors are matched.
void ReportSetup(const ModelLibrary& library, const RecognizerOptions& options, double setup_ms) {
  const auto stored = std::count_if(library.models().begin(), library.models().end(),
                                    [](const LibraryModel& model) { return !model.record.mesh_blob.empty(); });
  std::cerr << "recognize: meshes loaded for verification (" << stored << " stored in the library, "
            << library.models().size() - static_cast<size_t>(stored) << " from mesh files; " << setup_ms << " ms)\n";
  std::cerr << "recognize: descriptors matched by ";
  if (options.match.index == MatchIndex::kBytes) {
    std::cerr << "bytes (" << (ByteNeighbours::CpuHasVnni() ? "AVX-512 VNNI" : "plain loop") << ", exact)\n";
  } else {
    std::cerr << "kd-forest (" << options.match.trees << " trees, " << options.match.checks << " checks; view ranking "
              << options.RankingChecks() << ")\n";
  }
}

int RecognizeOneFrame(const RecognizeArgs& args, const LoadedFrame& loaded, Recognizer& recognizer) {
  const RecognitionResult result = recognizer.Recognize(loaded.rgbd);
  PrintDetections(loaded, result);
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, RecognitionToJson(result));
  if (!args.out_bop.empty()) {
    const auto [scene_id, image_id] = BopIds(args.frame.positional, args.scene_id, args.image_id);
    std::ostringstream csv;
    csv << "scene_id,im_id,obj_id,score,R,t,time\n";
    AppendBopRows(csv, scene_id, image_id, result);
    WriteFileAtomically(args.out_bop, csv.str());
  }
  if (!args.overlay.empty()) WriteColorImage(args.overlay, recognizer.DrawDetections(loaded.rgbd, result.detections));
  return kExitOk;
}

// A sequence, processed in order as a camera stream would arrive; a broken frame is reported and skipped.
int RecognizeSequence(const RecognizeArgs& args, const std::vector<std::string>& frames, Recognizer& recognizer) {
  std::ostringstream lines, csv;
  csv << "scene_id,im_id,obj_id,score,R,t,time\n";
  int failed = 0;
  double total_ms = 0.0;
  RecognitionStream stream(recognizer, args.stream);
  if (!args.overlay.empty()) std::filesystem::create_directories(args.overlay);
  for (size_t i = 0; i < frames.size(); ++i) {
    FrameSpec spec;
    spec.positional = frames[i];
    try {
      const LoadedFrame loaded = app::LoadFrameWithWarnings(spec);
      const std::pair<int, int> ids = args.out_bop.empty() ? std::pair{-1, -1} : BopIds(frames[i], -1, -1);
      const RecognitionResult result = stream.Next(loaded.rgbd);
      total_ms += result.timings_ms.at("total");
      std::cout << "[" << i + 1 << "/" << frames.size() << "] ";
      PrintDetections(loaded, result);
      nlohmann::json line = RecognitionToJson(result);
      line["frame"] = frames[i];
      lines << line.dump() << '\n';
      if (!args.out_bop.empty()) AppendBopRows(csv, ids.first, ids.second, result);
      if (!args.overlay.empty()) {
        char name[32];
        std::snprintf(name, sizeof(name), "/%04zu.png", i + 1);
        WriteColorImage(args.overlay + name, recognizer.DrawDetections(loaded.rgbd, result.detections));
      }
    } catch (const InputError& error) {
      ++failed;
      stream.Reset();  // the priors are lost: the next frame searches every model
      std::cerr << "recognize: frame " << frames[i] << " skipped: " << error.what() << '\n';
      lines << nlohmann::json{{"frame", frames[i]}, {"error", error.what()}}.dump() << '\n';
    }
  }
  const size_t done = frames.size() - static_cast<size_t>(failed);
  std::cout << std::setprecision(2) << done << " frames in " << total_ms / 1000.0 << " s ("
            << (total_ms > 0.0 ? 1000.0 * static_cast<double>(done) / total_ms : 0.0) << " frames per second)";
  if (failed > 0) std::cout << ", " << failed << " failed";
  std::cout << '\n';
  if (!args.out_json.empty()) WriteFileAtomically(args.out_json, lines.str());
  if (!args.out_bop.empty()) WriteFileAtomically(args.out_bop, csv.str());
  return failed > 0 ? kExitBadInput : kExitOk;
}

int RunRecognize(const RecognizeArgs& args) {
  const RecognizerOptions options = OptionsFromArgs(args);
  std::vector<std::string> frames;
  if (!args.sequence.empty()) frames = ListSequenceFrames(args.sequence);
  // One frame is read first: a broken one is reported before the library and its meshes (seconds) are loaded.
  std::optional<LoadedFrame> single;
  if (frames.empty()) single.emplace(app::LoadFrameWithWarnings(args.frame));
  LibraryLoadOptions load;
  load.names = args.models;
  load.build_matchers = false;  // the scene is indexed, the views are queried
  const ModelLibrary library = ModelLibrary::Load(args.db, load);
  if (library.models().empty()) {
    ThrowInputError(args.db, "models", "a library with at least one model (ecvpose modeldb build MESH --db LIB)",
                    "none");
  }
  std::cerr << "recognize: " << library.models().size() << " models, " << library.NumViews() << " views from "
            << args.db << " (" << std::fixed << std::setprecision(0) << library.timings().read_ms << " ms)\n";
  const Clock::time_point setup = Clock::now();
  Recognizer recognizer(library, options);
  ReportSetup(library, options, MillisecondsSince(setup));
  for (const std::string& warning : recognizer.PointPairWarnings())
    std::cerr << "recognize: warning: " << warning << '\n';
  return single ? RecognizeOneFrame(args, *single, recognizer) : RecognizeSequence(args, frames, recognizer);
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
      ->check(AtLeastOne());
  command.add_flag(
      "--no-icp", [o = &options](int64_t) { o->refine = false; }, "Skip the ICP refinement");
}

// The stream flags: tracking objects from frame to frame.
void AddTrackingFlags(CLI::App& command, RecognizeArgs* args) {
  command.add_flag("--track", args->stream.track,
                   "With --sequence: try each object first at its pose in the previous frame (refined and verified);\n"
                   "objects tracked so skip view ranking and RANSAC");
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
}

// The flags of verification, RANSAC's inliers, matching and ICP.
void AddVerifyFlags(CLI::App& command, RecognizeArgs* args) {
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

CommandAction SetupRecognizeCommand(CLI::App& command) {
  auto args = std::make_shared<RecognizeArgs>();
  AddDbOption(command, &args->db, "Model library (SQLite), from `ecvpose modeldb build`");
  command.add_option("--models", args->models, "Only these models of the library (default: all)");
  command.add_option("FRAME", args->frame.positional,
                     "Frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or organized .pcd (or the frame flags)");
  AddFrameFlags(command, &args->frame);
  command.add_option(
      "--sequence", args->sequence,
      "Frames in order: a BOP scene folder, a YCB-Video video folder, a directory of frame JSONs, or a file with\n"
      "one FRAME per line");
  command.add_option(
      "--out-json", args->out_json,
      "Detections as JSON (model, score, camera_from_object and the verification terms); JSON Lines for a sequence");
  command.add_option("--out-bop", args->out_bop,
                     "Detections as BOP CSV (scene_id,im_id,obj_id,score,R,t,time; t in mm)");
  command.add_option("--scene-id", args->scene_id, "BOP scene id (default: from the frame name)");
  command.add_option("--image-id", args->image_id, "BOP image id (default: from the frame name)");
  command.add_option("--overlay", args->overlay,
                     "Picture: each detected model in red with its name (PNG); with --sequence a directory,\n"
                     "one DIR/0001.png ... per frame in sequence order");
  args->options.ransac.threads = app::AllCores();
  AddSearchFlags(command, args->options);
  AddTrackingFlags(command, args.get());
  AddVerifyFlags(command, args.get());
  command.footer(
      "Example:\n  ecvpose modeldb build models/meshes --db lib.sqlite\n"
      "  ecvpose recognize --db lib.sqlite models/frame/000001 --out-json detections.json --overlay detections.png");
  return [args] { return RunRecognize(*args); };
}

}  // namespace ecv::app
