#pragma once

// What one frame offers to every model's search, and where a frame's time goes. Internal to the recognizer, but for
// ComputeSceneDescriptors, which benches and tests call to describe a scene as the recognizer does.

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/frame.h"
#include "core/point_index.h"
#include "ecv/descriptor.h"
#include "ecv/matching.h"
#include "ecv/primitives.h"
#include "modeldb/model_record.h"
#include "recognize/detection.h"
#include "recognize/recognizer_options.h"
#include "recognize/verification.h"
#include "registration/icp.h"
#include "registration/ransac.h"

namespace ecv {

/// The stages of a frame's recognition, as RecognitionResult::timings_ms names them.
enum class Stage {
  kExtract,
  kDescribe,
  kPreselect,
  kTrack,
  kRank,
  kMatch,
  kRansac,
  kRefine,
  kVerify,
  kPointPairs,
  kTotal,
  kCount
};

/// Milliseconds per stage; a stage never added to is absent from Map().
class StageTimes {
 public:
  void Add(Stage stage, double ms);
  StageTimes& operator+=(const StageTimes& other);
  /// {"extract": ms, ...} for the stages that ran.
  std::map<std::string, double> Map() const;

 private:
  static constexpr auto kStages = static_cast<size_t>(Stage::kCount);
  std::array<double, kStages> ms_{};
  std::array<bool, kStages> ran_{};
};

/// A frame as the models' searches see it: primitives with descriptors and a matcher over them (DescribeScene), dense
/// points and the images verification compares with (PrepareScene).
struct Scene {
  const RgbdFrame* frame = nullptr;
  std::vector<Primitive> primitives;
  Descriptors descriptors;
  std::unique_ptr<DescriptorMatcher> matcher;
  std::vector<Eigen::Vector3f> points;  ///< the depth points at dense_stride_px, for ICP
  /// Primitive positions first, then (unless projective_inliers) the depth points at ransac_stride_px and a grid
  /// over all of them with the inlier threshold as radius.
  std::vector<Eigen::Vector3f> ransac_points;
  std::unique_ptr<RadiusGrid> ransac_grid;
  VerificationFrame verification;
  OrganizedScene organized;  ///< the depth samples with normals, for projective ICP and point pair hypotheses
  SceneVisibility visibility;
  /// With RecognizerOptions::keep_verified: every verified pose, from the model workers.
  struct VerifiedLog {
    std::mutex mutex;
    std::vector<Detection> poses;
  };
  std::unique_ptr<VerifiedLog> verified_log;
};

/// What every model needs of `frame` (which must outlive the scene): dense points, verification images, visibility.
/// No primitives yet: a frame whose objects are all tracked needs none.
Scene PrepareScene(const RgbdFrame& frame, const RecognizerOptions& options);

/// The frame's primitives, their descriptors under the library's `settings` and a matcher over them: what view
/// ranking and RANSAC need.
void DescribeScene(const FeatureSettings& settings, const RecognizerOptions& options, Scene* scene, StageTimes* times);

/// A frame's descriptors as the recognizer computes them from its `primitives`: the library's `descriptor`
/// settings with at most options.scene_max_neighbours neighbours per context, and every n-th primitive a source
/// so that at most options.scene_max_descriptors are described; on options.threads threads. `surface`: the
/// frame's surface, for a library whose descriptors use the surface context (DescriptorShape::kSurface).
Descriptors ComputeSceneDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& descriptor,
                                    const RecognizerOptions& options, const SurfaceSamples* surface = nullptr);

}  // namespace ecv
