#include "recognize/evaluation.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/point_index.h"
#include "io/frame_io.h"
#include "io/pose_io.h"

namespace ecv {

EvalModel EvalModelFromRecord(const ModelRecord& record, size_t max_points) {
  const TriangleMesh mesh = ModelMesh(record, /*with_textures=*/false);
  EvalModel model;
  model.name = record.name;
  model.diameter_m = record.diameter_m;
  model.symmetric = record.symmetric;
  const size_t step = std::max<size_t>(1, mesh.NumVertices() / std::max<size_t>(max_points, 1));
  size_t vertex = 0;
  for (const MeshPart& part : mesh.parts) {
    for (const Eigen::Vector3f& position : part.positions) {
      if (vertex++ % step == 0) model.points.push_back(position);
    }
  }
  return model;
}

std::vector<EvalModel> EvalModels(const ModelLibrary& library) {
  std::vector<EvalModel> models;
  for (const LibraryModel& model : library.models()) models.push_back(EvalModelFromRecord(model.record));
  return models;
}

PoseError ComputePoseError(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
                           const Eigen::Isometry3d& truth) {
  PoseError error;
  error.rotation_deg = RotationAngle(estimate, truth) * 180.0 / M_PI;
  error.translation_mm = TranslationDistance(estimate, truth) * 1000.0;
  if (points.empty()) return error;
  const Eigen::Isometry3f a = estimate.cast<float>(), b = truth.cast<float>();
  std::vector<Eigen::Vector3f> under_truth;
  under_truth.reserve(points.size());
  double add = 0.0;
  for (const Eigen::Vector3f& point : points) {
    under_truth.push_back(b * point);
    add += (a * point - under_truth.back()).norm();
  }
  const PointIndex index(under_truth);
  double adds = 0.0;
  for (const Eigen::Vector3f& point : points) adds += std::sqrt(index.Nearest(a * point).second);
  error.add_m = add / static_cast<double>(points.size());
  error.adds_m = adds / static_cast<double>(points.size());
  return error;
}

FrameEvaluation EvaluateFrame(const std::string& frame, const std::vector<Detection>& detections,
                              const std::vector<GroundTruth>& truth, const std::vector<EvalModel>& models) {
  FrameEvaluation evaluation;
  evaluation.frame = frame;
  auto add_false_positive = [&](const std::string& model) {
    ++evaluation.false_positives;
    evaluation.false_positive_models.push_back(model);
  };
  std::map<std::string, const EvalModel*> by_name;
  for (const EvalModel& model : models) by_name[model.name] = &model;
  // Per ground-truth object of a library model: its result, and the error of every detection of its model.
  struct Instance {
    const GroundTruth* truth;
    const EvalModel* model;
    ObjectEvaluation result;
  };
  std::vector<Instance> instances;
  for (const GroundTruth& object : truth) {
    const auto model = by_name.find(object.object_name);
    if (model == by_name.end()) continue;  // not in the library: not asked for
    Instance instance{&object, model->second, {}};
    instance.result.model = object.object_name;
    instance.result.diameter_m = model->second->diameter_m;
    instances.push_back(instance);
  }
  auto correct = [](const Instance& instance, const PoseError& error) {
    const double distance = instance.model->symmetric ? error.adds_m : error.add_m;
    return distance < 0.1 * instance.model->diameter_m;
  };
  // Best score first, each detection takes the nearest (by ADD) instance of its model that it finds correctly
  // and that no better detection took; one that takes none is a false positive.
  std::vector<const Detection*> ranked;
  for (const Detection& detection : detections) ranked.push_back(&detection);
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const Detection* a, const Detection* b) { return a->score > b->score; });
  std::vector<const Detection*> unmatched;
  for (const Detection* detection : ranked) {
    Instance* taken = nullptr;
    PoseError taken_error;
    for (Instance& instance : instances) {
      if (instance.truth->object_name != detection->model || instance.result.correct) continue;
      const PoseError error =
          ComputePoseError(instance.model->points, detection->camera_from_object, instance.truth->camera_from_object);
      if (correct(instance, error) && (taken == nullptr || error.add_m < taken_error.add_m)) {
        taken = &instance;
        taken_error = error;
      }
    }
    if (taken == nullptr) {
      add_false_positive(detection->model);
      unmatched.push_back(detection);
      continue;
    }
    taken->result.detected = taken->result.correct = true;
    taken->result.error = taken_error;
  }
  // An instance no detection found is still shown with the error of its model's best unmatched detection
  // (already a false positive), if any.
  for (Instance& instance : instances) {
    if (instance.result.correct) continue;
    for (const Detection* detection : unmatched) {
      if (detection->model != instance.truth->object_name) continue;
      instance.result.detected = true;
      instance.result.error =
          ComputePoseError(instance.model->points, detection->camera_from_object, instance.truth->camera_from_object);
      break;
    }
  }
  for (const Instance& instance : instances) evaluation.objects.push_back(instance.result);
  return evaluation;
}

namespace {

struct Tally {
  int objects = 0, detected = 0, correct = 0, false_positives = 0;
};

double Ratio(int count, int total) {
  return total > 0 ? static_cast<double>(count) / total : 0.0;
}

// Totals per model (by name) and, under "", over all models.
std::map<std::string, Tally> TallyByModel(const std::vector<FrameEvaluation>& frames) {
  std::map<std::string, Tally> tallies;
  for (const FrameEvaluation& frame : frames) {
    for (const ObjectEvaluation& object : frame.objects) {
      for (Tally* tally : {&tallies[object.model], &tallies[""]}) {
        ++tally->objects;
        tally->detected += object.detected ? 1 : 0;
        tally->correct += object.correct ? 1 : 0;
      }
    }
    for (const std::string& model : frame.false_positive_models) ++tallies[model].false_positives;
    tallies[""].false_positives += frame.false_positives;
  }
  return tallies;
}

int CountMissedFrames(const std::vector<FrameEvaluation>& frames) {
  return static_cast<int>(
      std::count_if(frames.begin(), frames.end(), [](const FrameEvaluation& f) { return !f.missed.empty(); }));
}

}  // namespace

std::string EvaluationMarkdown(const std::vector<FrameEvaluation>& frames) {
  std::ostringstream out;
  out << "| frame | object | detected | rotation (deg) | translation (mm) | ADD (mm) | ADD-S (mm) | 0.1 d (mm) | "
         "correct |\n|---|---|---|---:|---:|---:|---:|---:|---|\n";
  char line[512];
  for (const FrameEvaluation& frame : frames) {
    for (const ObjectEvaluation& object : frame.objects) {
      if (object.detected) {
        std::snprintf(line, sizeof(line), "| %s | %s | yes | %.1f | %.1f | %.1f | %.1f | %.1f | %s |\n",
                      frame.frame.c_str(), object.model.c_str(), object.error.rotation_deg, object.error.translation_mm,
                      object.error.add_m * 1000.0, object.error.adds_m * 1000.0, object.diameter_m * 100.0,
                      object.correct ? "yes" : "no");
      } else {
        std::snprintf(line, sizeof(line), "| %s | %s | no | | | | | %.1f | no |\n", frame.frame.c_str(),
                      object.model.c_str(), object.diameter_m * 100.0);
      }
      out << line;
    }
  }
  const int missed_frames = CountMissedFrames(frames);
  if (missed_frames > 0) {
    out << "\nFrames counted as missed (all their objects not detected): " << missed_frames << " of " << frames.size()
        << "\n";
    for (const FrameEvaluation& frame : frames) {
      if (!frame.missed.empty()) out << "- " << frame.frame << ": " << frame.missed << "\n";
    }
  }
  const std::map<std::string, Tally> tallies = TallyByModel(frames);
  const Tally all = tallies.count("") > 0 ? tallies.at("") : Tally{};
  std::snprintf(line, sizeof(line),
                "\nRecall at ADD < 0.1 d: %d of %d (%.1f %%); false positives: %d (%.2f per frame)\n", all.correct,
                all.objects, 100.0 * Ratio(all.correct, all.objects), all.false_positives,
                frames.empty() ? 0.0 : static_cast<double>(all.false_positives) / static_cast<double>(frames.size()));
  out << line;
  out << "\n| model | objects | detected | correct | recall | false positives |\n|---|---:|---:|---:|---:|---:|\n";
  for (const auto& [model, tally] : tallies) {
    if (model.empty()) continue;
    std::snprintf(line, sizeof(line), "| %s | %d | %d | %d | %.1f %% | %d |\n", model.c_str(), tally.objects,
                  tally.detected, tally.correct, 100.0 * Ratio(tally.correct, tally.objects), tally.false_positives);
    out << line;
  }
  return out.str();
}

nlohmann::json EvaluationToJson(const std::vector<FrameEvaluation>& frames) {
  nlohmann::json json_frames = nlohmann::json::array();
  for (const FrameEvaluation& frame : frames) {
    nlohmann::json objects = nlohmann::json::array();
    for (const ObjectEvaluation& object : frame.objects) {
      nlohmann::json item = {{"model", object.model},
                             {"diameter_m", object.diameter_m},
                             {"detected", object.detected},
                             {"correct", object.correct}};
      if (object.detected) {
        item["rotation_error_rad"] = object.error.rotation_deg * M_PI / 180.0;
        item["translation_error_m"] = object.error.translation_mm / 1000.0;
        item["add_m"] = object.error.add_m;
        item["adds_m"] = object.error.adds_m;
      }
      objects.push_back(item);
    }
    nlohmann::json item = {{"frame", frame.frame},
                           {"objects", objects},
                           {"false_positives", frame.false_positives},
                           {"false_positive_models", frame.false_positive_models}};
    if (!frame.missed.empty()) item["missed"] = frame.missed;
    json_frames.push_back(item);
  }
  nlohmann::json models = nlohmann::json::array();
  nlohmann::json summary;
  for (const auto& [model, tally] : TallyByModel(frames)) {
    const nlohmann::json item = {{"objects", tally.objects},
                                 {"detected", tally.detected},
                                 {"correct", tally.correct},
                                 {"recall", Ratio(tally.correct, tally.objects)},
                                 {"false_positives", tally.false_positives}};
    if (model.empty()) {
      summary = item;
    } else {
      models.push_back(item);
      models.back()["model"] = model;
    }
  }
  if (summary.is_null()) summary = {{"objects", 0}, {"detected", 0}, {"correct", 0}, {"recall", 0.0}};
  summary["frames"] = frames.size();
  summary["frames_missed"] = CountMissedFrames(frames);
  if (!summary.contains("false_positives")) summary["false_positives"] = 0;
  return {{"frames", json_frames}, {"summary", summary}, {"models", models}};
}

// ---- Detections files against a folder of ground truth ----

namespace {
namespace fs = std::filesystem;

// The detections a file gives for one frame.
struct FrameDetections {
  std::string source;  // "FILE:LINE" of its (first) line
  std::vector<Detection> detections;
  std::string error;  // recognize's error for the frame
};

// A folder of ground truth: its name, its frames by image number, and the numbers detections may name.
struct TruthFolder {
  GroundTruthFolder kind;
  std::string path, name;
  std::map<int, std::string> frames;  // image number -> FRAME ("DIR/000001" or "DIR:3")
  std::set<int> known;                // image numbers with ground truth
};

// A decimal image or scene number (as in "000001"), or -1.
int ParseNumber(const std::string& text) {
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(text);
}

std::string Trimmed(const std::string& text) {
  const size_t begin = text.find_first_not_of(" \t\r");
  return begin == std::string::npos ? "" : text.substr(begin, text.find_last_not_of(" \t\r") + 1 - begin);
}

// The comma-separated cells of a CSV line, trimmed (BOP CSV cells hold no quoted commas).
std::vector<std::string> SplitCsv(const std::string& text) {
  std::vector<std::string> cells(1);
  for (const char c : text) {
    if (c == ',') {
      cells.emplace_back();
    } else {
      cells.back() += c;
    }
  }
  for (std::string& cell : cells) cell = Trimmed(cell);
  return cells;
}

TruthFolder ListTruthFolder(GroundTruthFolder kind, const std::string& folder) {
  const char* flag = kind == GroundTruthFolder::kYcbVideo ? "--gt-ycbv" : "--gt-bop";
  if (!fs::is_directory(folder)) ThrowInputError(folder, flag, "a directory", "no such directory");
  TruthFolder truth{kind, folder, fs::weakly_canonical(folder).filename().string(), {}, {}};
  if (kind == GroundTruthFolder::kYcbVideo) {
    for (const auto& entry : fs::directory_iterator(folder)) {
      const std::string name = entry.path().filename().string();
      const int number = name.size() > 10 ? ParseNumber(name.substr(0, name.size() - 10)) : -1;
      if (number >= 0 && name.compare(name.size() - 10, 10, "-color.png") == 0) {
        truth.frames[number] = (fs::path(folder) / name.substr(0, name.size() - 10)).string();
        truth.known.insert(number);
      }
    }
    if (truth.frames.empty()) ThrowInputError(folder, flag, "YCB-Video frames (NNNNNN-color.png, -meta.mat)", "none");
    return truth;
  }
  const std::string gt_path = (fs::path(folder) / "scene_gt.json").string();
  const nlohmann::json gt = ReadJsonFile(gt_path);
  if (!gt.is_object()) ThrowInputError(gt_path, "image ids", "an object keyed by image id");
  for (const auto& item : gt.items()) {
    const int id = ParseNumber(item.key());
    if (id < 0) ThrowInputError(gt_path, item.key(), "image ids as decimal keys");
    truth.known.insert(id);
    char stem[16];
    std::snprintf(stem, sizeof(stem), "%06d", id);
    for (const auto& [images, extension] :
         {std::pair{"rgb", ".png"}, std::pair{"rgb", ".jpg"}, std::pair{"gray", ".png"}, std::pair{"gray", ".tif"}}) {
      if (fs::exists(fs::path(folder) / images / (stem + std::string(extension)))) {
        truth.frames[id] = folder + ":" + std::to_string(id);
      }
    }
  }
  return truth;
}

// The image number of a FRAME string of a recognize line in `truth`'s folder, or an InputError.
int FrameNumber(const TruthFolder& truth, const std::string& frame, const std::string& source) {
  std::string folder_name;
  int number = -1;
  if (truth.kind == GroundTruthFolder::kYcbVideo) {
    const fs::path path = fs::weakly_canonical(frame);
    folder_name = path.parent_path().filename().string();
    number = ParseNumber(path.filename().string());
  } else if (frame.rfind(':') != std::string::npos) {
    const size_t colon = frame.rfind(':');
    folder_name = fs::weakly_canonical(frame.substr(0, colon)).filename().string();
    number = ParseNumber(frame.substr(colon + 1));
  }
  if (folder_name != truth.name || truth.known.count(number) == 0) {
    const std::string form = truth.kind == GroundTruthFolder::kYcbVideo ? truth.path + "/NNNNNN" : truth.path + ":ID";
    ThrowInputError(source, "frame", "a frame of " + truth.path + " (" + form + ") with ground truth",
                    "'" + frame + "'");
  }
  return number;
}

void CheckModel(const std::string& model, const std::vector<EvalModel>& models, const std::string& source,
                const std::string& field) {
  std::string names;
  for (const EvalModel& known : models) {
    if (known.name == model) return;
    names += (names.empty() ? "" : ", ") + known.name;
  }
  ThrowInputError(source, field, "a model of the library (" + names + ")", "'" + model + "'");
}

void Insert(std::map<int, FrameDetections>* frames, int number, FrameDetections detections) {
  const auto [previous, inserted] = frames->emplace(number, detections);
  if (!inserted)
    ThrowInputError(detections.source, "frame", "each frame once", "again (first at " + previous->second.source + ")");
}

// JSON Lines of `recognize --sequence`.
std::map<int, FrameDetections> ReadDetectionLines(const std::string& path, const TruthFolder& truth,
                                                  const std::vector<EvalModel>& models) {
  std::ifstream in(path);
  if (!in) ThrowInputError(path, "detections", "a readable file (JSON Lines or BOP CSV)");
  std::map<int, FrameDetections> frames;
  int number = 0;
  for (std::string text; std::getline(in, text);) {
    const std::string source = path + ":" + std::to_string(++number);
    if (Trimmed(text).empty()) continue;
    nlohmann::json line;
    try {
      line = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& error) {
      ThrowInputError(source, "JSON", "one JSON object per line (recognize --sequence --out-json)", error.what());
    }
    if (!line.is_object() || !line.contains("frame") || !line["frame"].is_string()) {
      ThrowInputError(source, "frame", "a string naming the frame of the line");
    }
    FrameDetections detections;
    detections.source = source;
    const int image = FrameNumber(truth, line["frame"].get<std::string>(), source);
    if (line.contains("error")) {
      detections.error = line["error"].is_string() ? line["error"].get<std::string>() : line["error"].dump();
    } else {
      detections.detections = DetectionsFromJson(line, source);
      for (size_t i = 0; i < detections.detections.size(); ++i) {
        CheckModel(detections.detections[i].model, models, source, "detections[" + std::to_string(i) + "].model");
      }
    }
    Insert(&frames, image, detections);
  }
  return frames;
}

std::vector<double> CsvNumbers(const std::string& text, size_t count, const std::string& source,
                               const std::string& field) {
  std::istringstream stream(text);
  std::vector<double> values;
  for (double value = 0.0; stream >> value;) values.push_back(value);
  if (!stream.eof() || values.size() != count) {
    ThrowInputError(source, field, std::to_string(count) + " numbers separated by spaces", "'" + text + "'");
  }
  return values;
}

int CsvInteger(const std::string& text, const std::string& source, const std::string& field) {
  const int value = ParseNumber(text);
  if (value < 0) ThrowInputError(source, field, "a non-negative integer", "'" + text + "'");
  return value;
}

std::string ObjectName(int object_id, GroundTruthFolder kind, const std::string& source) {
  if (kind == GroundTruthFolder::kYcbVideo) {
    if (object_id < 1 || object_id > 21) {
      ThrowInputError(source, "obj_id", "a YCB-Video class index in 1..21", std::to_string(object_id));
    }
    return YcbvClassName(object_id);
  }
  char name[32];
  std::snprintf(name, sizeof(name), "obj_%06d", object_id);
  return name;
}

// One detection of a BOP CSV row; `columns` maps the header's names to their column.
Detection CsvDetection(const std::vector<std::string>& cells, const std::map<std::string, size_t>& columns,
                       GroundTruthFolder kind, const std::string& source, const std::vector<EvalModel>& models) {
  auto cell = [&](const char* name) { return cells[columns.at(name)]; };
  Detection detection;
  const int object_id = CsvInteger(cell("obj_id"), source, "obj_id");
  detection.model = ObjectName(object_id, kind, source);
  CheckModel(detection.model, models, source, "obj_id");
  detection.score = CsvNumbers(cell("score"), 1, source, "score")[0];
  const std::vector<double> r = CsvNumbers(cell("R"), 9, source, "R");
  const std::vector<double> t = CsvNumbers(cell("t"), 3, source, "t");
  CsvNumbers(cell("time"), 1, source, "time");
  Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) matrix(row, col) = r[static_cast<size_t>(3 * row + col)];
    matrix(row, 3) = t[static_cast<size_t>(row)] / 1000.0;  // mm -> m
  }
  detection.camera_from_object = RigidFromMatrix(matrix, source, "R");
  return detection;
}

// BOP CSV: scene_id,im_id,obj_id,score,R,t,time with a header line naming the columns.
std::map<int, FrameDetections> ReadBopCsv(const std::string& path, const TruthFolder& truth,
                                          const std::vector<EvalModel>& models) {
  static const std::vector<std::string> kColumns = {"scene_id", "im_id", "obj_id", "score", "R", "t", "time"};
  std::ifstream in(path);
  std::string text;
  if (!in || !std::getline(in, text)) ThrowInputError(path + ":1", "header", "scene_id,im_id,obj_id,score,R,t,time");
  const std::vector<std::string> header = SplitCsv(text);
  std::map<std::string, size_t> columns;
  for (size_t i = 0; i < header.size(); ++i) columns[header[i]] = i;
  for (const std::string& column : kColumns) {
    if (columns.count(column) == 0) {
      ThrowInputError(path + ":1", column, "a column named so (header scene_id,im_id,obj_id,score,R,t,time)",
                      "'" + Trimmed(text) + "'");
    }
  }
  const int scene = ParseNumber(truth.name);
  std::map<int, FrameDetections> frames;
  for (int number = 2; std::getline(in, text); ++number) {
    const std::string source = path + ":" + std::to_string(number);
    if (Trimmed(text).empty()) continue;
    const std::vector<std::string> cells = SplitCsv(text);
    for (const std::string& column : kColumns) {
      if (columns.at(column) >= cells.size()) {
        ThrowInputError(source, column, "a value in column " + std::to_string(columns.at(column) + 1),
                        std::to_string(cells.size()) + " columns");
      }
    }
    if (cells.size() > header.size()) {
      ThrowInputError(source, "columns", std::to_string(header.size()) + " as the header",
                      std::to_string(cells.size()));
    }
    if (CsvInteger(cells[columns.at("scene_id")], source, "scene_id") != scene) {
      ThrowInputError(source, "scene_id", "the scene of " + truth.path + " (" + std::to_string(scene) + ")",
                      cells[columns.at("scene_id")]);
    }
    const int image = CsvInteger(cells[columns.at("im_id")], source, "im_id");
    if (truth.known.count(image) == 0) {
      ThrowInputError(source, "im_id", "an image of " + truth.path + " with ground truth", std::to_string(image));
    }
    FrameDetections& frame = frames[image];
    if (frame.source.empty()) frame.source = source;
    frame.detections.push_back(CsvDetection(cells, columns, truth.kind, source, models));
  }
  return frames;
}

bool IsCsv(const std::string& path) {
  if (fs::path(path).extension() == ".csv") return true;
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  return Trimmed(first).rfind("scene_id", 0) == 0;
}

}  // namespace

std::vector<FrameEvaluation> EvaluateDetectionsFile(const std::string& detections_path, GroundTruthFolder kind,
                                                    const std::string& folder, const std::vector<EvalModel>& models) {
  TruthFolder truth = ListTruthFolder(kind, folder);
  if (!fs::is_regular_file(detections_path)) {
    ThrowInputError(detections_path, "--detections", "a JSON Lines or BOP CSV file", "no such file");
  }
  if (IsCsv(detections_path) && ParseNumber(truth.name) < 0) {
    ThrowInputError(folder, "scene id", "a folder named by its number, for the CSV's scene_id", truth.name);
  }
  const std::map<int, FrameDetections> detections = IsCsv(detections_path)
                                                        ? ReadBopCsv(detections_path, truth, models)
                                                        : ReadDetectionLines(detections_path, truth, models);
  for (const auto& item : detections) {  // BOP images with ground truth but no image file, named by the file
    if (truth.frames.count(item.first) == 0) truth.frames[item.first] = folder + ":" + std::to_string(item.first);
  }
  if (truth.frames.empty()) {
    ThrowInputError(folder, "frames", "images of scene_gt.json with an rgb/ image, or detections naming some", "none");
  }
  std::vector<FrameEvaluation> evaluations;
  for (const auto& [number, frame] : truth.frames) {
    const std::vector<GroundTruth> ground_truth =
        kind == GroundTruthFolder::kYcbVideo ? LoadYcbvFrame(frame).ground_truth : ReadBopGroundTruth(folder, number);
    const auto found = detections.find(number);
    const bool judged = found != detections.end() && found->second.error.empty();
    evaluations.push_back(
        EvaluateFrame(frame, judged ? found->second.detections : std::vector<Detection>{}, ground_truth, models));
    if (found == detections.end()) {
      evaluations.back().missed = "no line in the detections";
    } else if (!judged) {
      evaluations.back().missed = "recognize failed: " + found->second.error;
    }
  }
  return evaluations;
}

}  // namespace ecv
