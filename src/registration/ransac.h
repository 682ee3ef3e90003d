#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/point_index.h"

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
  /// Beyond the paper: the iteration count is lowered as accepted poses show a larger share w of agreeing
  /// correspondences (k = log(1 - p) / log(1 - w^n), w from the best pose so far, at most Iterations()).
  bool adaptive = false;
  /// Beyond the paper: of the accepted poses keep the one with the most agreeing correspondences (ties: the
  /// lower fit error) instead of the lowest fit error. The correspondences carry appearance, so this tells a
  /// box from the same box turned over, which fit the scene's shape equally well.
  bool prefer_agreeing = false;
  uint64_t seed = 1;  ///< same seed, same result (whatever the number of threads)
  int threads = 1;    ///< worker threads (1 to kMaxThreads); the result does not depend on it
  /// Beyond the paper: object points are checked in a fixed random order and a hypothesis is dropped once
  /// its inlier count falls 3 standard deviations below the required fraction (binomial), after at least
  /// 50 points. Wrong poses are then dropped after a few hundred points instead of all of them; a pose
  /// whose true inlier fraction is at least the required one is dropped with a probability below 0.2 %
  /// per check. false: every point is checked, as in the paper.
  bool preverify = true;
  /// Beyond the paper: the second and later correspondences of a sample are drawn among those whose scene
  /// and object points both lie within this distance of the first one's, metres (0: anywhere, as in the
  /// paper). Set to the object's diameter, a sample whose first correspondence is true is then all true with
  /// probability w'^(n-1), w' the share of true ones near the object, instead of w^(n-1) over the whole scene.
  double sample_radius_m = 0.0;
  /// Beyond the paper: a sample's pose is dropped before its inliers are counted unless, besides the sample's
  /// own, at least max(min_support, ceil(min_support_share x the correspondences)) correspondences agree with it
  /// (within inlier_threshold_m). Counting them costs a transform per correspondence; counting inliers costs a
  /// nearest-point search per object point, and in a cluttered scene most poses near a surface pass the inlier
  /// test. A wrong pose gathers agreeing correspondences by chance, more of them the more there are, hence the
  /// share. Both 0: every pose is counted, as in the paper.
  int min_support = 0;
  double min_support_share = 0.0;
  /// Where an object point's inlier partner is looked for. 0 (the paper): the nearest scene point in 3D. n > 0
  /// (beyond the paper; needs a SceneVisibility, whose depth image and camera it uses): the nearest of the 3 x 3
  /// depth samples n pixels apart centred on the pixel the point projects to. Nine look-ups in the image instead
  /// of a search among the scene points; a partner within inlier_threshold_m is missed only where the surface
  /// runs so steeply away from the ray that it lies more than n pixels aside. The scene points then serve the
  /// correspondences alone.
  int projective_stride_px = 0;

  /// Throws InputError on values outside their ranges.
  void Check() const;

  /// The iteration count k (max_iterations when set).
  int Iterations() const;
};

/// What the scene camera can see. With it, the required inlier fraction counts against the object points
/// that the pose hypothesis leaves visible (in the image, in front of or on the scene surface, where the
/// sensor measured depth), so a partly hidden object is not rejected for what it cannot show.
struct SceneVisibility {
  cv::Mat depth;                      ///< CV_32FC1 scene depth, metres, 0 = missing
  PinholeCamera camera;               ///< the scene camera; scene points are in its frame
  double occlusion_margin_m = 0.01;   ///< an object point further than this behind the scene surface is hidden
  double min_visible_fraction = 0.2;  ///< hypotheses that leave fewer object points visible are dropped

  /// Throws InputError when the depth image is not CV_32FC1 of the camera's size or a value is out of range.
  void Check() const;
};

/// Outcome of one estimation. "Nothing found" is success == false, not an exception.
struct RansacResult {
  bool success = false;
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();  ///< camera_from_object for a scene frame
  double inlier_fraction = 0.0;              ///< of the object points (of the visible ones, with a SceneVisibility)
  double correspondence_inlier_ratio = 0.0;  ///< share of the correspondences that agree with the pose
  double visible_fraction = 1.0;             ///< object points visible under the pose (1 without a SceneVisibility)
  double fit_error_m = 0.0;                  ///< mean distance of the inlier pairs under the re-estimated pose, metres
  int iterations = 0;                        ///< samples drawn
  int rejected_by_polygon = 0;               ///< samples the polygon test dropped before a pose was computed
  int rejected_by_support = 0;               ///< poses dropped by min_support(_share) before their inliers were counted
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

/// Estimates scene_from_object from correspondences between object and scene points (metres). Samples are
/// drawn in blocks with their own seeds, so the result depends on the seed only, not on `options.threads`.
/// `visibility` (optional) counts the required inliers against the visible object points only.
RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options = {},
                                const SceneVisibility* visibility = nullptr);

/// The same with `scene_points` already in `scene_grid`, a RadiusGrid over exactly those points with radius
/// `options.inlier_threshold_m`: a recognizer that tries many views against one frame builds it once (about
/// 0.3 ms per build over a YCB-Video frame's points). Throws InputError when the grid does not fit, or when
/// options.projective_stride_px asks for the depth image instead (use the overload above: it builds no grid then).
RansacResult EstimatePoseRansac(const std::vector<Eigen::Vector3f>& object_points,
                                const std::vector<Eigen::Vector3f>& scene_points, const RadiusGrid& scene_grid,
                                const std::vector<Correspondence>& correspondences, const RansacOptions& options = {},
                                const SceneVisibility* visibility = nullptr);

}  // namespace ecv
