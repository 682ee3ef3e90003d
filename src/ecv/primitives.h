#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "core/frame.h"
#include "ecv/monogenic.h"

namespace ecv {

/// Kind of an ECV primitive (paper Sect. II-A): an edge cell gives a line segment, a texture cell a texlet.
enum class PrimitiveType : uint8_t { kSegment = 0, kTexlet = 1 };

const char* ToString(PrimitiveType type);

/// One ECV primitive, in the camera frame of the image it came from (or an object frame once moved).
struct Primitive {
  PrimitiveType type = PrimitiveType::kTexlet;
  Eigen::Vector3f position = Eigen::Vector3f::Zero();  ///< metres
  /// Unit vector: a segment's 3D direction along its edge, a texlet's surface normal facing the camera. A
  /// segment's sign follows the image axes (the monogenic orientation lies in [0, pi)), not the object: it
  /// turns over when the camera rolls about its optical axis (DescriptorOptions::unsigned_segments).
  Eigen::Vector3f orientation = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f color = Eigen::Vector3f::Zero();  ///< mean RGB near the keypoint, in [0, 1]
  Eigen::Vector2f pixel = Eigen::Vector2f::Zero();  ///< keypoint, pixels
  float magnitude = 0.0F;                           ///< monogenic magnitude at the keypoint
  float image_orientation = 0.0F;                   ///< monogenic orientation at the keypoint, radians in [0, pi)
};

/// Options of the ECV extraction; defaults chosen by the correspondence score of the context descriptor on
/// YCB-Video videos 0000 and 0001 (bench/discriminative_bench's ablations, bench/EXPERIMENTS.md, 2026-11-21).
struct EcvOptions {
  MonogenicOptions monogenic;
  double grid_spacing_px = 5.0;     ///< distance between hexagonal cell centres, pixels
  double min_magnitude = 0.02;      ///< cells whose largest magnitude is below are homogeneous (grey in [0, 1])
  double max_edge_variance = 0.25;  ///< circular variance of 2 theta (magnitude-weighted) below: edge, above: texture
  bool edge_nms = true;             ///< drop edge cells whose keypoint is not a magnitude maximum across the edge
  double surface_radius_m = 0.01;   ///< radius of the local surface fitted for normals and edge directions, metres
  double depth_gap_m = 0.01;        ///< depths further than this behind the nearest one belong to another surface
  int color_radius_px = 2;          ///< colour = mean over the (2r+1)^2 pixels around the keypoint on its surface

  void Check() const;
};

/// What happened to the cells of one image.
struct ExtractionCounts {
  int cells = 0;          ///< cells of the hexagonal grid
  int homogeneous = 0;    ///< dropped: magnitude too low
  int edge_cells = 0;     ///< classified as edge
  int texture_cells = 0;  ///< classified as texture
  int suppressed = 0;     ///< edge cells dropped by non-maximum suppression (ringing beside a stronger edge)
  int no_depth = 0;       ///< dropped: no valid depth near the keypoint
  int no_surface = 0;     ///< dropped: too few surface points for an orientation
  int segments = 0;       ///< segments kept
  int texlets = 0;        ///< texlets kept
};

/// Time per step, milliseconds.
struct ExtractionTimings {
  double monogenic_ms = 0.0;
  double grid_ms = 0.0;
  double classify_ms = 0.0;
  double reconstruct_ms = 0.0;
  double Total() const { return monogenic_ms + grid_ms + classify_ms + reconstruct_ms; }
};

struct ExtractionResult {
  std::vector<Primitive> primitives;
  ExtractionCounts counts;
  ExtractionTimings timings;
};

/// ECV primitives of an RGB-D frame (paper Sect. II-A): monogenic signal,
/// hexagonal grid, intrinsic-dimensionality classification and 3D reconstruction from the depth image.
/// `mask` (CV_8UC1, optional) restricts keypoints to non-zero pixels.
ExtractionResult ExtractPrimitives(const RgbdFrame& frame, const EcvOptions& options = {}, const cv::Mat& mask = {});

/// The positions of `primitives`, in order (the point sets of RANSAC and ICP).
std::vector<Eigen::Vector3f> PrimitivePositions(const std::vector<Primitive>& primitives);

}  // namespace ecv
