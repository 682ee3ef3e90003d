// `ecvpose eval --db lib.sqlite --detections F (FRAME | --gt-bop SCENE_DIR | --gt-ycbv VIDEO_DIR)`: detections
// against ground truth, for one frame or for every frame of a BOP scene or YCB-Video video folder.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/bop_evaluation.h"
#include "recognize/bop_task.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_json.h"
#include "render/renderer.h"

namespace ecv::app {
namespace {

struct EvalArgs {
  std::string detections;
  std::string db;
  FrameSpec frame;
  std::string gt_bop;
  std::string gt_ycbv;
  std::string out_markdown;
  std::string out_json;
  std::string metric = "add";
  std::string models_info;  // BOP models_info.json: the symmetries of --metric bop
};

// The detections JSON of one frame, each naming a model of the library.
std::vector<Detection> ReadFrameDetections(const EvalArgs& args, const std::vector<EvalModel>& models) {
  const std::vector<Detection> detections = DetectionsFromJson(ReadJsonFile(args.detections), args.detections);
  for (size_t i = 0; i < detections.size(); ++i) {
    const bool known = std::any_of(models.begin(), models.end(),
                                   [&](const EvalModel& model) { return model.name == detections[i].model; });
    if (!known) {
      ThrowInputError(args.detections, "detections[" + std::to_string(i) + "].model",
                      "a model of the library " + args.db, "'" + detections[i].model + "'");
    }
  }
  return detections;
}

// The frame and its ground truth, each instance named as the library names its model (a BOP frame's obj_000001 may be
// the library's 002_master_chef_can).
LoadedFrame LoadFrameWithTruth(const FrameSpec& spec, const ModelLibrary& library) {
  LoadedFrame frame = app::LoadFrameWithWarnings(spec);
  if (frame.ground_truth.empty()) {
    ThrowInputError(frame.rgbd.name, "ground truth", "a frame with ground-truth poses (YCB-Video prefix or BOP image)");
  }
  NameTruthAfterModels(ModelOfObject(LibraryObjectIds(library)), &frame.ground_truth);
  return frame;
}

// One detections JSON against the ground truth of one frame.
std::vector<FrameEvaluation> EvaluateOneFrame(const EvalArgs& args, const ModelLibrary& library,
                                              const std::vector<EvalModel>& models) {
  const std::vector<Detection> detections = ReadFrameDetections(args, models);
  const LoadedFrame frame = LoadFrameWithTruth(args.frame, library);
  return {EvaluateFrame(frame.rgbd.name, detections, frame.ground_truth, models)};
}

// BOP's average recall of the detections of one frame or of a folder's frames: VSD from depth rendered at each pose,
// MSSD and MSPD over the symmetries of --models-info; a table per model and over all.
int EvaluateBop(const EvalArgs& args, const ModelLibrary& library, const std::vector<EvalModel>& models) {
  std::vector<FolderFrame> frames;
  if (!args.frame.positional.empty()) {
    FolderFrame frame;
    frame.frame = args.frame.positional;
    frame.detections = ReadFrameDetections(args, models);
    frames.push_back(std::move(frame));
  } else {
    const bool ycbv = !args.gt_ycbv.empty();
    frames = ReadFolderDetections(args.detections, ycbv ? GroundTruthFolder::kYcbVideo : GroundTruthFolder::kBopScene,
                                  ycbv ? args.gt_ycbv : args.gt_bop, models);
  }
  std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries;
  if (!args.models_info.empty()) symmetries = ReadBopSymmetries(args.models_info, library);
  Renderer renderer;
  BopJudge judge(library, models, symmetries, renderer);
  std::map<std::string, std::vector<BopObjectErrors>> by_model;
  int width = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    FrameSpec spec = args.frame;
    spec.positional = frames[i].frame;
    const LoadedFrame frame = LoadFrameWithTruth(spec, library);
    if (width != 0 && frame.rgbd.camera.width != width) {
      ThrowInputError(frame.rgbd.name, "image width", "that of the other frames, " + std::to_string(width),
                      std::to_string(frame.rgbd.camera.width));
    }
    width = frame.rgbd.camera.width;
    const std::vector<BopObjectErrors> objects =
        judge.FrameErrors(frame.rgbd, frames[i].detections, frame.ground_truth);
    for (size_t k = 0; k < objects.size(); ++k) by_model[judge.judged_models()[k]].push_back(objects[k]);
    if (frames.size() > 1) std::cerr << "eval: [" << i + 1 << "/" << frames.size() << "] " << frames[i].frame << '\n';
  }
  const std::string source = args.frame.positional.empty() ? std::to_string(frames.size()) + " frames of " +
                                                                 (args.gt_ycbv.empty() ? args.gt_bop : args.gt_ycbv)
                                                           : frames.front().frame;
  std::string table = source + ": BOP average recall (VSD, MSSD, MSPD; symmetries " +
                      (args.models_info.empty() ? std::string("none: no --models-info") : "of " + args.models_info) +
                      ")\n\n" + BopRecallMarkdown(by_model, width);
  std::cout << table;
  if (!args.out_markdown.empty()) WriteFileAtomically(args.out_markdown, table);
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, BopRecallJson(by_model, width));
  return kExitOk;
}

int RunEval(const EvalArgs& args) {
  const int forms =
      (args.frame.positional.empty() ? 0 : 1) + (args.gt_bop.empty() ? 0 : 1) + (args.gt_ycbv.empty() ? 0 : 1);
  if (forms != 1) {
    std::cerr << "ecvpose eval: give exactly one of FRAME, --gt-bop SCENE_DIR or --gt-ycbv VIDEO_DIR\n";
    return kExitBadUsage;
  }
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(args.db, load);
  const std::vector<EvalModel> models = EvalModels(library);
  if (args.metric == "bop") return EvaluateBop(args, library, models);
  if (!args.models_info.empty()) {
    std::cerr << "ecvpose eval: --models-info is for --metric bop\n";
    return kExitBadUsage;
  }

  std::vector<FrameEvaluation> frames;
  if (!args.frame.positional.empty()) {
    frames = EvaluateOneFrame(args, library, models);
  } else if (!args.gt_ycbv.empty()) {
    frames = EvaluateDetectionsFile(args.detections, GroundTruthFolder::kYcbVideo, args.gt_ycbv, models);
  } else {
    frames = EvaluateDetectionsFile(args.detections, GroundTruthFolder::kBopScene, args.gt_bop, models);
  }
  const std::string table = EvaluationMarkdown(frames);
  std::cout << table;
  if (!args.out_markdown.empty()) WriteFileAtomically(args.out_markdown, table);
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, EvaluationToJson(frames));
  return kExitOk;
}

}  // namespace

CommandAction SetupEvalCommand(CLI::App& command) {
  auto args = std::make_shared<EvalArgs>();
  command
      .add_option("--detections", args->detections,
                  "Detections: JSON of one frame (recognize --out-json), the JSON Lines of recognize --sequence, "
                  "or a BOP CSV (recognize --out-bop)")
      ->required();
  AddDbOption(command, &args->db, "The model library the detections came from (meshes, diameters)");
  command.add_option("FRAME", args->frame.positional, "YCB-Video prefix or BOP SCENE_DIR:IMAGE_ID with ground truth");
  command.add_option(
      "--depth", args->frame.depth_path,
      "16-bit depth PNG replacing the FRAME's (a BOP image's; --metric bop's VSD reads the frames' depth)");
  command.add_option("--gt-bop", args->gt_bop, "BOP scene folder: ground truth from its scene_gt.json");
  command.add_option("--gt-ycbv", args->gt_ycbv, "YCB-Video video folder: ground truth from each frame's -meta.mat");
  command.add_option("--out-md", args->out_markdown, "The tables as a markdown file");
  command.add_option("--out-json", args->out_json, "Per frame and object numbers (metres, radians) and totals");
  command
      .add_option("--metric", args->metric,
                  "add: recall at ADD (ADD-S) < 0.1 d with false positives; bop: the BOP challenge's average recall "
                  "(VSD, MSSD, MSPD)")
      ->check(CLI::IsMember({"add", "bop"}))
      ->capture_default_str();
  command.add_option("--models-info", args->models_info,
                     "BOP models_info.json (millimetres): each object's symmetries for --metric bop (default: none)");
  command.footer(
      "Per object: rotation and translation error, ADD, ADD-S, and correct when ADD (ADD-S for symmetric models)\n"
      "is below 0.1 x diameter; then recall and false positives, overall and per model. With --gt-bop/--gt-ycbv,\n"
      "frames of the folder without a line in the detections (or with an \"error\" line) count as missed.\n"
      "--metric bop: the BOP challenge's average recall per model and over all (docs/bop.md).");
  return [args] { return RunEval(*args); };
}

}  // namespace ecv::app
