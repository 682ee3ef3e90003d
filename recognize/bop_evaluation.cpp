#include "recognize/bop_evaluation.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "core/error.h"
#include "io/pose_io.h"
#include "modeldb/model_builder.h"

namespace ecv {
namespace {

constexpr double kVsdDeltaM = 0.015;         // BOP's tolerance of the visibility test
constexpr double kMinVisibleFraction = 0.1;  // BOP counts instances at least this visible

std::string Fixed3(double value) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.3f", value);
  return text;
}

}  // namespace

std::map<std::string, std::vector<Eigen::Isometry3d>> ReadBopSymmetries(const std::string& models_info_path,
                                                                        const ModelLibrary& library) {
  const nlohmann::json info = ReadJsonFile(models_info_path);
  if (!info.is_object()) ThrowInputError(models_info_path, "models info", "an object keyed by obj_id");
  std::vector<std::pair<std::string, int64_t>> named;
  for (const LibraryModel& model : library.models()) named.emplace_back(model.record.name, model.record.id);
  std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries;
  for (const auto& [name, object_id] : BopObjectIds(std::move(named))) {
    const std::string key = std::to_string(object_id);
    if (!info.contains(key)) continue;
    symmetries[name] = BopSymmetries(info[key], 0.001, models_info_path + ": \"" + key + "\"");
  }
  return symmetries;
}

BopJudge::BopJudge(const ModelLibrary& library, std::vector<EvalModel> models,
                   std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries, Renderer& renderer)
    : library_(library), models_(std::move(models)), symmetries_(std::move(symmetries)), renderer_(renderer) {}

cv::Mat BopJudge::RenderDepth(const std::string& model, const PinholeCamera& camera, const Eigen::Isometry3d& pose) {
  auto mesh = meshes_.find(model);
  if (mesh == meshes_.end()) {
    mesh = meshes_.emplace(model, renderer_.AddMesh(ModelMesh(library_.Find(model)->record, false))).first;
  }
  return renderer_.Render(mesh->second, camera, pose).depth;
}

std::vector<BopObjectErrors> BopJudge::FrameErrors(const RgbdFrame& frame, const std::vector<Detection>& detections,
                                                   const std::vector<GroundTruth>& truth) {
  std::vector<BopObjectErrors> objects;
  judged_.clear();
  for (const EvalModel& model : models_) {
    std::vector<const GroundTruth*> instances;
    for (const GroundTruth& gt : truth) {
      const bool visible = gt.visible_fraction < 0.0 || gt.visible_fraction >= kMinVisibleFraction;
      if (gt.object_name == model.name && visible) instances.push_back(&gt);
    }
    if (instances.empty()) continue;
    std::vector<const Detection*> estimates;
    for (const Detection& detection : detections) {
      if (detection.model == model.name) estimates.push_back(&detection);
    }
    std::stable_sort(estimates.begin(), estimates.end(),
                     [](const Detection* a, const Detection* b) { return a->score > b->score; });
    if (estimates.size() > instances.size()) estimates.resize(instances.size());

    const auto symmetry = symmetries_.find(model.name);
    const std::vector<Eigen::Isometry3d> identity = {Eigen::Isometry3d::Identity()};
    const std::vector<Eigen::Isometry3d>& turns = symmetry != symmetries_.end() ? symmetry->second : identity;
    std::vector<double> taus;
    for (const double fraction : BopFractions()) taus.push_back(fraction * model.diameter_m);
    std::vector<cv::Mat> truth_depth;
    for (const GroundTruth* gt : instances) {
      truth_depth.push_back(RenderDepth(model.name, frame.camera, gt->camera_from_object));
    }
    BopObjectErrors object;
    object.diameter_m = model.diameter_m;
    object.instances = static_cast<int>(instances.size());
    for (const Detection* estimate : estimates) {
      const cv::Mat estimate_depth = RenderDepth(model.name, frame.camera, estimate->camera_from_object);
      std::vector<BopPoseErrors> row;
      for (size_t i = 0; i < instances.size(); ++i) {
        const Eigen::Isometry3d& pose = instances[i]->camera_from_object;
        BopPoseErrors errors;
        errors.vsd = Vsd(estimate_depth, truth_depth[i], frame.depth, frame.camera, kVsdDeltaM, taus);
        errors.mssd_m = Mssd(model.points, estimate->camera_from_object, pose, turns);
        errors.mspd_px = Mspd(model.points, estimate->camera_from_object, pose, turns, frame.camera);
        row.push_back(std::move(errors));
      }
      object.errors.push_back(std::move(row));
    }
    objects.push_back(std::move(object));
    judged_.push_back(model.name);
  }
  return objects;
}

std::string BopRecallMarkdown(const std::map<std::string, std::vector<BopObjectErrors>>& by_model, int width) {
  std::string table = "| model | instances | AR_VSD | AR_MSSD | AR_MSPD | AR |\n|---|---:|---:|---:|---:|---:|\n";
  std::vector<BopObjectErrors> all;
  const auto row = [&](const std::string& name, const BopRecall& r) {
    table += "| " + name + " | " + std::to_string(r.instances) + " | " + Fixed3(r.ar_vsd) + " | " + Fixed3(r.ar_mssd) +
             " | " + Fixed3(r.ar_mspd) + " | " + Fixed3(r.ar) + " |\n";
  };
  for (const auto& [name, objects] : by_model) {
    row(name, AverageRecall(objects, width));
    all.insert(all.end(), objects.begin(), objects.end());
  }
  row("**all**", AverageRecall(all, width));
  return table;
}

nlohmann::json BopRecallJson(const std::map<std::string, std::vector<BopObjectErrors>>& by_model, int width) {
  const auto json = [](const BopRecall& r) {
    return nlohmann::json{
        {"instances", r.instances}, {"ar_vsd", r.ar_vsd}, {"ar_mssd", r.ar_mssd}, {"ar_mspd", r.ar_mspd}, {"ar", r.ar}};
  };
  nlohmann::json result = {{"models", nlohmann::json::object()}};
  std::vector<BopObjectErrors> all;
  for (const auto& [name, objects] : by_model) {
    result["models"][name] = json(AverageRecall(objects, width));
    all.insert(all.end(), objects.begin(), objects.end());
  }
  result["all"] = json(AverageRecall(all, width));
  return result;
}

}  // namespace ecv
