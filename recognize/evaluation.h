#pragma once

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/pose.h"
#include "modeldb/model_record.h"
#include "recognize/recognizer.h"

namespace ecv {

/// Errors of an estimated pose against the ground truth (DESIGN.md "Evaluation").
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

/// The outcome for one ground-truth object of a frame.
struct ObjectEvaluation {
  std::string model;
  bool detected = false;  ///< a detection of this model exists
  bool correct = false;   ///< its ADD (ADD-S when symmetric) is below 0.1 x diameter
  PoseError error;        ///< when detected
  double diameter_m = 0.0;
};

struct FrameEvaluation {
  std::string frame;
  std::vector<ObjectEvaluation> objects;  ///< one per ground-truth object that is in `models`
  int false_positives = 0;                ///< detections of models not in the frame, or wrong (ADD >= 0.1 d)
};

/// Matches detections to the ground truth by model name (one instance per model).
FrameEvaluation EvaluateFrame(const std::string& frame, const std::vector<Detection>& detections,
                              const std::vector<GroundTruth>& truth, const std::vector<EvalModel>& models);

/// Markdown table: per object rotation / translation error, ADD, ADD-S, correct; then recall and false
/// positives over all frames.
std::string EvaluationMarkdown(const std::vector<FrameEvaluation>& frames);

}  // namespace ecv
