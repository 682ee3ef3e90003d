#pragma once

// The detections JSON of `ecvpose recognize --out-json`, the service and the Python module.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "recognize/detection.h"

namespace ecv {

/// The detections JSON that `ecvpose recognize --out-json` writes: {"detections": [{"model", "score",
/// "camera_from_object", "inlier_fraction", "fit_error", "view", ..., "tracked", "confirmed", "hypothesis"}],
/// "timings_ms": {stage: ms}, ...}, with "searched_frames_ago" when a search beside the tracking joined the frame, and
/// "judged" (each a detection's fields and "accepted") when the result holds judged poses.
nlohmann::json RecognitionToJson(const RecognitionResult& result);

/// The detections of such JSON (model, score, camera_from_object, hypothesis); throws InputError naming `source`
/// and the field when one is missing or malformed.
std::vector<Detection> DetectionsFromJson(const nlohmann::json& json, const std::string& source);

}  // namespace ecv
