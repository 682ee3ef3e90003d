#include "ecv/surface_shape.h"

#include <cstdint>
#include <unordered_map>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <Eigen/Eigenvalues>

namespace ecv {
namespace {

// Depth pixels summed per voxel.
struct Voxel {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
};

flann::SearchParams Unsorted() {  // a plane fit does not need its points by distance
  flann::SearchParams params;
  params.sorted = false;
  return params;
}

int64_t VoxelKey(const Eigen::Vector3d& point, double voxel_m) {
  constexpr int64_t kOffset = 1 << 20;  // voxel indices within +-2^20 (4 km at 4 mm)
  const Eigen::Vector3d cell = (point / voxel_m).array().floor();
  return ((static_cast<int64_t>(cell.x()) + kOffset) << 42) | ((static_cast<int64_t>(cell.y()) + kOffset) << 21) |
         (static_cast<int64_t>(cell.z()) + kOffset);
}

}  // namespace

SurfaceSamples SampleSurface(const RgbdFrame& frame, const cv::Mat& mask, const SurfaceSampling& sampling) {
  std::unordered_map<int64_t, Voxel> voxels;
  std::vector<int64_t> order;  // first-seen order of the voxels: the result does not depend on hashing
  for (int v = 0; v < frame.depth.rows; ++v) {
    const float* depth = frame.depth.ptr<float>(v);
    const uchar* inside = mask.empty() ? nullptr : mask.ptr<uchar>(v);
    for (int u = 0; u < frame.depth.cols; ++u) {
      if (!(depth[u] > 0.0F) || (inside != nullptr && inside[u] == 0)) continue;
      const Eigen::Vector3d point = frame.camera.BackProject(Eigen::Vector2d(u, v), depth[u]);
      const int64_t key = VoxelKey(point, sampling.voxel_m);
      Voxel& voxel = voxels[key];
      if (voxel.count == 0) order.push_back(key);
      voxel.sum += point;
      ++voxel.count;
    }
  }
  SurfaceSamples samples;
  samples.points.reserve(order.size());
  for (const int64_t key : order) {
    const Voxel& voxel = voxels[key];
    samples.points.push_back((voxel.sum / voxel.count).cast<float>());
  }
  if (samples.points.empty()) return samples;

  flann::KDTreeSingleIndex<flann::L2_Simple<float>> index(
      flann::Matrix<float>(samples.points[0].data(), samples.points.size(), 3), flann::KDTreeSingleIndexParams(12));
  index.buildIndex();
  std::vector<std::vector<size_t>> found(1);
  std::vector<std::vector<float>> squared(1);
  const float radius = static_cast<float>(sampling.normal_radius_m);
  samples.normals.reserve(samples.points.size());
  for (Eigen::Vector3f point : samples.points) {
    index.radiusSearch(flann::Matrix<float>(point.data(), 1, 3), found, squared, radius * radius, Unsorted());
    Eigen::Vector3f normal = -point.normalized();  // too few neighbours: facing the camera
    if (found[0].size() >= 3) {
      Eigen::Vector3f mean = Eigen::Vector3f::Zero();
      for (const size_t i : found[0]) mean += samples.points[i];
      mean /= static_cast<float>(found[0].size());
      Eigen::Matrix3f covariance = Eigen::Matrix3f::Zero();
      for (const size_t i : found[0]) {
        const Eigen::Vector3f offset = samples.points[i] - mean;
        covariance += offset * offset.transpose();
      }
      normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f>(covariance).eigenvectors().col(0);
      if (normal.dot(point) > 0.0F) normal = -normal;  // the camera is at the origin
    }
    samples.normals.push_back(normal);
  }
  return samples;
}

SurfaceSamples MovedSurface(const SurfaceSamples& samples, const Eigen::Isometry3f& transform) {
  SurfaceSamples moved;
  moved.points.reserve(samples.points.size());
  moved.normals.reserve(samples.normals.size());
  for (const Eigen::Vector3f& point : samples.points) moved.points.push_back(transform * point);
  for (const Eigen::Vector3f& normal : samples.normals) moved.normals.push_back(transform.linear() * normal);
  return moved;
}

}  // namespace ecv
