#include "recognize/scene.h"

#include "core/timing.h"

namespace ecv {

void StageTimes::Add(Stage stage, double ms) {
  const auto s = static_cast<size_t>(stage);
  ms_[s] += ms;
  ran_[s] = true;
}

StageTimes& StageTimes::operator+=(const StageTimes& other) {
  for (size_t s = 0; s < kStages; ++s) {
    if (other.ran_[s]) Add(static_cast<Stage>(s), other.ms_[s]);
  }
  return *this;
}

std::map<std::string, double> StageTimes::Map() const {
  static constexpr const char* kNames[kStages] = {"extract", "describe", "preselect", "track",       "rank", "match",
                                                  "ransac",  "refine",   "verify",    "point_pairs", "total"};
  std::map<std::string, double> map;
  for (size_t s = 0; s < kStages; ++s) {
    if (ran_[s]) map[kNames[s]] = ms_[s];
  }
  return map;
}

Scene PrepareScene(const RgbdFrame& frame, const RecognizerOptions& options) {
  Scene scene;
  scene.frame = &frame;
  scene.points = DepthPoints(frame, options.dense_stride_px);
  scene.verification = MakeVerificationFrame(frame, options.verify, options.dense_stride_px);
  if ((options.refine && options.projective_icp) || options.point_pairs.source != HypothesisSource::kContext) {
    scene.organized = MakeOrganizedScene(frame.depth, frame.camera, options.dense_stride_px);
  }
  scene.visibility.depth = frame.depth;
  scene.visibility.camera = frame.camera;
  return scene;
}

void DescribeScene(const FeatureSettings& settings, const RecognizerOptions& options, Scene* scene, StageTimes* times) {
  const RgbdFrame& frame = *scene->frame;
  Clock::time_point stage = Clock::now();
  scene->primitives = ExtractPrimitives(frame, settings.ecv).primitives;
  // Primitives first in ransac_points, so that a primitive's index is its point's.
  scene->ransac_points = PrimitivePositions(scene->primitives);
  if (!options.projective_inliers) {
    const std::vector<Eigen::Vector3f> depth_points = DepthPoints(frame, options.ransac_stride_px);
    scene->ransac_points.insert(scene->ransac_points.end(), depth_points.begin(), depth_points.end());
    scene->ransac_grid =
        std::make_unique<RadiusGrid>(scene->ransac_points, static_cast<float>(options.ransac.inlier_threshold_m));
  }
  times->Add(Stage::kExtract, MillisecondsSince(stage));

  stage = Clock::now();
  // The surface context's support (if the library's descriptors use it): the whole frame's surface.
  const SurfaceSamples surface = DescriptorSurface(frame, settings.descriptor);
  scene->descriptors = ComputeSceneDescriptors(scene->primitives, settings.descriptor, options, &surface);
  if (scene->descriptors.values.rows > 0) {
    scene->matcher = std::make_unique<DescriptorMatcher>(scene->primitives, scene->descriptors, options.match);
  }
  times->Add(Stage::kDescribe, MillisecondsSince(stage));
}

Descriptors ComputeSceneDescriptors(const std::vector<Primitive>& primitives, const DescriptorOptions& descriptor,
                                    const RecognizerOptions& options, const SurfaceSamples* surface) {
  DescriptorOptions describe = descriptor;
  if (options.scene_max_neighbours > 0 &&
      (describe.max_neighbours == 0 || describe.max_neighbours > options.scene_max_neighbours)) {
    describe.max_neighbours = options.scene_max_neighbours;
  }
  const size_t count = primitives.size(), most = static_cast<size_t>(options.scene_max_descriptors);
  const int source_step = most > 0 && count > most ? static_cast<int>((count + most - 1) / most) : 1;
  return ComputeDescriptors(primitives, describe, options.threads, source_step, surface);
}

}  // namespace ecv
