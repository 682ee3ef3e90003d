#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace ecv {

/// An object point matched to a scene point (indices into the two point sets).
struct Correspondence {
  int object = -1;
  int scene = -1;
};

/// The paper's RANSAC (Sect. III). With polygon_threshold > 0 it is the prerejective variant: a sample
/// whose polygon edge lengths disagree is dropped before any pose is computed.
struct RansacOptions {
  int sample_size = 3;               ///< n, correspondences per sample (>= 3)
  double polygon_threshold = 0.25;   ///< t_poly on max_i |d_p,i - d_q,i| / max(d_p,i, d_q,i); <= 0: standard RANSAC
  double inlier_threshold_m = 0.01;  ///< eps: an object point is an inlier within this of a scene point, metres
  double required_inlier_fraction = 0.5;  ///< of the object points (0.1 for scene registration)
  double success_probability = 0.99;      ///< p
  double expected_inlier_ratio = 0.05;    ///< w, of the correspondences
  int max_iterations = 0;                 ///< 0: k = log(1 - p) / log(1 - w^n), about 37 000 by default
  double early_stop_fit_error_m = 0.0;    ///< > 0: stop once an accepted pose fits better than this, metres
  uint64_t seed = 1;                      ///< same seed, same result

  /// Throws InputError on values outside their ranges.
  void Check() const;

  /// The iteration count k (max_iterations when set).
  int Iterations() const;
};

/// Outcome of one estimation. "Nothing found" is success == false, not an exception.
struct RansacResult {
  bool success = false;
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();  ///< camera_from_object for a scene frame
  double inlier_fraction = 0.0;                                         ///< of the object points
  double fit_error_m = 0.0;     ///< mean distance of the inliers to their nearest scene points, metres
  int iterations = 0;           ///< samples drawn
  int rejected_by_polygon = 0;  ///< samples the polygon test dropped before a pose was computed
  double time_ms = 0.0;
};

/// The polygon edge-length test of the paper (Sect. III) as a small check object: true when the two
/// polygons through the sampled points are similar enough to be related by a rigid motion.
class PolygonEdgeCheck {
 public:
  explicit PolygonEdgeCheck(double threshold) : threshold_(threshold) {}
  bool operator()(const std::vector<Eigen::Vector3f>& object_sample,
                  const std::vector<Eigen::Vector3f>& scene_sample) const;

 private:
  double threshold_;
};

/// Estimates scene_from_object from correspondences between object and scene points (metres).
RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options = {});

}  // namespace ecv
