// Detections files (recognize's JSON Lines, BOP CSV) judged against a folder of ground truth (YCB-Video video, BOP
// scene): reading both, then EvaluateFrame per frame.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "io/frame_io.h"
#include "io/pose_io.h"
#include "recognize/evaluation.h"
#include "recognize/recognition_json.h"

namespace ecv {
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

std::vector<FolderFrame> ReadFolderDetections(const std::string& detections_path, GroundTruthFolder kind,
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
  std::vector<FolderFrame> frames;
  for (const auto& [number, frame] : truth.frames) {
    FolderFrame folder_frame;
    folder_frame.frame = frame;
    folder_frame.ground_truth =
        kind == GroundTruthFolder::kYcbVideo ? LoadYcbvFrame(frame).ground_truth : ReadBopGroundTruth(folder, number);
    const auto found = detections.find(number);
    if (found == detections.end()) {
      folder_frame.missed = "no line in the detections";
    } else if (!found->second.error.empty()) {
      folder_frame.missed = "recognize failed: " + found->second.error;
    } else {
      folder_frame.detections = found->second.detections;
    }
    frames.push_back(std::move(folder_frame));
  }
  return frames;
}

std::vector<FrameEvaluation> EvaluateDetectionsFile(const std::string& detections_path, GroundTruthFolder kind,
                                                    const std::string& folder, const std::vector<EvalModel>& models) {
  std::vector<FrameEvaluation> evaluations;
  for (const FolderFrame& frame : ReadFolderDetections(detections_path, kind, folder, models)) {
    evaluations.push_back(EvaluateFrame(frame.frame, frame.detections, frame.ground_truth, models));
    evaluations.back().missed = frame.missed;
  }
  return evaluations;
}

}  // namespace ecv
