#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "io/frame_io.h"

namespace ecv::bench {

/// A plane of a frame's camera: points x with normal . x + offset = 0.
struct TablePlane {
  Eigen::Vector3d normal = -Eigen::Vector3d::UnitZ();  ///< unit, camera frame, pointing towards the camera
  double offset = 0.0;                                 ///< metres; the camera's height above the plane
  int inliers = 0;                                     ///< depth samples within 1 cm of the plane

  /// Signed height of a camera-frame point above the plane, metres (positive on the camera's side).
  double Height(const Eigen::Vector3d& point_camera) const { return normal.dot(point_camera) + offset; }
};

/// The dominant plane of `frame`'s depth: RANSAC from `seed` over the back-projected points of a pixel grid,
/// leaving out the pixels `labels` gives an object (and a margin around them), then least squares on the inliers.
/// `inliers` is 0 when the depth holds too few points for a plane.
TablePlane FitTablePlane(const RgbdFrame& frame, const cv::Mat& labels, uint32_t seed);

/// A real YCB-Video frame with what compositing needs beyond LoadYcbvFrame.
struct SourceFrame {
  std::string prefix;  ///< ".../0001/000001"
  LoadedFrame frame;
  cv::Mat labels;    ///< CV_8UC1 -label.png: YCB-Video class index per pixel, 0 for none
  TablePlane table;  ///< the table the objects stand on (FitTablePlane, seed 0)
  /// Per ground-truth object name: its model points (points.xyz), object frame, metres.
  std::map<std::string, std::vector<Eigen::Vector3d>> model_points;
};

/// Loads `prefix` (-color, -depth, -meta.mat, -label.png), the points.xyz of each of its ground-truth objects from
/// `models_dir` (default: the "models" folder beside the dataset's Example-Scenes, `prefix`/../../../models) and fits
/// its table plane. InputError naming the file on a broken or missing one.
SourceFrame LoadSourceFrame(const std::string& prefix, const std::string& models_dir = "");

/// How composites are made.
struct CompositeOptions {
  double max_view_change_deg = 12.0;  ///< the pasted object is seen from at most this far from its source view
  double max_hidden_share = 0.5;      ///< a target object may lose at most this share of its visible pixels
  double min_gap_m = 0.0;             ///< placed beside a neighbour at a gap drawn in [min, max], metres
  double max_gap_m = 0.03;
  int attempts = 200;                    ///< placements tried before giving up on one composite
  double max_turn_deg = 15.0;            ///< random turn about the target table's normal, in [-max, max] degrees
  double min_source_whole = 0.95;        ///< share of the object's projected model points its source labels must cover
  double max_label_depth_m = 0.15;       ///< label pixels farther than this from the cut's median depth are dropped
  double max_surface_distance_m = 0.02;  ///< and those farther than this from the model at its ground truth, metres
  double min_inside_share = 0.9;         ///< share of the warped object's pixels that must land inside the image
  double min_support_share = 0.8;        ///< share of the footprint's visible table pixels within 2 cm of the plane
  double occlusion_tolerance_m = 0.005;  ///< pasted where nearer than the target's depth plus this, metres

  /// Throws InputError naming the field for values outside their domains and an inverted gap range.
  void Check() const;
};

/// Why placements were rejected: counts over the attempts of one MakeComposite call.
struct CompositeAttempts {
  int tried = 0;
  int view_changed = 0;  ///< seen from farther than max_view_change_deg from its source view
  int left_image = 0;    ///< less than min_inside_share of it inside the image
  int unsupported = 0;   ///< its footprint is not on the target's table (edge of the table, unlabelled things)
  int collided = 0;      ///< intersects a target object
  int hid_target = 0;    ///< hides more than max_hidden_share of a target object
  std::string refused;   ///< set when no placement was tried: the model is in the target, the source object not whole
};

/// One composite: `target` with the object `object_name` of `source` cut by its label mask (colour and depth),
/// moved rigidly onto the target's table (its pose and image reprojected pixel by pixel through its depth), pasted
/// where it is nearer than the target's surface, so it hides and is hidden consistently.
struct Composite {
  LoadedFrame frame;          ///< the target frame with the object pasted; ground truth: the target's plus the pasted
  std::string source_prefix;  ///< where the object was cut
  std::string target_prefix;  ///< the frame pasted into
  std::string object_name;    ///< pasted object
  std::string beside;         ///< the target's object it was placed beside ("" for a free place on the table)
  cv::Mat labels;             ///< CV_8UC1 class index per pixel of the composite (the target's, the pasted object's)
  Eigen::Isometry3d target_from_source;  ///< the rigid move applied, camera frames, metres
  double view_change_deg = 0.0;          ///< angle between the object's source and composite viewing directions
  int pasted_pixels = 0;                 ///< pixels of the composite that show the pasted object
  CompositeAttempts attempts;            ///< the rejected placements before this one
};

/// Makes a composite from `seed` (the same seed and frames give the same composite): `object_name` cut from
/// `source` and placed beside the target's object `beside` (or anywhere on the table when ""). Returns false (and
/// leaves `out` alone) when no placement within the options was found, when the target already holds the model
/// (one instance per model) or when the source object is not whole in its frame; `attempts`, when given, says
/// why. Throws InputError when `source` lacks `object_name` or its label pixels, or `target` lacks `beside`.
bool MakeComposite(const SourceFrame& source, const std::string& object_name, const SourceFrame& target,
                   const std::string& beside, uint32_t seed, const CompositeOptions& options, Composite* out,
                   CompositeAttempts* attempts = nullptr);

}  // namespace ecv::bench
