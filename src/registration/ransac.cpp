#include "registration/ransac.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <random>
#include <string>

#include <Eigen/Geometry>

#include "core/error.h"
#include "core/parallel.h"
#include "core/point_index.h"

namespace ecv {
namespace {

// Rigid motion (Kabsch/Umeyama, no scale) taking `from` onto `to`; false when degenerate.
bool FitRigid(const std::vector<Eigen::Vector3f>& from, const std::vector<Eigen::Vector3f>& to,
              Eigen::Isometry3d* result) {
  Eigen::Matrix3Xd a(3, from.size()), b(3, to.size());
  for (size_t i = 0; i < from.size(); ++i) {
    a.col(static_cast<long>(i)) = from[i].cast<double>();
    b.col(static_cast<long>(i)) = to[i].cast<double>();
  }
  const Eigen::Vector3d centred_extent = (a.colwise() - a.rowwise().mean()).rowwise().norm();
  if (centred_extent.maxCoeff() < 1e-9) return false;  // all points identical
  const Eigen::Matrix4d transform = Eigen::umeyama(a, b, false);
  if (!transform.allFinite()) return false;
  result->matrix() = transform;
  return true;
}

// Samples per block. Each block draws from its own generator seeded by (seed, block), so the result does
// not depend on which thread runs which block.
constexpr int kBlockSize = 64;

// The generator of `block` for `seed`. Seeding an mt19937_64 through a seed_seq costs about as much as a block's
// 64 samples, most of which fail a cheap test; the recognizer runs RANSAC for every view it tries with one seed,
// so each thread keeps the seeded generators of its last seed and copies them instead of seeding them again.
// They take 2.5 KB per block: 1.4 MB for the paper's 37 000 iterations, 390 KB for the recognizer's 10 000.
std::mt19937_64 BlockGenerator(uint64_t seed, int block) {
  thread_local uint64_t cached_seed = 0;
  thread_local std::vector<std::mt19937_64> generators;
  if (cached_seed != seed) {
    generators.clear();
    cached_seed = seed;
  }
  while (generators.size() <= static_cast<size_t>(block)) {
    std::seed_seq seeds{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32U),
                        static_cast<uint32_t>(generators.size())};
    generators.emplace_back(seeds);
  }
  return generators[static_cast<size_t>(block)];
}

bool Visible(const SceneVisibility& visibility, const Eigen::Vector3f& point_camera) {
  if (point_camera.z() <= 0.0F) return false;
  const Eigen::Vector2d pixel = visibility.camera.Project(point_camera.cast<double>());
  if (!visibility.camera.Contains(pixel)) return false;
  const int u = std::clamp(static_cast<int>(std::lround(pixel.x())), 0, visibility.depth.cols - 1);
  const int v = std::clamp(static_cast<int>(std::lround(pixel.y())), 0, visibility.depth.rows - 1);
  const float depth = visibility.depth.at<float>(v, u);
  // No measurement: the sensor cannot show the point. Behind the measured surface: hidden. In front of it
  // (free space), the point stays visible and counts against the pose.
  return depth > 0.0F && point_camera.z() <= depth + static_cast<float>(visibility.occlusion_margin_m);
}

// The nearest of the 3 x 3 depth samples `stride` pixels apart around the pixel where `point` (camera frame, in
// front of the camera) is seen, and its squared distance; false when none has a measurement.
bool NearestDepthSample(const SceneVisibility& visibility, int stride, const Eigen::Vector3f& point,
                        Eigen::Vector3f* nearest, float* squared) {
  const PinholeCamera& camera = visibility.camera;
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const int centre_u = static_cast<int>(std::lround(fx * point.x() / point.z() + cx));
  const int centre_v = static_cast<int>(std::lround(fy * point.y() / point.z() + cy));
  *squared = std::numeric_limits<float>::infinity();
  for (int v = centre_v - stride; v <= centre_v + stride; v += stride) {
    if (v < 0 || v >= visibility.depth.rows) continue;
    const float* row = visibility.depth.ptr<float>(v);
    for (int u = centre_u - stride; u <= centre_u + stride; u += stride) {
      if (u < 0 || u >= visibility.depth.cols || row[u] <= 0.0F) continue;
      const float z = row[u];
      const Eigen::Vector3f sample((static_cast<float>(u) - cx) * z / fx, (static_cast<float>(v) - cy) * z / fy, z);
      const float distance = (sample - point).squaredNorm();
      if (distance < *squared) {
        *squared = distance;
        *nearest = sample;
      }
    }
  }
  return std::isfinite(*squared);
}

// Object points within eps of their nearest scene point under a pose, with those scene points.
struct Inliers {
  std::vector<Eigen::Vector3f> object, scene;
  double distance_sum = 0.0;
  size_t visible = 0;
};

double MeanPairDistance(const Eigen::Isometry3d& pose, const Inliers& inliers) {
  const Eigen::Isometry3f transform = pose.cast<float>();
  double sum = 0.0;
  for (size_t i = 0; i < inliers.object.size(); ++i) sum += (transform * inliers.object[i] - inliers.scene[i]).norm();
  return sum / static_cast<double>(inliers.object.size());
}

// One RANSAC problem; RunBlock may be called from several threads at once.
class Estimator {
 public:
  Estimator(const std::vector<Eigen::Vector3f>& object_points, const std::vector<Eigen::Vector3f>& scene_points,
            const RadiusGrid* scene_grid, const std::vector<Correspondence>& correspondences,
            const RansacOptions& options, const SceneVisibility* visibility)
      : object_(object_points),
        scene_(scene_points),
        correspondences_(correspondences),
        options_(options),
        visibility_(visibility),
        tree_(scene_grid),
        order_(object_points.size()) {
    std::iota(order_.begin(), order_.end(), 0);
    std::mt19937_64 random(options.seed);
    std::shuffle(order_.begin(), order_.end(), random);
    if (options.sample_radius_m > 0.0) FindSampleNeighbours();
    const auto support = std::max<size_t>(
        static_cast<size_t>(options.min_support),
        static_cast<size_t>(std::ceil(options.min_support_share * static_cast<double>(correspondences.size()))));
    if (support > 0) required_agreeing_ = static_cast<size_t>(options.sample_size) + support;
  }

  struct Best {
    double agreeing = 0.0;  // share of agreeing correspondences (ranks poses first when prefer_agreeing)
    double error = std::numeric_limits<double>::max();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    size_t inliers = 0, visible = 0;
  };
  struct BlockOutcome {
    Best best;
    int iterations = 0, rejected_by_polygon = 0, rejected_by_support = 0;
    double agreeing = 0.0;  // largest share of agreeing correspondences of an accepted pose
    bool stopped_early = false;
  };

  // The ranking of accepted poses: more agreeing correspondences first (when preferred; 0 otherwise), then
  // the lower mean fit error.
  static bool Better(const Best& a, const Best& b) {
    return a.agreeing > b.agreeing || (a.agreeing == b.agreeing && a.error < b.error);
  }

  // Share of the correspondences whose object point lands within eps of its scene point under `pose`.
  double AgreeingShare(const Eigen::Isometry3d& pose) const {
    return static_cast<double>(AgreeingCount(pose)) / static_cast<double>(correspondences_.size());
  }

  // How many correspondences' object points land within eps of their scene points under `pose`.
  size_t AgreeingCount(const Eigen::Isometry3d& pose) const {
    const Eigen::Isometry3f transform = pose.cast<float>();
    const float eps_squared = static_cast<float>(options_.inlier_threshold_m * options_.inlier_threshold_m);
    return static_cast<size_t>(
        std::count_if(correspondences_.begin(), correspondences_.end(), [&](const Correspondence& c) {
          return (transform * object_[static_cast<size_t>(c.object)] - scene_[static_cast<size_t>(c.scene)])
                     .squaredNorm() <= eps_squared;
        }));
  }

  BlockOutcome RunBlock(int block, int size) const {
    std::mt19937_64 random = BlockGenerator(options_.seed, block);
    const size_t n = static_cast<size_t>(options_.sample_size);
    std::vector<Eigen::Vector3f> object_sample(n), scene_sample(n);
    const PolygonEdgeCheck polygon(options_.polygon_threshold);
    Inliers inliers;
    BlockOutcome outcome;
    std::vector<int> sample(n);
    while (outcome.iterations < size) {
      ++outcome.iterations;
      if (!DrawSample(random, &sample)) continue;
      for (size_t k = 0; k < n; ++k) {
        const Correspondence& c = correspondences_[static_cast<size_t>(sample[k])];
        object_sample[k] = object_[static_cast<size_t>(c.object)];
        scene_sample[k] = scene_[static_cast<size_t>(c.scene)];
      }
      if (options_.polygon_threshold > 0.0 && !polygon(object_sample, scene_sample)) {
        ++outcome.rejected_by_polygon;
        continue;
      }
      Eigen::Isometry3d pose;
      if (!FitRigid(object_sample, scene_sample, &pose)) continue;
      if (required_agreeing_ > 0 && AgreeingCount(pose) < required_agreeing_) {
        ++outcome.rejected_by_support;
        continue;
      }
      if (!FindInliers(pose, &inliers)) continue;
      // Re-estimate on the inliers; the fit error is that of the same inlier pairs under the new pose.
      if (!FitRigid(inliers.object, inliers.scene, &pose)) continue;
      const double error = MeanPairDistance(pose, inliers);
      const double agreeing = options_.adaptive || options_.prefer_agreeing ? AgreeingShare(pose) : 0.0;
      outcome.agreeing = std::max(outcome.agreeing, agreeing);
      const Best candidate{options_.prefer_agreeing ? agreeing : 0.0, error, pose, inliers.object.size(),
                           inliers.visible};
      if (Better(candidate, outcome.best)) {
        outcome.best = candidate;
        if (options_.early_stop_fit_error_m > 0.0 && error < options_.early_stop_fit_error_m) {
          outcome.stopped_early = true;
          break;
        }
      }
    }
    return outcome;
  }

 private:
  // Indices of a sample's correspondences: uniform over all (the paper), or the first uniform and the
  // others among its neighbours (sample_radius_m). False when the first one has too few neighbours.
  bool DrawSample(std::mt19937_64& random, std::vector<int>* sample) const {
    const size_t n = sample->size();
    if (neighbours_.empty()) {
      std::uniform_int_distribution<int> pick(0, static_cast<int>(correspondences_.size()) - 1);
      for (int& index : *sample) index = pick(random);
      return true;
    }
    std::uniform_int_distribution<size_t> pick(0, correspondences_.size() - 1);
    const size_t first = pick(random);
    const std::vector<int>& near = neighbours_[first];
    if (near.size() < n - 1) return false;
    (*sample)[0] = static_cast<int>(first);
    std::uniform_int_distribution<size_t> pick_near(0, near.size() - 1);
    for (size_t k = 1; k < n; ++k) {
      int index = 0;
      do {  // distinct from the ones drawn before (near.size() >= n - 1, so this ends)
        index = near[pick_near(random)];
      } while (std::find(sample->begin() + 1, sample->begin() + static_cast<std::ptrdiff_t>(k), index) !=
               sample->begin() + static_cast<std::ptrdiff_t>(k));
      (*sample)[k] = index;
    }
    return true;
  }

  // For each correspondence, the others whose object and scene points both lie within sample_radius_m.
  void FindSampleNeighbours() {
    const float radius_squared = static_cast<float>(options_.sample_radius_m * options_.sample_radius_m);
    neighbours_.resize(correspondences_.size());
    for (size_t i = 0; i < correspondences_.size(); ++i) {
      const Eigen::Vector3f& object_i = object_[static_cast<size_t>(correspondences_[i].object)];
      const Eigen::Vector3f& scene_i = scene_[static_cast<size_t>(correspondences_[i].scene)];
      for (size_t j = i + 1; j < correspondences_.size(); ++j) {
        if ((scene_[static_cast<size_t>(correspondences_[j].scene)] - scene_i).squaredNorm() > radius_squared ||
            (object_[static_cast<size_t>(correspondences_[j].object)] - object_i).squaredNorm() > radius_squared) {
          continue;
        }
        neighbours_[i].push_back(static_cast<int>(j));
        neighbours_[j].push_back(static_cast<int>(i));
      }
    }
  }

  // Fills `inliers` for `pose`; false when fewer than the required fraction of the visible object points are
  // inliers, or (preverify) as soon as the count falls clearly behind it. Visibility is tested point by point
  // as they are checked, so a hypothesis dropped early costs a few dozen points, not all of them.
  bool FindInliers(const Eigen::Isometry3d& pose, Inliers* inliers) const {
    const Eigen::Isometry3f transform = pose.cast<float>();
    inliers->object.clear();
    inliers->scene.clear();
    inliers->distance_sum = 0.0;
    const float eps_squared = static_cast<float>(options_.inlier_threshold_m * options_.inlier_threshold_m);
    const double fraction = options_.required_inlier_fraction;
    const double spread = 3.0 * std::sqrt(fraction * (1.0 - fraction));  // 3 sigma of the binomial, per sqrt(k)
    size_t checked = 0;                                                  // visible object points so far
    size_t remaining = order_.size();                                    // points not looked at yet
    for (const int index : order_) {
      // Lost even if every remaining point were a visible inlier: (inliers + r) / (checked + r) < fraction.
      if (static_cast<double>(inliers->object.size() + remaining) <
          fraction * static_cast<double>(checked + remaining)) {
        return false;
      }
      --remaining;
      const Eigen::Vector3f& point = object_[static_cast<size_t>(index)];
      const Eigen::Vector3f moved = transform * point;
      if (visibility_ != nullptr && !Visible(*visibility_, moved)) continue;
      if (options_.preverify && checked >= 50 && checked % 16 == 0) {
        const double k = static_cast<double>(checked);
        if (static_cast<double>(inliers->object.size()) < fraction * k - spread * std::sqrt(k)) return false;
      }
      ++checked;
      Eigen::Vector3f partner;
      float squared = 0.0F;
      if (!Partner(moved, &partner, &squared) || squared > eps_squared) continue;
      inliers->object.push_back(point);
      inliers->scene.push_back(partner);
      inliers->distance_sum += std::sqrt(squared);
    }
    inliers->visible = checked;
    if (visibility_ != nullptr &&
        static_cast<double>(checked) < visibility_->min_visible_fraction * static_cast<double>(object_.size())) {
      return false;
    }
    const size_t required =
        std::max<size_t>(3, static_cast<size_t>(std::ceil(fraction * static_cast<double>(checked))));
    return inliers->object.size() >= required;
  }

  // The scene point nearest `moved` (an object point under a pose) where options_.projective_stride_px says to look.
  bool Partner(const Eigen::Vector3f& moved, Eigen::Vector3f* partner, float* squared) const {
    if (options_.projective_stride_px > 0) {
      return moved.z() > 0.0F &&
             NearestDepthSample(*visibility_, options_.projective_stride_px, moved, partner, squared);
    }
    const auto [nearest, distance] = tree_->NearestWithin(moved);
    if (nearest < 0) return false;
    *partner = scene_[static_cast<size_t>(nearest)];
    *squared = distance;
    return true;
  }

  const std::vector<Eigen::Vector3f>& object_;
  const std::vector<Eigen::Vector3f>& scene_;
  const std::vector<Correspondence>& correspondences_;
  const RansacOptions& options_;
  const SceneVisibility* visibility_;
  const RadiusGrid* tree_;                    // null when options_.projective_stride_px > 0
  size_t required_agreeing_ = 0;              // correspondences that must agree with a sample's pose (0: no test)
  std::vector<int> order_;                    // object points in a fixed random order, for the preverification
  std::vector<std::vector<int>> neighbours_;  // per correspondence, when sampling is local (sample_radius_m)
};

}  // namespace

void RansacOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowInputError("RANSAC options", field, expected);
  };
  require(sample_size >= 3, "sample_size", "at least 3");
  require(sample_radius_m >= 0.0, "sample_radius_m", ">= 0 m (0: sample anywhere)");
  require(std::isfinite(polygon_threshold) && polygon_threshold < 1.0, "polygon_threshold", "below 1 (<= 0 disables)");
  require(inlier_threshold_m > 0.0 && std::isfinite(inlier_threshold_m), "inlier_threshold_m", "> 0 m");
  require(required_inlier_fraction > 0.0 && required_inlier_fraction <= 1.0, "required_inlier_fraction", "in (0, 1]");
  require(success_probability > 0.0 && success_probability < 1.0, "success_probability", "in (0, 1)");
  require(expected_inlier_ratio > 0.0 && expected_inlier_ratio <= 1.0, "expected_inlier_ratio", "in (0, 1]");
  require(max_iterations >= 0, "max_iterations", ">= 0 (0: from p, w and n)");
  CheckThreadCount("RANSAC options", threads);
  require(min_support >= 0, "min_support", ">= 0 (0: no test)");
  require(min_support_share >= 0.0 && min_support_share <= 1.0, "min_support_share", "in [0, 1] (0: no test)");
  require(projective_stride_px >= 0, "projective_stride_px", ">= 0 (0: the nearest scene point)");
}

int RansacOptions::Iterations() const {
  if (max_iterations > 0) return max_iterations;
  const double good_sample = std::pow(expected_inlier_ratio, sample_size);
  if (good_sample >= 1.0) return 1;
  return static_cast<int>(std::ceil(std::log(1.0 - success_probability) / std::log(1.0 - good_sample)));
}

bool PolygonEdgeCheck::operator()(const std::vector<Eigen::Vector3f>& object_sample,
                                  const std::vector<Eigen::Vector3f>& scene_sample) const {
  const size_t n = object_sample.size();
  for (size_t i = 0; i < n; ++i) {
    const float d_p = (object_sample[(i + 1) % n] - object_sample[i]).norm();
    const float d_q = (scene_sample[(i + 1) % n] - scene_sample[i]).norm();
    const float longer = std::max(d_p, d_q);
    if (longer <= 0.0F || std::abs(d_p - d_q) / longer > threshold_) return false;
  }
  return true;
}

void SceneVisibility::Check() const {
  camera.Check("scene visibility camera");
  if (depth.type() != CV_32FC1 || depth.cols != camera.width || depth.rows != camera.height) {
    ThrowInputError("scene visibility", "depth", "a CV_32FC1 image of the camera's size");
  }
  if (!(occlusion_margin_m >= 0.0)) ThrowInputError("scene visibility", "occlusion_margin_m", ">= 0 m");
  if (!(min_visible_fraction >= 0.0 && min_visible_fraction <= 1.0)) {
    ThrowInputError("scene visibility", "min_visible_fraction", "in [0, 1]");
  }
}

namespace {

RansacResult Estimate(const std::vector<Eigen::Vector3f>& object_points,
                      const std::vector<Eigen::Vector3f>& scene_points, const RadiusGrid* scene_grid,
                      const std::vector<Correspondence>& correspondences, const RansacOptions& options,
                      const SceneVisibility* visibility) {
  if (visibility != nullptr) visibility->Check();
  if (options.projective_stride_px > 0 && visibility == nullptr) {
    ThrowInputError("RANSAC options", "projective_stride_px", "0 without a SceneVisibility (its depth image)");
  }
  const auto start = std::chrono::steady_clock::now();
  RansacResult result;
  if (static_cast<int>(correspondences.size()) < options.sample_size || object_points.empty() || scene_points.empty()) {
    return result;
  }
  for (const Correspondence& c : correspondences) {
    if (c.object < 0 || c.scene < 0 || c.object >= static_cast<int>(object_points.size()) ||
        c.scene >= static_cast<int>(scene_points.size())) {
      ThrowInputError("RANSAC", "correspondences", "indices inside the point sets");
    }
  }
  const Estimator estimator(object_points, scene_points, scene_grid, correspondences, options, visibility);
  const int iterations = options.Iterations();
  const int blocks = (iterations + kBlockSize - 1) / kBlockSize;
  auto block_size = [&](int block) { return std::min(kBlockSize, iterations - block * kBlockSize); };

  // Blocks are taken in order. A block that ends the run (early stop, or enough iterations for the
  // adaptive count) is found in block order, once every block before it is done; later blocks are then
  // skipped and ignored, so the outcome is that of the serial run whatever the number of threads.
  std::vector<Estimator::BlockOutcome> outcomes(static_cast<size_t>(blocks));
  std::vector<char> done(static_cast<size_t>(blocks), 0);
  std::mutex mutex;
  int frontier = 0;       // blocks before it are done and checked (guarded by mutex)
  double agreeing = 0.0;  // largest share of agreeing correspondences so far, in block order (guarded)
  std::atomic<int> next_block{0};
  std::atomic<int> stop_block{blocks};
  auto needed_iterations = [&](double share) {
    RansacOptions adapted = options;
    adapted.max_iterations = 0;
    adapted.expected_inlier_ratio = std::max(share, options.expected_inlier_ratio);
    return std::min(adapted.Iterations(), iterations);
  };
  auto work = [&] {
    for (int block = next_block++; block < blocks && block <= stop_block.load(); block = next_block++) {
      outcomes[static_cast<size_t>(block)] = estimator.RunBlock(block, block_size(block));
      const std::lock_guard<std::mutex> lock(mutex);
      done[static_cast<size_t>(block)] = 1;
      for (; frontier < blocks && done[static_cast<size_t>(frontier)] != 0 && frontier < stop_block.load();
           ++frontier) {
        const Estimator::BlockOutcome& outcome = outcomes[static_cast<size_t>(frontier)];
        agreeing = std::max(agreeing, outcome.agreeing);
        const bool enough = options.adaptive && (frontier + 1) * kBlockSize >= needed_iterations(agreeing);
        if (outcome.stopped_early || enough) stop_block.store(frontier);
      }
    }
  };
  RunOnThreads(std::min(options.threads, blocks), work);

  Estimator::Best best;
  const int last_block = std::min(stop_block.load(), blocks - 1);
  for (int block = 0; block <= last_block; ++block) {
    const Estimator::BlockOutcome& outcome = outcomes[static_cast<size_t>(block)];
    result.iterations += outcome.iterations;
    result.rejected_by_polygon += outcome.rejected_by_polygon;
    result.rejected_by_support += outcome.rejected_by_support;
    if (Estimator::Better(outcome.best, best)) best = outcome.best;
  }
  if (best.inliers > 0) result.correspondence_inlier_ratio = estimator.AgreeingShare(best.pose);
  if (best.inliers > 0) {
    result.success = true;
    result.scene_from_object = best.pose;
    result.fit_error_m = best.error;  // (the pose with the most agreeing correspondences, when preferred)
    result.inlier_fraction = static_cast<double>(best.inliers) / static_cast<double>(best.visible);
    result.visible_fraction = static_cast<double>(best.visible) / static_cast<double>(object_points.size());
  }
  result.time_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace

RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options,
                                const SceneVisibility* visibility) {
  options.Check();
  if (options.projective_stride_px > 0) {
    return Estimate(object_points, scene_points, nullptr, correspondences, options, visibility);
  }
  const RadiusGrid scene_grid(scene_points, static_cast<float>(options.inlier_threshold_m));
  return Estimate(object_points, scene_points, &scene_grid, correspondences, options, visibility);
}

RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points, const RadiusGrid& scene_grid,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options,
                                const SceneVisibility* visibility) {
  options.Check();
  if (options.projective_stride_px > 0) {
    ThrowInputError("RANSAC", "scene_grid", "none when projective_stride_px looks for partners in the depth image");
  }
  if (scene_grid.size() != scene_points.size() ||
      scene_grid.radius() != static_cast<float>(options.inlier_threshold_m)) {
    ThrowInputError("RANSAC", "scene_grid", "a grid over the scene points with the inlier threshold as radius");
  }
  return Estimate(object_points, scene_points, &scene_grid, correspondences, options, visibility);
}

}  // namespace ecv
