#include "recognize/bop_task.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/pose.h"
#include "io/pose_io.h"

namespace ecv {
namespace {

// A non-negative integer field of a targets entry.
int TargetField(const nlohmann::json& entry, const char* field, const std::string& where) {
  if (!entry.contains(field) || !entry[field].is_number_integer() || entry[field].get<int64_t>() < 0 ||
      entry[field].get<int64_t>() > 999999) {
    ThrowInputError(where, field, "an integer from 0 to 999999",
                    entry.contains(field) ? entry[field].dump() : std::string("nothing"));
  }
  return entry[field].get<int>();
}

// `text` split at commas (BOP's CSV has no quoting).
std::vector<std::string> SplitAtCommas(const std::string& text) {
  std::vector<std::string> cells;
  std::stringstream stream(text);
  for (std::string cell; std::getline(stream, cell, ',');) cells.push_back(cell);
  if (!text.empty() && text.back() == ',') cells.emplace_back();
  return cells;
}

// Exactly `count` finite numbers separated by spaces.
std::vector<double> Numbers(const std::string& cell, size_t count, const std::string& source, const char* field) {
  std::vector<double> values;
  const char* at = cell.c_str();
  while (true) {
    while (*at == ' ' || *at == '\t' || *at == '\r') ++at;
    if (*at == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(at, &end);
    if (end == at || errno == ERANGE || !std::isfinite(value)) {
      ThrowInputError(source, field, std::to_string(count) + " numbers separated by spaces", "'" + cell + "'");
    }
    values.push_back(value);
    at = end;
  }
  if (values.size() != count) {
    ThrowInputError(source, field, std::to_string(count) + " numbers separated by spaces",
                    std::to_string(values.size()));
  }
  return values;
}

int Integer(const std::string& cell, const std::string& source, const char* field) {
  const std::vector<double> value = Numbers(cell, 1, source, field);
  if (value[0] < 0.0 || value[0] > 999999.0 || value[0] != std::floor(value[0])) {
    ThrowInputError(source, field, "an integer from 0 to 999999", "'" + cell + "'");
  }
  return static_cast<int>(value[0]);
}

}  // namespace

std::map<std::string, int> LibraryObjectIds(const ModelLibrary& library) {
  std::vector<std::pair<std::string, int64_t>> models;
  for (const LibraryModel& model : library.models()) models.emplace_back(model.record.name, model.record.id);
  return BopObjectIds(std::move(models));
}

std::map<int, std::string> ModelOfObject(const std::map<std::string, int>& object_ids) {
  std::map<int, std::string> models;
  for (const auto& [name, id] : object_ids) models[id] = name;
  return models;
}

void NameTruthAfterModels(const std::map<int, std::string>& model_of_object, std::vector<GroundTruth>* truth) {
  std::set<std::string> models;
  for (const auto& [id, name] : model_of_object) models.insert(name);
  for (GroundTruth& instance : *truth) {
    const auto model = model_of_object.find(instance.object_id);
    if (models.count(instance.object_name) == 0 && model != model_of_object.end()) {
      instance.object_name = model->second;
    }
  }
}

std::vector<BopTarget> ReadBopTargets(const std::string& path) {
  const nlohmann::json json = ReadJsonFile(path);
  if (!json.is_array()) ThrowInputError(path, "targets", "an array of {scene_id, im_id, obj_id, inst_count}");
  std::vector<BopTarget> targets;
  for (size_t i = 0; i < json.size(); ++i) {
    const std::string where = path + ": [" + std::to_string(i) + "]";
    if (!json[i].is_object()) ThrowInputError(where, "entry", "an object {scene_id, im_id, obj_id, inst_count}");
    BopTarget target;
    target.scene_id = TargetField(json[i], "scene_id", where);
    target.image_id = TargetField(json[i], "im_id", where);
    target.object_id = TargetField(json[i], "obj_id", where);
    target.instances = TargetField(json[i], "inst_count", where);
    if (target.instances < 1) ThrowInputError(where, "inst_count", "at least 1", "0");
    targets.push_back(target);
  }
  return targets;
}

std::vector<BopImage> GroupBopTargets(const std::vector<BopTarget>& targets, const std::string& source) {
  std::map<std::pair<int, int>, BopImage> images;
  for (const BopTarget& target : targets) {
    BopImage& image = images[{target.scene_id, target.image_id}];
    image.scene_id = target.scene_id;
    image.image_id = target.image_id;
    if (!image.objects.emplace(target.object_id, target.instances).second) {
      ThrowInputError(source, "obj_id",
                      "each object once per image; " + std::to_string(target.object_id) +
                          " is listed twice for scene " + std::to_string(target.scene_id) + " image " +
                          std::to_string(target.image_id));
    }
  }
  std::vector<BopImage> ordered;
  for (auto& [key, image] : images) ordered.push_back(std::move(image));
  return ordered;
}

std::map<std::string, int> TargetModels(const BopImage& image, const std::map<int, std::string>& model_of_object,
                                        std::set<int>* missing) {
  std::map<std::string, int> models;
  for (const auto& [object, instances] : image.objects) {
    const auto model = model_of_object.find(object);
    if (model != model_of_object.end()) {
      models[model->second] = instances;
    } else if (missing != nullptr) {
      missing->insert(object);
    }
  }
  return models;
}

void WriteBopRows(std::ostream& out, std::pair<int, int> scene_image, const std::vector<Detection>& detections,
                  const std::map<std::string, int>& object_ids, double seconds) {
  const std::streamsize precision = out.precision(9);
  for (const Detection& d : detections) {
    const Eigen::Matrix3d r = d.camera_from_object.linear();
    const Eigen::Vector3d t = d.camera_from_object.translation() * 1000.0;  // m -> mm
    out << scene_image.first << ',' << scene_image.second << ',' << object_ids.at(d.model) << ',' << d.score << ',';
    for (int i = 0; i < 9; ++i) out << (i > 0 ? " " : "") << r(i / 3, i % 3);
    out << ',' << t.x() << ' ' << t.y() << ' ' << t.z() << ',' << seconds << '\n';
  }
  out.precision(precision);
}

std::map<std::pair<int, int>, std::vector<Detection>> ReadBopResults(
    const std::string& path, const std::map<int, std::string>& model_of_object) {
  std::ifstream in(path);
  std::string line;
  if (!in || !std::getline(in, line)) ThrowInputError(path, "header", "a readable BOP CSV with a header line");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line + "\n" != kBopCsvHeader) ThrowInputError(path + ":1", "header", kBopCsvHeader, "'" + line + "'");
  std::map<std::pair<int, int>, std::vector<Detection>> results;
  for (int number = 2; std::getline(in, line); ++number) {
    const std::string source = path + ":" + std::to_string(number);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> cells = SplitAtCommas(line);
    if (cells.size() != 7) {
      ThrowInputError(source, "columns", "7: scene_id,im_id,obj_id,score,R,t,time", std::to_string(cells.size()));
    }
    const int scene = Integer(cells[0], source, "scene_id");
    const int image = Integer(cells[1], source, "im_id");
    const int object = Integer(cells[2], source, "obj_id");
    const auto model = model_of_object.find(object);
    if (model == model_of_object.end()) {
      ThrowInputError(source, "obj_id", "the BOP object id of a model of the library", std::to_string(object));
    }
    Detection detection;
    detection.model = model->second;
    detection.score = Numbers(cells[3], 1, source, "score")[0];
    const std::vector<double> r = Numbers(cells[4], 9, source, "R");
    const std::vector<double> t = Numbers(cells[5], 3, source, "t");
    Numbers(cells[6], 1, source, "time");
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) matrix(row, col) = r[static_cast<size_t>(3 * row + col)];
      matrix(row, 3) = t[static_cast<size_t>(row)] / 1000.0;  // mm -> m
    }
    detection.camera_from_object = RigidFromMatrix(matrix, source, "R");
    results[{scene, image}].push_back(std::move(detection));
  }
  return results;
}

}  // namespace ecv
