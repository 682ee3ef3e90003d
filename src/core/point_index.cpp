#include "core/point_index.h"

#include <algorithm>
#include <limits>

#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>

namespace ecv {

struct PointIndex::Impl {
  explicit Impl(const std::vector<Eigen::Vector3f>& points)
      : tree(flann::Matrix<float>(const_cast<float*>(points[0].data()), points.size(), 3)) {
    tree.buildIndex();
  }
  flann::KDTreeSingleIndex<flann::L2_Simple<float>> tree;
};

PointIndex::PointIndex(const std::vector<Eigen::Vector3f>& points) : size_(points.size()) {
  if (!points.empty()) impl_ = std::make_unique<Impl>(points);  // Vector3f is 3 packed floats
}

PointIndex::~PointIndex() = default;

std::pair<int, float> PointIndex::Nearest(const Eigen::Vector3f& query) const {
  if (!impl_) return {-1, std::numeric_limits<float>::infinity()};
  size_t index = 0;
  float squared = 0.0F;
  flann::Matrix<size_t> indices(&index, 1, 1);
  flann::Matrix<float> distances(&squared, 1, 1);
  impl_->tree.knnSearch(flann::Matrix<float>(const_cast<float*>(query.data()), 1, 3), indices, distances, 1,
                        flann::SearchParams(-1));
  return {static_cast<int>(index), squared};
}

std::vector<int> PointIndex::KNearest(const Eigen::Vector3f& query, int k) const {
  const size_t count = std::min(size_, static_cast<size_t>(std::max(k, 0)));
  if (!impl_ || count == 0) return {};
  std::vector<size_t> found(count);
  std::vector<float> squared(count);
  flann::Matrix<size_t> indices(found.data(), 1, count);
  flann::Matrix<float> distances(squared.data(), 1, count);
  impl_->tree.knnSearch(flann::Matrix<float>(const_cast<float*>(query.data()), 1, 3), indices, distances, count,
                        flann::SearchParams(-1));
  return std::vector<int>(found.begin(), found.end());
}

}  // namespace ecv
