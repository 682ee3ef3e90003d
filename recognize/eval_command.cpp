// `ecvpose eval --detections F --db lib.sqlite FRAME`: detections against a frame's ground truth.

#include <fstream>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/frame_args.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_library.h"
#include "recognize/evaluation.h"

namespace ecv::app {
namespace {

struct EvalArgs {
  std::string detections;
  std::string db;
  FrameSpec frame;
  std::string out_markdown;
};

int RunEval(const EvalArgs& args) {
  const std::vector<Detection> detections = DetectionsFromJson(ReadJsonFile(args.detections), args.detections);
  const LoadedFrame frame = LoadFrame(args.frame);
  if (frame.ground_truth.empty()) {
    ThrowInputError(frame.rgbd.name, "ground truth", "a frame with ground-truth poses (YCB-Video prefix or BOP image)");
  }
  LibraryLoadOptions load;
  load.build_matchers = false;
  const ModelLibrary library = ModelLibrary::Load(args.db, load);
  std::vector<EvalModel> models;
  for (const LibraryModel& model : library.models()) models.push_back(EvalModelFromRecord(model.record));
  const std::string table =
      EvaluationMarkdown({EvaluateFrame(frame.rgbd.name, detections, frame.ground_truth, models)});
  std::cout << table;
  if (!args.out_markdown.empty()) {
    std::ofstream out(args.out_markdown);
    out << table;
    if (!out) ThrowInputError(args.out_markdown, "markdown", "a writable file");
  }
  return kExitOk;
}

}  // namespace

CommandAction SetupEvalCommand(CLI::App& command) {
  auto args = std::make_shared<EvalArgs>();
  command.add_option("--detections", args->detections, "Detections JSON (ecvpose recognize --out-json)")->required();
  command.add_option("--db", args->db, "The model library the detections came from (meshes, diameters)")->required();
  command.add_option("FRAME", args->frame.positional, "YCB-Video prefix or BOP SCENE_DIR:IMAGE_ID with ground truth")
      ->required();
  command.add_option("--out-md", args->out_markdown, "The table as a markdown file");
  command.footer(
      "Per object: rotation and translation error, ADD, ADD-S, and correct when ADD (ADD-S for symmetric models)\n"
      "is below 0.1 x diameter; then recall and false positives.");
  return [args] { return RunEval(*args); };
}

}  // namespace ecv::app
