#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace ecv {

/// A hexagonal grid of cells over an image: cell centres on a triangular lattice (rows `spacing * sqrt(3)/2`
/// apart, every other row shifted by half a spacing); each pixel belongs to its nearest centre, so cells
/// are hexagons of `spacing` pixels across.
class HexGrid {
 public:
  /// Grid for images of `size` with centres `spacing_px` apart (>= 2).
  HexGrid(cv::Size size, double spacing_px);

  int NumCells() const { return static_cast<int>(centres_.size()); }
  const Eigen::Vector2f& Centre(int cell) const { return centres_[static_cast<size_t>(cell)]; }

  /// CV_32SC1 image of the cell index of each pixel.
  const cv::Mat& Labels() const { return labels_; }

  cv::Size ImageSize() const { return labels_.size(); }
  double Spacing() const { return spacing_; }

 private:
  double spacing_;
  std::vector<Eigen::Vector2f> centres_;
  cv::Mat labels_;
};

}  // namespace ecv
