#pragma once

#include <cstdint>
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

/// Nearest point within a fixed radius, by a dense grid over the points' bounding box with cells of at
/// least twice the radius, so that a query visits at most 8 cells. Several times faster than the kd-tree
/// for the many fixed-radius queries of RANSAC's inlier count.
class RadiusGrid {
 public:
  RadiusGrid(const std::vector<Eigen::Vector3f>& points, float radius);

  /// Index of the point nearest `query` among those within the radius, and its squared distance (m^2);
  /// {-1, inf} when there is none.
  std::pair<int, float> NearestWithin(const Eigen::Vector3f& query) const;

  float radius() const { return radius_; }
  size_t size() const { return sorted_.size(); }

 private:
  float radius_ = 0.0F, cell_ = 1.0F;
  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  Eigen::Vector3i size_ = Eigen::Vector3i::Zero();
  std::vector<uint32_t> cell_start_;     // points of cell c: sorted_[cell_start_[c] .. cell_start_[c + 1])
  std::vector<Eigen::Vector3f> sorted_;  // points ordered by cell
  std::vector<int> sorted_index_;        // their indices in the input
};

}  // namespace ecv
