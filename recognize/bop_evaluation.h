#pragma once

// Detections of a frame judged by BOP's average recall (recognize/bop_metrics.h): the errors of each model's
// detections against its ground-truth instances, with depth rendered for VSD.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/frame.h"
#include "core/pose.h"
#include "modeldb/model_library.h"
#include "recognize/bop_metrics.h"
#include "recognize/detection.h"
#include "recognize/evaluation.h"
#include "render/renderer.h"

namespace ecv {

/// Each model's symmetries from a BOP models_info.json (keys: the obj_id as text; millimetres), found by the BOP
/// object id of each library model (BopObjectIds); a model without an entry has the identity only. Throws InputError
/// naming the file and the field.
std::map<std::string, std::vector<Eigen::Isometry3d>> ReadBopSymmetries(const std::string& models_info_path,
                                                                        const ModelLibrary& library);

/// What BOP's errors of one frame need of the library: the evaluation points and diameters, the symmetries, and each
/// model's mesh in a renderer (uploaded on first use).
class BopJudge {
 public:
  /// `symmetries` by model name; models without are judged with the identity only.
  BopJudge(const ModelLibrary& library, std::vector<EvalModel> models,
           std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries, Renderer& renderer);

  /// Per model with ground truth in `frame` that is in the library: its detections, best score first and at most as
  /// many as its instances (BOP's task: the target count), against its instances at least 10 % visible (all where the
  /// visible fraction is unknown). VSD with delta 15 mm and taus 5 % to 50 % of the diameter.
  std::vector<BopObjectErrors> FrameErrors(const RgbdFrame& frame, const std::vector<Detection>& detections,
                                           const std::vector<GroundTruth>& truth);

  /// The model names, in the order of FrameErrors' results (filled by the last call).
  const std::vector<std::string>& judged_models() const { return judged_; }

 private:
  cv::Mat RenderDepth(const std::string& model, const PinholeCamera& camera, const Eigen::Isometry3d& pose);

  const ModelLibrary& library_;
  std::vector<EvalModel> models_;
  std::map<std::string, std::vector<Eigen::Isometry3d>> symmetries_;
  Renderer& renderer_;
  std::map<std::string, MeshId> meshes_;  // by model name
  std::vector<std::string> judged_;
};

/// Markdown table of AR_VSD, AR_MSSD, AR_MSPD and AR per model and over all, from each frame's FrameErrors with the
/// model names, for images of `width` pixels.
std::string BopRecallMarkdown(const std::map<std::string, std::vector<BopObjectErrors>>& by_model, int width);

/// The same as JSON: {"models": {name: {...}}, "all": {...}}.
nlohmann::json BopRecallJson(const std::map<std::string, std::vector<BopObjectErrors>>& by_model, int width);

}  // namespace ecv
