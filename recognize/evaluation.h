#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/pose.h"
#include "modeldb/model_library.h"
#include "modeldb/model_record.h"
#include "recognize/detection.h"

namespace ecv {

/// Errors of an estimated pose against the ground truth.
struct PoseError {
  double rotation_deg = 0.0;
  double translation_mm = 0.0;
  double add_m = 0.0;   ///< mean distance of corresponding model points under the two poses
  double adds_m = 0.0;  ///< mean distance of each point under the estimate to the nearest under the truth
};

/// Errors for `points` (object frame, metres; a few thousand suffice).
PoseError ComputePoseError(const std::vector<Eigen::Vector3f>& points, const Eigen::Isometry3d& estimate,
                           const Eigen::Isometry3d& truth);

/// What evaluation needs of a model.
struct EvalModel {
  std::string name;
  std::vector<Eigen::Vector3f> points;  ///< object frame, metres
  double diameter_m = 0.0;
  bool symmetric = false;  ///< judged by ADD-S instead of ADD
};

/// A model's evaluation points (at most `max_points` vertices of its mesh, object frame), diameter and
/// symmetry, from its library record. Throws InputError when the mesh cannot be loaded.
EvalModel EvalModelFromRecord(const ModelRecord& record, size_t max_points = 4000);

/// EvalModelFromRecord of every model of `library`, in its order.
std::vector<EvalModel> EvalModels(const ModelLibrary& library);

/// The outcome for one ground-truth object of a frame.
struct ObjectEvaluation {
  std::string model;
  bool detected = false;  ///< a detection of this model exists (see EvaluateFrame)
  bool correct = false;   ///< a detection found it: ADD (ADD-S when symmetric) below 0.1 x diameter
  PoseError error;        ///< of that detection, when detected
  double diameter_m = 0.0;
};

struct FrameEvaluation {
  std::string frame;
  std::vector<ObjectEvaluation> objects;  ///< one per ground-truth object that is in `models`
  int false_positives = 0;                ///< detections of models not in the frame, wrong (ADD >= 0.1 d) or repeated
  std::vector<std::string> false_positive_models;  ///< the model of each false positive
  /// Why the frame had no detections to judge (all its objects count as missed): "no line in the detections"
  /// or the error `recognize` reported for it; empty when its detections were judged.
  std::string missed;
};

/// Matches detections to the ground truth by model name, any number of instances per model (as BOP does): in
/// order of score, each detection takes the nearest not yet taken instance of its model that it finds within
/// ADD (ADD-S when symmetric) < 0.1 x diameter; a detection that takes none is a false positive. An instance
/// left untaken shows the error of its model's best-scoring false positive, when there is one.
FrameEvaluation EvaluateFrame(const std::string& frame, const std::vector<Detection>& detections,
                              const std::vector<GroundTruth>& truth, const std::vector<EvalModel>& models);

/// Markdown table: per object rotation / translation error, ADD, ADD-S, correct; the frames counted as missed
/// and why; then recall and false positives over all frames, and per model.
std::string EvaluationMarkdown(const std::vector<FrameEvaluation>& frames);

/// Per frame and object numbers (metres, radians) and the totals, per model and overall, as JSON.
nlohmann::json EvaluationToJson(const std::vector<FrameEvaluation>& frames);

/// Where the ground truth of a folder of frames comes from.
enum class GroundTruthFolder {
  kYcbVideo,  ///< a YCB-Video video folder: <frame>-meta.mat beside each <frame>-color.png
  kBopScene,  ///< a BOP scene folder: scene_gt.json (images are not needed)
};

/// Evaluates a detections file against every frame of a ground-truth folder, in the folder's order.
/// `detections_path` holds either the JSON Lines of `ecvpose recognize --sequence` (per line "frame" and
/// "detections", or "error") or a BOP CSV (header scene_id,im_id,obj_id,score,R,t,time; R row-major, t in
/// mm; obj_id is "obj_%06d" for BOP, the YCB-Video class index otherwise). The folder's frames are the
/// YCB-Video frames (*-color.png), or the BOP images of scene_gt.json with an rgb/ (or gray/) image plus those
/// the detections name. A line or row naming another frame, a model not in `models`, or a malformed line is an
/// InputError naming the file, the line and the field. Frames without a line, or whose line is an "error",
/// come back with `missed` set.
std::vector<FrameEvaluation> EvaluateDetectionsFile(const std::string& detections_path, GroundTruthFolder kind,
                                                    const std::string& folder, const std::vector<EvalModel>& models);

/// One frame of a ground-truth folder with the detections a file holds for it.
struct FolderFrame {
  std::string frame;  ///< as LoadFrame takes it: "DIR/000001" (YCB-Video) or "DIR:3" (BOP)
  std::vector<Detection> detections;
  std::vector<GroundTruth> ground_truth;
  std::string missed;  ///< why it has no detections to judge (see FrameEvaluation::missed); empty when judged
};

/// The frames of a folder with their detections and ground truth, read and checked as EvaluateDetectionsFile reads
/// them, in the folder's order.
std::vector<FolderFrame> ReadFolderDetections(const std::string& detections_path, GroundTruthFolder kind,
                                              const std::string& folder, const std::vector<EvalModel>& models);

}  // namespace ecv
