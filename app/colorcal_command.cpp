// `ecvpose colorcal`: fit a model's 3x3 colour matrix (paper Sect. IV-C) from hand-labelled pairs or automatically from
// a frame where the model's pose is known, and show or clear the stored one. Compiled only into the ecvpose executable;
// reads flags into options and calls ecv_colorcal, ecv_render and ecv_modeldb.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/frame_args.h"
#include "colorcal/color_matrix.h"
#include "colorcal/color_pairs.h"
#include "colorcal/pairs_csv.h"
#include "core/error.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "modeldb/model_database.h"
#include "render/renderer.h"

namespace ecv::app {
namespace {

struct ColorcalArgs {
  std::string db;
  std::string model;
  // fit
  std::string pairs_path;
  std::string method = "ransac";
  // The matrices the recognizer applies before matching: per-channel gains, brightness kept. Measured by
  // recognize_bench on YCB-Video (bench/EXPERIMENTS.md, 2026-11-22, "colour matrices of other forms"):
  // 30 of 70 objects against 25 without matrices and 21-23 with full or auto-form matrices as fitted.
  std::string form = "diagonal";
  bool keep_brightness = true;
  // auto
  std::vector<std::string> frames;  // positional FRAMEs; empty: the frame given by --color/--depth
  FrameSpec frame;
  std::string pose_path;
  double max_depth_difference_m = 0.01;
};

std::string Fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  return text;
}

ColorFitMethod MethodArgument(const std::string& method) {
  if (method == "lsq") return ColorFitMethod::kLeastSquares;
  if (method == "irls") return ColorFitMethod::kTukeyIrls;
  return ColorFitMethod::kRansac;
}

ColorFitOptions FitOptions(const ColorcalArgs& args) {
  ColorFitOptions options;
  options.method = MethodArgument(args.method);
  if (args.form == "full") options.form = ColorMatrixForm::kFull;
  if (args.form == "diagonal") options.form = ColorMatrixForm::kDiagonal;
  if (args.form == "auto") options.form = ColorMatrixForm::kAuto;
  options.keep_brightness = args.keep_brightness;
  options.Check();
  return options;
}

void PrintMatrix(const Eigen::Matrix3d& a) {
  for (int row = 0; row < 3; ++row) {
    std::cout << (row == 0 ? "A = [" : "     ");
    for (int col = 0; col < 3; ++col) std::cout << (col == 0 ? "" : " ") << Fixed(a(row, col), 6);
    std::cout << (row == 2 ? "]" : "") << '\n';
  }
}

void PrintFit(const ColorFit& fit, size_t num_pairs, ColorFitMethod method) {
  std::cout << "method: " << ToString(method) << ", form: " << ToString(fit.form) << '\n';
  PrintMatrix(fit.A);
  std::cout << "rms: " << Fixed(fit.rms, 6) << " (RGB in [0, 1])\n"
            << "condition number: " << Fixed(fit.condition_number, 2) << '\n'
            << "inliers: " << fit.num_inliers << "/" << num_pairs << '\n';
  if (fit.brightness_scale != 1.0)
    std::cout << "brightness kept: A scaled by " << Fixed(fit.brightness_scale, 4) << '\n';
}

// The model's summary; throws InputError naming the model and the library when there is none.
ModelSummary FindModelOrThrow(const ModelDatabase& database, const std::string& name) {
  std::optional<ModelSummary> model = database.FindModel(name);
  if (!model) {
    throw InputError(database.path() + ": no model \"" + name + "\" (see `ecvpose modeldb list --db " +
                     database.path() + "`)");
  }
  return *model;
}

void Store(ModelDatabase& database, const std::string& name, const ColorFit& fit, const std::string& source) {
  ColorMatrixRecord record;
  record.model_to_scene = fit.A;
  record.rms = fit.rms;
  record.source = source;
  database.SetColorMatrix(name, record);
  std::cout << "stored the colour matrix of " << name << " in " << database.path() << " (source " << source << ")\n";
}

int RunFit(const ColorcalArgs& args) {
  ModelDatabase database(args.db, OpenMode::kReadWrite);
  FindModelOrThrow(database, args.model);  // before reading the pairs: a wrong name fails at once
  const std::vector<ColorPair> pairs = ReadColorPairsCsv(args.pairs_path);
  const ColorFitOptions options = FitOptions(args);
  const ColorFit fit = FitColorMatrix(pairs, options);
  std::cout << args.model << ": " << pairs.size() << " pairs from " << args.pairs_path << '\n';
  PrintFit(fit, pairs.size(), options.method);
  std::cout << "mean colour error: " << Fixed(MeanColorError(pairs), 6) << " -> "
            << Fixed(MeanColorError(pairs, fit.A), 6) << '\n';
  Store(database, args.model, fit, "pairs:" + args.pairs_path);
  return kExitOk;
}

// A short name of the frame for the stored source: the last two path components (".../0001/000001" -> "0001/000001").
std::string FrameName(const FrameSpec& spec) {
  const std::filesystem::path path(spec.positional.empty() ? spec.color_path : spec.positional);
  const std::string parent = path.parent_path().filename().string();
  return parent.empty() ? path.filename().string() : parent + "/" + path.filename().string();
}

// The model's pose in the frame: --pose FILE, else the frame's ground truth of the model.
Eigen::Isometry3d PoseInFrame(const ColorcalArgs& args, const LoadedFrame& frame, const std::string& frame_name) {
  if (!args.pose_path.empty()) return ReadPoseFile(args.pose_path, "camera_from_object");
  for (const GroundTruth& truth : frame.ground_truth) {
    if (truth.object_name == args.model) return truth.camera_from_object;
  }
  throw InputError("no pose of \"" + args.model + "\" in frame " + frame_name +
                   ": give --pose FILE (key camera_from_object), or a frame whose ground truth holds " + args.model);
}

// Automatic pairs of the model in one frame: rendered at the pose, paired where the depths agree.
std::vector<ColorPair> PairsInFrame(const ColorcalArgs& args, const FrameSpec& spec, Renderer& renderer, MeshId id) {
  const LoadedFrame frame = app::LoadFrameWithWarnings(spec);
  const std::string frame_name = FrameName(spec);
  const Eigen::Isometry3d camera_from_object = PoseInFrame(args, frame, frame_name);
  RenderOptions render_options;
  render_options.shading = Shading::kUnlit;  // as the model library renders its views
  const RenderResult render = renderer.Render(id, frame.rgbd.camera, camera_from_object, render_options);
  const cv::Mat mask = DepthAgreementMask(render.depth, frame.rgbd.depth, args.max_depth_difference_m);
  const PosePairs pose_pairs = ColorPairsFromPose(render.color, frame.rgbd.color, mask);
  std::cout << args.model << " in " << frame_name << ": " << cv::countNonZero(render.mask) << " rendered pixels, "
            << pose_pairs.mask_pixels << " where the depth agrees within "
            << Fixed(1000.0 * args.max_depth_difference_m, 1) << " mm, " << pose_pairs.pairs.size()
            << " pairs (skipped: " << pose_pairs.window_outside << " at the mask's edge, " << pose_pairs.dark
            << " dark, " << pose_pairs.saturated << " saturated)\n";
  return pose_pairs.pairs;
}

int RunAuto(const ColorcalArgs& args) {
  ModelDatabase database(args.db, OpenMode::kReadWrite);
  FindModelOrThrow(database, args.model);  // before reading frames: a wrong name fails at once
  if (args.frames.size() > 1 && !args.pose_path.empty()) {
    throw InputError("--pose " + args.pose_path + " is one frame's pose, but " + std::to_string(args.frames.size()) +
                     " frames were given: use frames with ground truth, or one frame");
  }
  std::vector<FrameSpec> specs;
  for (const std::string& path : args.frames) {
    specs.push_back(args.frame);
    specs.back().positional = path;
  }
  if (specs.empty()) specs.push_back(args.frame);

  // The mesh the recognizer verifies with: stored in the library, or (a model stored without) its file.
  std::vector<std::string> warnings;
  const TriangleMesh mesh = ModelMesh(database.LoadModels({args.model}).at(0).record, true, &warnings);
  for (const std::string& warning : warnings) std::cerr << "ecvpose: warning: " << warning << '\n';
  Renderer renderer;
  const MeshId id = renderer.AddMesh(mesh);

  std::vector<ColorPair> pairs;  // pooled over the frames
  std::string source = "auto:";
  for (const FrameSpec& spec : specs) {
    const std::vector<ColorPair> frame_pairs = PairsInFrame(args, spec, renderer, id);
    pairs.insert(pairs.end(), frame_pairs.begin(), frame_pairs.end());
    source += (&spec == &specs.front() ? "" : "+") + FrameName(spec);
  }
  if (pairs.size() < 3) {
    throw InputError("only " + std::to_string(pairs.size()) + " colour pairs of \"" + args.model + "\" in " +
                     source.substr(5) +
                     " (the model is not seen there, or the pose or depth is wrong); need at least 3");
  }
  const ColorFitOptions options = FitOptions(args);
  const ColorFit fit = FitColorMatrix(pairs, options);
  PrintFit(fit, pairs.size(), options.method);
  std::cout << "mean colour error: " << Fixed(MeanColorError(pairs), 6) << " -> "
            << Fixed(MeanColorError(pairs, fit.A), 6) << '\n';
  Store(database, args.model, fit, source);
  return kExitOk;
}

int RunShow(const ColorcalArgs& args) {
  const ModelDatabase database(args.db, OpenMode::kReadOnly);
  FindModelOrThrow(database, args.model);
  const std::optional<ColorMatrixRecord> matrix = database.GetColorMatrix(args.model);
  if (!matrix) {
    std::cout << args.model << ": no colour matrix (identity is used)\n";
    return kExitOk;
  }
  std::cout << args.model << ":\n";
  PrintMatrix(matrix->model_to_scene);
  std::cout << "rms: " << Fixed(matrix->rms, 6) << '\n'
            << "source: " << matrix->source << '\n'
            << "created: " << matrix->created << '\n';
  return kExitOk;
}

int RunClear(const ColorcalArgs& args) {
  ModelDatabase database(args.db, OpenMode::kReadWrite);
  FindModelOrThrow(database, args.model);
  if (database.ClearColorMatrix(args.model)) {
    std::cout << "cleared the colour matrix of " << args.model << " in " << args.db << '\n';
  } else {
    std::cout << args.model << " had no colour matrix\n";
  }
  return kExitOk;
}

CLI::App* AddModelCommand(CLI::App& command, const char* name, const char* summary, ColorcalArgs* args) {
  CLI::App* sub = command.add_subcommand(name, summary);
  AddDbOption(*sub, &args->db);
  sub->add_option("--model", args->model, "Model name")->required();
  return sub;
}

void AddMethodFlag(CLI::App& command, ColorcalArgs* args) {
  command
      .add_option("--method", args->method,
                  "ransac (robust to mislabelled pairs), irls (Tukey reweighting) or lsq (plain least squares)")
      ->check(CLI::IsMember({"ransac", "irls", "lsq"}))
      ->capture_default_str();
  command
      .add_option("--form", args->form,
                  "full (3x3), diagonal (per-channel gains) or auto (diagonal when the colours are of one hue)")
      ->check(CLI::IsMember({"full", "diagonal", "auto"}))
      ->capture_default_str();
  command.add_flag("--keep-brightness,!--no-keep-brightness", args->keep_brightness,
                   "Scale A so that the model's colours keep their brightness (correct the balance, not the exposure; "
                   "the default, for matching); --no-keep-brightness stores A c_model = c_scene as fitted");
}

}  // namespace

CommandAction SetupColorcalCommand(CLI::App& command) {
  auto args = std::make_shared<ColorcalArgs>();
  command.require_subcommand(1);
  CLI::App* fit =
      AddModelCommand(command, "fit", "Fit a model's colour matrix from a pairs CSV and store it", args.get());
  fit->add_option("--pairs", args->pairs_path,
                  "CSV of pixel pairs (model_image,x,y,scene_image,x,y) or RGB triplets (mr,mg,mb,sr,sg,sb)")
      ->required();
  AddMethodFlag(*fit, args.get());
  CLI::App* automatic = AddModelCommand(
      command, "auto", "Fit from a frame where the model's pose is known (render, depth agreement) and store it",
      args.get());
  automatic->add_option("FRAME", args->frames,
                        "Frame JSON, YCB-Video prefix, BOP SCENE_DIR:IMAGE_ID or organized .pcd; several: the pairs of "
                        "all are pooled into one fit");
  AddFrameFlags(*automatic, &args->frame);
  automatic->add_option("--pose", args->pose_path,
                        "Pose JSON with key camera_from_object (default: the frame's ground truth of the model)");
  automatic
      ->add_option("--max-depth-difference", args->max_depth_difference_m,
                   "Pixels are paired where rendered and real depth differ by at most this, metres")
      ->capture_default_str()
      ->check(Positive());
  AddMethodFlag(*automatic, args.get());
  CLI::App* show = AddModelCommand(command, "show", "Print a model's stored colour matrix", args.get());
  CLI::App* clear = AddModelCommand(command, "clear", "Remove a model's colour matrix", args.get());
  return [args, fit, automatic, show, clear]() -> int {
    if (fit->parsed()) return RunFit(*args);
    if (automatic->parsed()) return RunAuto(*args);
    if (show->parsed()) return RunShow(*args);
    if (clear->parsed()) return RunClear(*args);
    return kExitBadUsage;
  };
}

}  // namespace ecv::app
