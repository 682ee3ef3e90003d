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

RadiusGrid::RadiusGrid(const std::vector<Eigen::Vector3f>& points, float radius) : radius_(radius) {
  if (points.empty() || !(radius > 0.0F)) return;
  Eigen::Vector3f low = points[0], high = points[0];
  for (const Eigen::Vector3f& point : points) {
    low = low.cwiseMin(point);
    high = high.cwiseMax(point);
  }
  // Cells of at least twice the radius; larger when the grid would exceed about 4 million cells.
  constexpr double kMaxCells = 4.0e6;
  const Eigen::Vector3f extent = (high - low).cwiseMax(1e-6F);
  cell_ = std::max(2.0F * radius, static_cast<float>(std::cbrt(extent.prod() / kMaxCells)));
  origin_ = low;
  size_ = ((extent / cell_).array().floor().cast<int>() + 1).matrix();
  auto cell_of = [&](const Eigen::Vector3f& point) {
    const Eigen::Vector3i c = ((point - origin_) / cell_).array().floor().cast<int>().cwiseMin(size_.array() - 1);
    return static_cast<size_t>((c.z() * size_.y() + c.y()) * size_.x() + c.x());
  };
  cell_start_.assign(static_cast<size_t>(size_.prod()) + 1, 0);
  for (const Eigen::Vector3f& point : points) ++cell_start_[cell_of(point) + 1];
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  std::vector<uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  sorted_.resize(points.size());
  sorted_index_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const uint32_t slot = fill[cell_of(points[i])]++;
    sorted_[slot] = points[i];
    sorted_index_[slot] = static_cast<int>(i);
  }
}

std::pair<int, float> RadiusGrid::NearestWithin(const Eigen::Vector3f& query) const {
  std::pair<int, float> best{-1, std::numeric_limits<float>::infinity()};
  if (sorted_.empty()) return best;
  const Eigen::Vector3f low = (query.array() - radius_ - origin_.array()) / cell_;
  const Eigen::Vector3f high = (query.array() + radius_ - origin_.array()) / cell_;
  // Clamped in float first, so that far-away queries cannot overflow the integer cast.
  const Eigen::Array3f top = size_.array().cast<float>() - 1.0F;
  const Eigen::Vector3i first = low.array().floor().max(0.0F).min(top + 1.0F).cast<int>();
  const Eigen::Vector3i last = high.array().floor().min(top).max(-1.0F).cast<int>();
  float best_squared = radius_ * radius_;
  for (int z = first.z(); z <= last.z(); ++z) {
    for (int y = first.y(); y <= last.y(); ++y) {
      for (int x = first.x(); x <= last.x(); ++x) {
        const size_t c = static_cast<size_t>((z * size_.y() + y) * size_.x() + x);
        for (uint32_t i = cell_start_[c]; i < cell_start_[c + 1]; ++i) {
          const float squared = (sorted_[i] - query).squaredNorm();
          if (squared <= best_squared) {
            best_squared = squared;
            best = {sorted_index_[i], squared};
          }
        }
      }
    }
  }
  return best;
}

}  // namespace ecv
