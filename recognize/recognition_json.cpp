#include "recognize/recognition_json.h"

#include "core/error.h"
#include "io/pose_io.h"

namespace ecv {

namespace {

nlohmann::json DetectionToJson(const Detection& d) {
  nlohmann::json json = {{"model", d.model},
                         {"score", d.score},
                         {"camera_from_object", PoseToJson(d.camera_from_object)},
                         {"inlier_fraction", d.inlier_fraction},
                         {"fit_error", d.fit_error_m},
                         {"view", d.view},
                         {"depth_agreement", d.depth_agreement},
                         {"color_agreement", d.color_agreement},
                         {"visible_fraction", d.visible_fraction},
                         {"surface_error", d.surface_error_m},
                         {"contour_agreement", d.contour_agreement},
                         {"continuation", d.continuation},
                         {"edge_agreement", d.edge_agreement},
                         {"edge_pixels", d.edge_pixels},
                         {"explained_surface", d.explained_surface},
                         {"free_space_violation", d.free_space_violation},
                         {"occluding_contour", d.occluding_contour},
                         {"creased_contour", d.creased_contour},
                         {"tracked", d.tracked},
                         {"confirmed", d.confirmed},
                         {"hypothesis", HypothesisSourceName(d.hypothesis_source)}};
  if (d.acceptance >= 0.0) json["acceptance"] = d.acceptance;
  if (!d.accepted) json["accepted"] = false;  // a target's best rejected pose (recognize --targets)
  return json;
}

}  // namespace

nlohmann::json RecognitionToJson(const RecognitionResult& result) {
  nlohmann::json detections = nlohmann::json::array();
  for (const Detection& d : result.detections) detections.push_back(DetectionToJson(d));
  nlohmann::json json = {{"detections", detections},
                         {"timings_ms", result.timings_ms},
                         {"scene_primitives", result.scene_primitives},
                         {"views_tried", result.views_tried}};
  if (result.searched_frames_ago >= 0) json["searched_frames_ago"] = result.searched_frames_ago;
  if (!result.judged.empty()) {
    nlohmann::json judged = nlohmann::json::array();
    for (const JudgedPose& pose : result.judged) {
      nlohmann::json item = DetectionToJson(pose.detection);
      item["accepted"] = pose.accepted;
      judged.push_back(std::move(item));
    }
    json["judged"] = std::move(judged);
  }
  return json;
}

std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source) {
  if (!json.contains("detections") || !json["detections"].is_array()) {
    ThrowInputError(source, "detections", "an array of detections (ecvpose recognize --out-json)");
  }
  std::vector<Detection> detections;
  for (size_t i = 0; i < json["detections"].size(); ++i) {
    const nlohmann::json& item = json["detections"][i];
    const std::string field = "detections[" + std::to_string(i) + "]";
    if (!item.contains("model") || !item["model"].is_string()) ThrowInputError(source, field + ".model", "a string");
    Detection detection;
    detection.model = item["model"].get<std::string>();
    detection.camera_from_object =
        PoseFromJson(item.value("camera_from_object", nlohmann::json()), source, field + ".camera_from_object");
    if (item.contains("score") && !item["score"].is_number()) ThrowInputError(source, field + ".score", "a number");
    detection.score = item.value("score", 0.0);
    if (item.contains("hypothesis")) {
      const nlohmann::json& hypothesis = item["hypothesis"];
      if (!hypothesis.is_string() || hypothesis == "both") {
        ThrowInputError(source, field + ".hypothesis", "\"context\" or \"ppf\"", hypothesis.dump());
      }
      detection.hypothesis_source = ParseHypothesisSource(hypothesis.get<std::string>(), source + " " + field);
    }
    if (item.contains("accepted")) {
      if (!item["accepted"].is_boolean()) ThrowInputError(source, field + ".accepted", "true or false");
      detection.accepted = item["accepted"].get<bool>();
    }
    detections.push_back(detection);
  }
  return detections;
}

}  // namespace ecv
