#include "recognize/evaluation.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>

#include "core/point_index.h"
#include "io/mesh_io.h"

namespace ecv {

EvalModel EvalModelFromRecord(const ModelRecord& record, size_t max_points) {
  MeshLoadOptions load;
  load.metres_per_unit = MetresPerUnit(record.unit);
  load.object_from_mesh = record.object_from_mesh;
  load.allow_missing_textures = true;
  const TriangleMesh mesh = LoadMesh(record.mesh_path, load);
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
  std::map<std::string, const EvalModel*> by_name;
  for (const EvalModel& model : models) by_name[model.name] = &model;
  for (const Detection& detection : detections) {
    const auto present = std::find_if(truth.begin(), truth.end(),
                                      [&](const GroundTruth& t) { return t.object_name == detection.model; });
    if (present == truth.end()) ++evaluation.false_positives;
  }
  for (const GroundTruth& object : truth) {
    const auto model = by_name.find(object.object_name);
    if (model == by_name.end()) continue;  // not in the library: not asked for
    ObjectEvaluation result;
    result.model = object.object_name;
    result.diameter_m = model->second->diameter_m;
    const auto found = std::find_if(detections.begin(), detections.end(),
                                    [&](const Detection& d) { return d.model == object.object_name; });
    if (found != detections.end()) {
      result.detected = true;
      result.error = ComputePoseError(model->second->points, found->camera_from_object, object.camera_from_object);
      const double distance = model->second->symmetric ? result.error.adds_m : result.error.add_m;
      result.correct = distance < 0.1 * result.diameter_m;
      if (!result.correct) ++evaluation.false_positives;
    }
    evaluation.objects.push_back(result);
  }
  return evaluation;
}

std::string EvaluationMarkdown(const std::vector<FrameEvaluation>& frames) {
  std::ostringstream out;
  out << "| frame | object | detected | rotation (deg) | translation (mm) | ADD (mm) | ADD-S (mm) | 0.1 d (mm) | "
         "correct |\n|---|---|---|---:|---:|---:|---:|---:|---|\n";
  int objects = 0, correct = 0, false_positives = 0;
  char line[512];
  for (const FrameEvaluation& frame : frames) {
    false_positives += frame.false_positives;
    for (const ObjectEvaluation& object : frame.objects) {
      ++objects;
      correct += object.correct ? 1 : 0;
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
  std::snprintf(line, sizeof(line),
                "\nRecall at ADD < 0.1 d: %d of %d (%.1f %%); false positives: %d (%.2f per frame)\n", correct, objects,
                objects > 0 ? 100.0 * correct / objects : 0.0, false_positives,
                frames.empty() ? 0.0 : static_cast<double>(false_positives) / static_cast<double>(frames.size()));
  out << line;
  return out.str();
}

}  // namespace ecv
