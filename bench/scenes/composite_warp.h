#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "scenes/composites.h"

namespace ecv::bench {

/// An object cut from a frame by its label mask.
struct Cut {
  std::vector<Eigen::Vector3d> points;  ///< camera frame of the source, metres, one per kept label pixel
  std::vector<cv::Vec3b> colors;        ///< RGB of each point's pixel
  std::vector<uint8_t> measured;        ///< 1 where the source measured the depth, 0 where it was interpolated
};

/// The pixels of `source` labelled `truth.object_id`, back-projected through their depth. Dropped: pixels farther than
/// max_label_depth_m from the mask's median depth (label noise) and pixels farther than max_surface_distance_m from
/// the object's model points at its ground-truth pose (outline pixels mixing it with what lies behind). Pixels
/// without depth take the mean depth of their neighbours in the mask (filled inwards over a few passes) or are
/// dropped when none is near.
Cut CutObject(const SourceFrame& source, const GroundTruth& truth, const std::vector<Eigen::Vector3d>& model_points,
              const CompositeOptions& options);

/// Share of `points` (object frame, at `camera_from_object`) whose pixel lies within 2 px of `source`'s label
/// mask of `class_index`: below 1 when another object or the image border hides part of the object.
double WholeShare(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& camera_from_object,
                  const SourceFrame& source, int class_index);

/// A cut seen from another camera.
struct Warp {
  cv::Mat depth;     ///< CV_32F, metres; 0 where the object does not show
  cv::Mat color;     ///< CV_8UC3 RGB
  cv::Mat measured;  ///< CV_8U, 1 where the source measured the depth
  int points = 0;    ///< cut points
  int inside = 0;    ///< of those, landing in front of the camera and inside the image
  cv::Rect box;      ///< the pixels the object may cover (empty when none)
};

/// `cut` moved by `target_from_source` and projected into `camera`: a forward splat of each point onto its 2x2 pixel
/// neighbourhood with a z-buffer; among the splats within `tolerance_m` of a pixel's nearest, the one nearest the
/// pixel's centre gives its colour and depth. Cracks (empty pixels with at least 5 of 8 filled neighbours) are
/// filled by their neighbours' mean.
Warp WarpCut(const Cut& cut, const Eigen::Isometry3d& target_from_source, const PinholeCamera& camera,
             double tolerance_m);

/// CV_8U mask (255) of the pixels where `warp` shows in front of `target_depth`: nearer than it plus `tolerance_m`,
/// or where it has no depth. In the holes of the target's objects (`target_labels` > 0) the nearest depth within
/// 5 px stands in for it.
cv::Mat ShownMask(const Warp& warp, const cv::Mat& target_depth, const cv::Mat& target_labels, double tolerance_m);

}  // namespace ecv::bench
