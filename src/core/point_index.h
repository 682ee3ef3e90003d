#pragma once

#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace ecv {

/// Exact nearest-neighbour queries over a fixed set of 3D points (a FLANN kd-tree). The points are not
/// copied: they must outlive the index and stay unchanged.
class PointIndex {
 public:
  explicit PointIndex(const std::vector<Eigen::Vector3f>& points);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  /// Index of the point nearest `query` and its squared distance (m^2); {-1, inf} for an empty set.
  std::pair<int, float> Nearest(const Eigen::Vector3f& query) const;

  /// Indices of the `k` points nearest `query`, nearest first (fewer when the set is smaller).
  std::vector<int> KNearest(const Eigen::Vector3f& query, int k) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  size_t size_ = 0;
};

}  // namespace ecv
