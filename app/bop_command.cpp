// `ecvpose bop --dataset DIR --db LIB --out RESULTS.csv`: BOP's localisation task over a dataset's target images,
// one CSV line per estimate as the challenge takes them, resumable; then the average recall per object and overall.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

#include "app/commands.h"
#include "app/frame_args.h"
#include "app/recognize_flags.h"
#include "core/error.h"
#include "io/atomic_file.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "recognize/bop_evaluation.h"
#include "recognize/bop_task.h"
#include "recognize/evaluation.h"
#include "render/renderer.h"

namespace ecv::app {
namespace {

namespace fs = std::filesystem;
using Key = std::pair<int, int>;  // (scene_id, im_id)

struct BopArgs {
  RecognizerArgs recognizer;
  std::string dataset;
  std::string split = "test";
  std::string targets;      // default: DATASET/test_targets_bop19.json
  std::string out;          // the BOP CSV
  std::string models_info;  // default: DATASET/models/models_info.json when there
  std::string out_markdown, out_json;
  bool restart = false;
};

std::string SceneDir(const BopArgs& args, int scene) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d", scene);
  return (fs::path(args.dataset) / args.split / name).string();
}

std::string Minutes(double seconds) {
  std::ostringstream text;
  if (seconds < 60.0) {
    text << std::lround(seconds) << " s";
  } else {
    text << std::lround(seconds / 60.0) << " min";
  }
  return text.str();
}

// The images a run recorded as done, one "scene_id im_id" line each; an image not among `images` means the file
// belongs to another run.
std::set<Key> ReadProgress(const std::string& path, const std::vector<BopImage>& images, const std::string& targets) {
  std::set<Key> known, done;
  for (const BopImage& image : images) known.insert(image.key());
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "progress", "a readable file");
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream fields(line);
    Key key;
    std::string rest;
    if (!(fields >> key.first >> key.second) || (fields >> rest)) {
      ThrowInputError(path + ":" + std::to_string(number), "progress", "\"scene_id im_id\"", "'" + line + "'");
    }
    if (known.count(key) == 0) {
      ThrowInputError(path + ":" + std::to_string(number), "image",
                      "an image of the targets " + targets + " (the file is another run's: --restart)",
                      "scene " + std::to_string(key.first) + " image " + std::to_string(key.second));
    }
    done.insert(key);
  }
  return done;
}

// `out` rewritten with the rows of the images done alone: an image interrupted half-written is done again.
void KeepRowsOfDoneImages(const std::string& out, const std::set<Key>& done) {
  std::ifstream in(out);
  std::string line, kept = kBopCsvHeader;
  std::getline(in, line);  // the header
  while (std::getline(in, line)) {
    Key key{-1, -1};
    if (std::sscanf(line.c_str(), "%d,%d,", &key.first, &key.second) == 2 && done.count(key) > 0) kept += line + '\n';
  }
  WriteFileAtomically(out, kept);
}

// The estimates of every target image appended to `out`, each image's rows and then its progress line flushed at
// once; images done before are skipped. Returns the images that failed to load.
int RunImages(const BopArgs& args, const std::vector<BopImage>& images, std::set<Key> done,
              const std::string& progress_path, const ModelLibrary& library, Recognizer& recognizer) {
  const std::map<std::string, int> object_ids = LibraryObjectIds(library);
  const std::map<int, std::string> model_of_object = ModelOfObject(object_ids);
  std::ofstream csv(args.out, std::ios::app), progress(progress_path, std::ios::app);
  if (!csv || !progress) ThrowInputError(args.out, "--out", "a writable file");
  std::set<int> missing;
  for (const BopImage& image : images) TargetModels(image, model_of_object, &missing);
  if (!missing.empty()) {
    std::cerr << "bop: warning: no model in " << args.recognizer.db << " for object ids";
    for (int id : missing) std::cerr << ' ' << id;
    std::cerr << " of the targets: they count as not found\n";
  }
  const size_t before = done.size();
  int failed = 0;
  double seconds_run = 0.0;
  for (const BopImage& image : images) {
    if (done.count(image.key()) > 0) continue;
    const auto start = std::chrono::steady_clock::now();
    std::ostringstream where;
    where << "scene " << image.scene_id << " image " << image.image_id;
    try {
      FrameSpec spec;
      spec.positional = SceneDir(args, image.scene_id) + ":" + std::to_string(image.image_id);
      const LoadedFrame frame = LoadFrameWithWarnings(spec);
      const std::map<std::string, int> targets = TargetModels(image, model_of_object);
      const RecognitionResult result = recognizer.RecognizeTargets(frame.rgbd, targets);
      // BOP's time: from reading the image to the estimates, the same on each of the image's rows.
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::ostringstream rows;
      WriteBopRows(rows, image.key(), result.detections, object_ids, seconds);
      csv << rows.str() << std::flush;
      progress << image.scene_id << ' ' << image.image_id << '\n' << std::flush;
      if (!csv || !progress) ThrowInputError(args.out, "--out", "room to write the results");
      done.insert(image.key());
      seconds_run += seconds;
      const size_t run = done.size() - before;
      const double left = seconds_run / static_cast<double>(run) * static_cast<double>(images.size() - done.size());
      const auto rejected = std::count_if(result.detections.begin(), result.detections.end(),
                                          [](const Detection& d) { return !d.accepted; });
      std::cerr << "bop: [" << done.size() << "/" << images.size() << "] " << where.str() << ": "
                << result.detections.size() << " estimates (" << rejected << " not accepted) for " << targets.size()
                << " target objects";
      if (targets.size() < image.objects.size())
        std::cerr << " (and " << image.objects.size() - targets.size() << " without a model)";
      std::cerr << " in " << std::fixed << std::setprecision(1) << seconds << " s; about " << Minutes(left)
                << " left\n";
    } catch (const InputError& error) {
      ++failed;
      std::cerr << "bop: " << where.str() << " skipped (run again to retry it): " << error.what() << '\n';
    }
  }
  return failed;
}

// Average recall of the CSV's estimates against the ground truth of the target images (objects not in the library
// count as not found), per model and over all; false when the dataset has no ground truth.
bool PrintAverageRecall(const BopArgs& args, const std::vector<BopImage>& images, const ModelLibrary& library) {
  const std::map<std::string, int> object_ids = LibraryObjectIds(library);
  const std::map<int, std::string> model_of_object = ModelOfObject(object_ids);
  const std::map<Key, std::vector<Detection>> results = ReadBopResults(args.out, model_of_object);
  std::string models_info = args.models_info;
  const fs::path default_info = fs::path(args.dataset) / "models" / "models_info.json";
  if (models_info.empty() && fs::exists(default_info)) models_info = default_info.string();
  std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries;
  if (!models_info.empty()) symmetries = ReadBopSymmetries(models_info, library);
  Renderer renderer;
  BopJudge judge(library, EvalModels(library), symmetries, renderer);
  std::map<std::string, std::vector<BopObjectErrors>> by_model;
  std::set<std::string> unmodelled_names;
  int width = 0;
  for (size_t i = 0; i < images.size(); ++i) {
    const BopImage& image = images[i];
    FrameSpec spec;
    spec.positional = SceneDir(args, image.scene_id) + ":" + std::to_string(image.image_id);
    LoadedFrame frame = LoadFrameWithWarnings(spec);
    if (frame.ground_truth.empty()) {
      std::cerr << "bop: no ground truth for " << spec.positional << ": average recall not computed\n";
      return false;
    }
    width = frame.rgbd.camera.width;
    // The targets' instances, named as the library names their models; the others' counted as not found.
    NameTruthAfterModels(model_of_object, &frame.ground_truth);
    std::vector<GroundTruth> truth;
    std::map<int, int> unmodelled;
    for (GroundTruth& instance : frame.ground_truth) {
      if (image.objects.count(instance.object_id) == 0) continue;
      if (model_of_object.count(instance.object_id) > 0) {
        truth.push_back(std::move(instance));
      } else if (instance.visible_fraction < 0.0 || instance.visible_fraction >= 0.1) {
        ++unmodelled[instance.object_id];
      }
    }
    const auto found = results.find(image.key());
    const std::vector<Detection> none;
    const std::vector<BopObjectErrors> objects =
        judge.FrameErrors(frame.rgbd, found == results.end() ? none : found->second, truth);
    for (size_t k = 0; k < objects.size(); ++k) by_model[judge.judged_models()[k]].push_back(objects[k]);
    for (const auto& [object, instances] : unmodelled) {
      char name[48];
      std::snprintf(name, sizeof(name), "obj_%06d (no model)", object);
      BopObjectErrors missed;
      missed.instances = instances;
      by_model[name].push_back(missed);
      unmodelled_names.insert(name);
    }
    std::cerr << "bop: judged [" << i + 1 << "/" << images.size() << "] " << spec.positional << '\n';
  }
  std::string table = args.out + ": BOP average recall over " + std::to_string(images.size()) + " images of " +
                      args.dataset + " (symmetries " +
                      (models_info.empty() ? std::string("none: no models_info.json") : "of " + models_info) + ")\n\n" +
                      BopRecallMarkdown(by_model, width);
  std::vector<BopObjectErrors> modelled;
  for (const auto& [name, objects] : by_model) {
    if (unmodelled_names.count(name) == 0) modelled.insert(modelled.end(), objects.begin(), objects.end());
  }
  if (!unmodelled_names.empty()) {
    const BopRecall recall = AverageRecall(modelled, width);
    std::ostringstream line;
    line << std::fixed << std::setprecision(3) << "\nOver the objects the library has a model of (" << recall.instances
         << " instances): AR " << recall.ar << "\n";
    table += line.str();
  }
  std::cout << table;
  if (!args.out_markdown.empty()) WriteFileAtomically(args.out_markdown, table);
  if (!args.out_json.empty()) WriteJsonFile(args.out_json, BopRecallJson(by_model, width));
  return true;
}

int RunBop(const BopArgs& args) {
  if (!fs::is_directory(args.dataset)) {
    ThrowInputError(args.dataset, "--dataset", "a BOP dataset folder (test_targets_bop19.json, " + args.split + "/)",
                    "no such directory");
  }
  const std::string targets =
      args.targets.empty() ? (fs::path(args.dataset) / "test_targets_bop19.json").string() : args.targets;
  const std::vector<BopImage> images = GroupBopTargets(ReadBopTargets(targets), targets);
  if (images.empty()) ThrowInputError(targets, "targets", "at least one image", "none");
  const std::string progress_path = args.out + ".progress";
  if (args.restart) {
    fs::remove(args.out);
    fs::remove(progress_path);
  }
  // A CSV without its progress file is a finished run: only its recall is computed again.
  const bool finished = fs::exists(args.out) && !fs::exists(progress_path);
  const RecognizerOptions options = RecognizerOptionsFromArgs(args.recognizer);
  LoadedRecognizer loaded = LoadRecognizer(args.recognizer, options, "bop");
  int failed = 0;
  if (finished) {
    std::cerr << "bop: " << args.out << " is a finished run (no " << progress_path
              << "): its average recall follows; --restart runs the images again\n";
  } else {
    std::set<Key> done;
    if (fs::exists(progress_path) && fs::exists(args.out)) {
      done = ReadProgress(progress_path, images, targets);
      KeepRowsOfDoneImages(args.out, done);
      std::cerr << "bop: resuming " << args.out << ": " << done.size() << " of " << images.size() << " images done\n";
    } else {
      WriteFileAtomically(args.out, kBopCsvHeader);
      WriteFileAtomically(progress_path, "");
    }
    failed = RunImages(args, images, done, progress_path, *loaded.library, *loaded.recognizer);
    if (failed == 0) fs::remove(progress_path);
  }
  loaded.recognizer.reset();  // its renderer's context: the judge makes its own
  PrintAverageRecall(args, images, *loaded.library);
  if (failed > 0) {
    std::cerr << "bop: " << failed << " images failed; run the same command again to retry them\n";
    return kExitBadInput;
  }
  return kExitOk;
}

}  // namespace

CommandAction SetupBopCommand(CLI::App& command) {
  auto args = std::make_shared<BopArgs>();
  AddRecognizerFlags(command, &args->recognizer);
  command.add_option("--dataset", args->dataset, "BOP dataset folder (test_targets_bop19.json, test/, models/)")
      ->required();
  command.add_option("--split", args->split, "The images' folder in the dataset")->capture_default_str();
  command.add_option("--targets", args->targets, "Targets file (default: DATASET/test_targets_bop19.json)");
  command.add_option("--out", args->out, "Results as BOP CSV (scene_id,im_id,obj_id,score,R,t,time)")->required();
  command.add_option("--models-info", args->models_info,
                     "Symmetries for the average recall (default: DATASET/models/models_info.json when there)");
  command.add_flag("--restart", args->restart, "Run every image again, discarding --out and its progress");
  command.add_option("--out-md", args->out_markdown, "The average recall table as a markdown file");
  command.add_option("--out-json", args->out_json, "The average recall per model and over all as JSON");
  command.footer(
      "Each target image is recognised for its target objects alone, each reporting up to its instance count of\n"
      "estimates without a threshold (recognize --targets); its rows are appended to --out at once, and OUT.progress\n"
      "lists the images done: an interrupted run continues where it stopped when started again with the same\n"
      "flags. At the end the average recall (VSD, MSSD, MSPD; docs/bop.md) per object and overall.\n"
      "Example:\n  scripts/make_bop_dataset lmo lmo-bop && scripts/build_bop_library lmo-bop lmo.sqlite\n"
      "  ecvpose bop --dataset lmo-bop --db lmo.sqlite --out lmo.csv");
  return [args] { return RunBop(*args); };
}

}  // namespace ecv::app
