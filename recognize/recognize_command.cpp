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
#include "recognize/recognize_flags.h"
#include "recognize/recognizer.h"

namespace ecv::app {
namespace {

struct RecognizeArgs {
  RecognizerArgs recognizer;  // --db, --models, the search, tracking and verification flags
  FrameSpec frame;
  std::string sequence;
  std::string out_json;
  std::string out_bop;
  int scene_id = -1, image_id = -1;
  std::string overlay;
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
  return options;
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
  RecognitionStream stream(recognizer, args.recognizer.stream);
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
  const LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options, "recognize");
  Recognizer& recognizer = *loaded.recognizer;
  return single ? RecognizeOneFrame(args, *single, recognizer) : RecognizeSequence(args, frames, recognizer);
}

}  // namespace

CommandAction SetupRecognizeCommand(CLI::App& command) {
  auto args = std::make_shared<RecognizeArgs>();
  AddRecognizerFlags(command, &args->recognizer);
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
  command.footer(
      "Example:\n  ecvpose modeldb build models/meshes --db lib.sqlite\n"
      "  ecvpose recognize --db lib.sqlite models/frame/000001 --out-json detections.json --overlay detections.png");
  return [args] { return RunRecognize(*args); };
}

}  // namespace ecv::app
