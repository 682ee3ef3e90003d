#include "recognize/evaluation.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/point_index.h"

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

}  // namespace ecv
