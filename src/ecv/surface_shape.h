#pragma once

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/frame.h"

namespace ecv {

/// The depth image's surface, thinned to one point per voxel, each with its normal: the support of the
/// surface-shape context (DescriptorShape::kSurface), as a dense point cloud is SHOT's.
struct SurfaceSamples {
  std::vector<Eigen::Vector3f> points;   ///< voxel centroids, metres, in the frame of the primitives they go with
  std::vector<Eigen::Vector3f> normals;  ///< unit, facing the camera that saw them

  size_t size() const { return points.size(); }
};

/// Options of the sampling.
struct SurfaceSampling {
  double voxel_m = 0.004;         ///< edge of the voxels the depth pixels are averaged in
  double normal_radius_m = 0.01;  ///< plane fit over the samples within this distance, for the normals
};

/// The surface of `frame`'s depth image where `mask` (CV_8UC1, optional) is set, in the camera frame.
SurfaceSamples SampleSurface(const RgbdFrame& frame, const cv::Mat& mask = {}, const SurfaceSampling& sampling = {});

/// `samples` moved by `transform` (points and normals), e.g. into an object's frame with its primitives.
SurfaceSamples MovedSurface(const SurfaceSamples& samples, const Eigen::Isometry3f& transform);

}  // namespace ecv
