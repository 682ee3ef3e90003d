// `ecvpose recognize --db lib.sqlite FRAME`: finds the library's objects in an RGB-D frame.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.h"
#include "app/frame_args.h"
#include "app/recognize_flags.h"
#include "app/sequence_io.h"
#include "core/byte_neighbours.h"
#include "core/error.h"
#include "core/pose.h"
#include "core/timing.h"
#include "io/atomic_file.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/bop_task.h"
#include "recognize/recognition_json.h"
#include "recognize/recognition_stream.h"
#include "recognize/recognizer.h"

namespace ecv::app {
namespace {

struct RecognizeArgs {
  RecognizerArgs recognizer;  // --db, --models, the search, tracking and verification flags
  FrameSpec frame;
  std::string sequence;
  bool follow = false;
  bool latest = false;
  double idle_timeout_s = 10.0;
  std::string out_json;
  std::string out_bop;
  int scene_id = -1, image_id = -1;
  std::string targets;  // BOP test_targets_bop19.json
  std::string overlay;
};

// With --targets: each image's targets by (scene_id, im_id), and the library's model of each BOP object id.
struct Targets {
  std::string path;
  std::map<std::pair<int, int>, BopImage> images;
  std::map<int, std::string> model_of_object;

  bool active() const { return !path.empty(); }

  // The frame's targets as library model names; an InputError for a frame the file has none for.
  std::map<std::string, int> Of(std::pair<int, int> ids) const {
    const auto image = images.find(ids);
    if (image == images.end()) {
      ThrowInputError(path, "targets",
                      "an entry for scene " + std::to_string(ids.first) + " image " + std::to_string(ids.second) +
                          " (set --scene-id and --image-id)");
    }
    return TargetModels(image->second, model_of_object);
  }
};

Targets ReadTargets(const std::string& path, const std::map<std::string, int>& object_ids) {
  Targets targets;
  if (path.empty()) return targets;
  targets.path = path;
  for (BopImage& image : GroupBopTargets(ReadBopTargets(path), path)) targets.images[image.key()] = std::move(image);
  targets.model_of_object = ModelOfObject(object_ids);
  return targets;
}

// The frame recognised as the task asks: the targets alone (BOP's localisation), else every model.
RecognitionResult RecognizeAsAsked(Recognizer& recognizer, const Targets& targets, const RgbdFrame& frame,
                                   std::pair<int, int> ids) {
  return targets.active() ? recognizer.RecognizeTargets(frame, targets.Of(ids)) : recognizer.Recognize(frame);
}

// Scene and image ids of a frame: from --scene-id and --image-id (a single frame), else as the frame names them (a
// YCB-Video prefix, a BOP image, a frame JSON's keys), else scene 0 and the frame's place in the sequence from 0.
std::pair<int, int> BopIds(const LoadedFrame& frame, int index, int scene_flag = -1, int image_flag = -1) {
  if (scene_flag >= 0 && image_flag >= 0) return {scene_flag, image_flag};
  if (frame.scene_id >= 0 && frame.image_id >= 0) return {frame.scene_id, frame.image_id};
  return {0, index};
}

void PrintDetections(std::ostream& out, const LoadedFrame& loaded, const RecognitionResult& result) {
  out << std::fixed << std::setprecision(2) << loaded.rgbd.name << ": " << result.detections.size() << " detections ("
      << result.scene_primitives << " scene primitives";
  if (result.searched_frames_ago >= 0) {
    out << "; joined by the search of " << result.searched_frames_ago
        << (result.searched_frames_ago == 1 ? " frame" : " frames") << " before";
  }
  out << ")\n";
  for (const Detection& d : result.detections) {
    out << "  " << std::left << std::setw(24) << d.model << std::right << " score " << d.score << " (depth "
        << d.depth_agreement << ", colour " << d.color_agreement << ", edges " << d.edge_agreement << " of "
        << d.edge_pixels << ", fit " << std::setprecision(1) << 1000.0 * d.surface_error_m << " mm"
        << std::setprecision(2) << ", outline " << d.contour_agreement << ", runs on " << d.continuation
        << "), inliers " << d.inlier_fraction << ", view " << d.view << ", "
        << HypothesisSourceName(d.hypothesis_source) << (d.tracked ? ", tracked" : "")
        << (d.accepted ? "" : ", not accepted (a target's best)") << ", t = [" << std::setprecision(3)
        << d.camera_from_object.translation().transpose() << "] m" << std::setprecision(2) << '\n';
    for (const GroundTruth& truth : loaded.ground_truth) {
      if (truth.object_name != d.model) continue;
      out << "    vs ground truth: " << std::setprecision(1)
          << TranslationDistance(d.camera_from_object, truth.camera_from_object) * 1000.0 << " mm, "
          << RotationAngle(d.camera_from_object, truth.camera_from_object) * 180.0 / M_PI << " deg\n"
          << std::setprecision(2);
    }
  }
  out << "time:" << std::setprecision(1);
  for (const auto& [stage, ms] : result.timings_ms) out << ' ' << stage << ' ' << ms << " ms";
  out << '\n';
}

// The recognizer's options from the flags, checked.
RecognizerOptions OptionsFromArgs(const RecognizeArgs& args) {
  const RecognizerOptions options = RecognizerOptionsFromArgs(args.recognizer);
  if (!args.sequence.empty() && (!args.frame.positional.empty() || args.frame.color_path.size() > 0)) {
    ThrowInputError("recognize", "--sequence", "either a sequence or one frame, not both");
  }
  if (args.recognizer.stream.track && args.sequence.empty()) {
    ThrowInputError("recognize", "--track", "a --sequence to track along");
  }
  if (args.recognizer.stream.search_every > 1 && !args.recognizer.stream.track) {
    ThrowInputError("recognize", "--search-every", "--track as well");
  }
  if (args.recognizer.stream.search_beside && !args.recognizer.stream.track) {
    ThrowInputError("recognize", "--search-beside", "--track as well");
  }
  if (!args.targets.empty() && args.recognizer.stream.track) {
    ThrowInputError("recognize", "--targets", "frames recognised one by one, not --track");
  }
  return options;
}

// The human-readable report: on standard output, unless the detections go there ("-").
std::ostream& Report(const RecognizeArgs& args) {
  return args.out_json == "-" || args.out_bop == "-" ? std::cerr : std::cout;
}

int RecognizeOneFrame(const RecognizeArgs& args, const LoadedFrame& loaded, const ModelLibrary& library,
                      Recognizer& recognizer) {
  const std::map<std::string, int> object_ids = LibraryObjectIds(library);
  const std::pair<int, int> ids = BopIds(loaded, 0, args.scene_id, args.image_id);
  const RecognitionResult result =
      RecognizeAsAsked(recognizer, ReadTargets(args.targets, object_ids), loaded.rgbd, ids);
  PrintDetections(Report(args), loaded, result);
  const std::string json = RecognitionToJson(result).dump(2) + "\n";
  if (args.out_json == "-") LineOutput("-", "--out-json").Write(json);
  if (!args.out_json.empty() && args.out_json != "-") WriteFileAtomically(args.out_json, json);
  if (!args.out_bop.empty()) {
    std::ostringstream csv;
    csv << kBopCsvHeader;
    WriteBopRows(csv, ids, result.detections, object_ids, result.timings_ms.at("total") / 1000.0);
    if (args.out_bop == "-") {
      LineOutput("-", "--out-bop").Write(csv.str());
    } else {
      WriteFileAtomically(args.out_bop, csv.str());
    }
  }
  if (!args.overlay.empty()) WriteColorImage(args.overlay, recognizer.DrawDetections(loaded.rgbd, result.detections));
  return kExitOk;
}

// The overlay picture of the sequence's `number`th frame (from 1) in the --overlay directory: DIR/0001.png ...
std::string OverlayPath(const std::string& directory, int number) {
  char name[32];
  std::snprintf(name, sizeof(name), "/%04d.png", number);
  return directory + name;
}

// A sequence, processed in order as a camera stream would arrive; a broken frame is reported and skipped. Each
// frame's JSON line and BOP rows are written as soon as it is done.
int RecognizeSequence(const RecognizeArgs& args, FrameSource& feed, const ModelLibrary& library, Recognizer& recognizer,
                      const RecognizerOptions& search_options) {
  std::ostream& report = Report(args);
  LineOutput lines(args.out_json, "--out-json"), csv(args.out_bop, "--out-bop");
  if (csv.active()) csv.Write(kBopCsvHeader);
  const std::map<std::string, int> object_ids = LibraryObjectIds(library);
  const Targets targets = ReadTargets(args.targets, object_ids);
  int done = 0, failed = 0;
  double total_ms = 0.0;
  RecognitionStream stream(recognizer, args.recognizer.stream, MakeRecognizerFactory(library, search_options));
  if (!args.overlay.empty()) std::filesystem::create_directories(args.overlay);
  while (const std::optional<std::string> frame = feed.Next()) {
    try {
      const LoadedFrame loaded = feed.Load();
      const std::pair<int, int> ids = BopIds(loaded, done + failed);
      const RecognitionResult result =
          targets.active() ? RecognizeAsAsked(recognizer, targets, loaded.rgbd, ids) : stream.Next(loaded.rgbd);
      total_ms += result.timings_ms.at("total");
      report << feed.Counter();
      if (feed.Skipped() > 0) report << "(" << feed.Skipped() << " older frames skipped) ";
      PrintDetections(report, loaded, result);
      nlohmann::json line = RecognitionToJson(result);
      line["frame"] = *frame;
      if (feed.Skipped() > 0) line["skipped_before"] = feed.Skipped();
      // The picture is written before the frame's line, so that a reader of the lines (ecvpose-view) finds it whole.
      if (!args.overlay.empty()) {
        const std::string picture = OverlayPath(args.overlay, done + failed + 1);
        WriteColorImage(picture, recognizer.DrawDetections(loaded.rgbd, result.detections));
        line["overlay"] = picture;
      }
      if (lines.active()) lines.Write(line.dump() + "\n");
      if (csv.active()) {
        std::ostringstream rows;
        WriteBopRows(rows, ids, result.detections, object_ids, result.timings_ms.at("total") / 1000.0);
        csv.Write(rows.str());
      }
      ++done;
    } catch (const InputError& error) {
      ++failed;
      stream.Reset();  // the priors are lost: the next frame searches every model
      std::cerr << "recognize: frame " << *frame << " skipped: " << error.what() << '\n';
      if (lines.active()) lines.Write(nlohmann::json{{"frame", *frame}, {"error", error.what()}}.dump() + "\n");
    }
  }
  report << std::setprecision(2) << done << " frames in " << total_ms / 1000.0 << " s ("
         << (total_ms > 0.0 ? 1000.0 * done / total_ms : 0.0) << " frames per second)";
  if (failed > 0) report << ", " << failed << " failed";
  report << '\n';
  return failed > 0 ? kExitBadInput : kExitOk;
}

// The frames of --sequence: a camera or a recording when `open_live` knows the source, else frame files.
std::unique_ptr<FrameSource> OpenSequence(const RecognizeArgs& args, const FrameSourceOpener& open_live) {
  if (open_live) {
    if (std::unique_ptr<FrameSource> live = open_live(args.sequence, args.frame.camera)) {
      if (args.follow) ThrowInputError(args.sequence, "--follow", "a folder of frame JSONs, not a camera or recording");
      return live;
    }
  }
  if (args.frame.camera) {
    ThrowInputError(args.sequence, "--camera",
                    "with --sequence, an openni2:// camera or a .oni recording (frame files "
                    "carry their own intrinsics)");
  }
  return std::make_unique<FrameFeed>(args.sequence, args.follow, args.idle_timeout_s, args.latest);
}

int RunRecognize(const RecognizeArgs& args, const FrameSourceOpener& open_live) {
  if (args.out_json == "-" && args.out_bop == "-") {
    std::cerr << "ecvpose recognize: --out-json and --out-bop cannot both be standard output (-)\n";
    return kExitBadUsage;
  }
  if (args.follow && args.sequence.empty()) {
    std::cerr << "ecvpose recognize: --follow needs --sequence FOLDER\n";
    return kExitBadUsage;
  }
  if (args.latest && !args.follow) {
    std::cerr << "ecvpose recognize: --latest needs --follow\n";
    return kExitBadUsage;
  }
  const StreamRecognizerOptions options = ShareThreads(OptionsFromArgs(args), args.recognizer.stream);
  std::unique_ptr<FrameSource> feed;
  if (!args.sequence.empty()) feed = OpenSequence(args, open_live);
  // One frame is read first: a broken one is reported before the library and its meshes (seconds) are loaded.
  std::optional<LoadedFrame> single;
  if (!feed) single.emplace(app::LoadFrameWithWarnings(args.frame));
  const LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options.track, "recognize");
  Recognizer& recognizer = *loaded.recognizer;
  return single ? RecognizeOneFrame(args, *single, *loaded.library, recognizer)
                : RecognizeSequence(args, *feed, *loaded.library, recognizer, options.search);
}

}  // namespace

CommandAction SetupRecognizeCommand(CLI::App& command, FrameSourceOpener open_live) {
  auto args = std::make_shared<RecognizeArgs>();
  AddRecognizerFlags(command, &args->recognizer);
  command.add_option("FRAME", args->frame.positional,
                     "Frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or organized .pcd (or the frame flags)");
  AddFrameFlags(command, &args->frame);
  command.add_option(
      "--sequence", args->sequence,
      "Frames in order: a BOP scene folder, a YCB-Video video folder, a directory of frame JSONs, a file with\n"
      "one FRAME per line, an OpenNI2 camera (openni2:// for the first, openni2://URI) or a FILE.oni recording\n"
      "(intrinsics from --camera, else FILE.oni.json beside it, else the fields of view)");
  command.add_flag("--follow", args->follow,
                   "With --sequence FOLDER: also take the frame JSONs that appear in the folder while it runs (write\n"
                   "the images first, the JSON last, by rename), until --idle-timeout passes without a new one");
  command.add_flag("--latest", args->latest,
                   "With --follow: when several frames are waiting, recognise the newest and skip the others (its\n"
                   "line says \"skipped_before\": N), so that a live feed keeps its latency when a frame takes\n"
                   "longer than the camera's interval");
  command.add_option("--idle-timeout", args->idle_timeout_s, "With --follow: seconds to wait for a new frame")
      ->capture_default_str()
      ->check(NonNegative());
  command.add_option("--out-json", args->out_json,
                     "Detections as JSON (model, score, camera_from_object and the verification terms); for a\n"
                     "sequence JSON Lines, each frame's line written as soon as it is done; - for standard output");
  command.add_option("--out-bop", args->out_bop,
                     "Detections as BOP CSV (scene_id,im_id,obj_id,score,R,t,time; t in mm), rows written as each\n"
                     "frame is done; - for standard output");
  command.add_option("--scene-id", args->scene_id,
                     "BOP scene id of a single frame (default: as the frame names it, else 0)");
  command.add_option("--image-id", args->image_id,
                     "BOP image id of a single frame (default: as the frame names it, else its place in the\n"
                     "sequence from 0)");
  command.add_option("--targets", args->targets,
                     "BOP's localisation task: a test_targets_bop19.json; in each frame (its scene and image ids as\n"
                     "for --out-bop) only its target objects are looked for, each reporting up to its inst_count\n"
                     "estimates, the best by score, without a threshold (a pose the acceptance rejected comes last,\n"
                     "\"accepted\": false)");
  command.add_option("--overlay", args->overlay,
                     "Picture: each detected model in red with its name (PNG); with --sequence a directory,\n"
                     "one DIR/0001.png ... per frame in sequence order, written before the frame's --out-json\n"
                     "line, which names it (\"overlay\")");
  command.footer(
      "Example:\n  ecvpose modeldb build models/meshes --db lib.sqlite\n"
      "  ecvpose recognize --db lib.sqlite models/frame/000001 --out-json detections.json --overlay detections.png");
  return [args, open_live = std::move(open_live)] { return RunRecognize(*args, open_live); };
}

}  // namespace ecv::app
