#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace ecv {

/// Settings of a KdForest.
struct KdForestOptions {
  int trees = 4;      ///< randomised kd-trees, searched together
  int leaf_size = 8;  ///< most rows in a leaf (a leaf is searched whole)
  uint64_t seed = 1;  ///< the trees' random split choices: the same rows and seed give the same trees

  void Check() const;
};

/// Approximate nearest neighbours (Euclidean) among the rows of a float matrix: FLANN's randomised kd-trees
/// (Silpa-Anan and Hartley; Muja and Lowe), searched best bin first across all trees at once, but with leaves of
/// several rows. FLANN's leaves hold one row, so each row it compares costs a descent from a branch point and a
/// heap entry per level; here a descent pays for `leaf_size` rows. On the context descriptors of YCB-Video
/// frames (96 dimensions, 900-6500 rows), 2 trees and 64 checks find the exact neighbour as often as OpenCV's
/// FLANN with 4 trees and 32 checks (50 % of queries) at 0.32x its time per query; the recognizer's 4 trees and 128
/// checks find it for 71 % at 0.68x (bench/matching_bench, 2026-11-24). Thread-safe to search once built.
class KdForest {
 public:
  /// Indexes the rows of `rows` (CV_32FC1, one point per row; copied).
  explicit KdForest(const cv::Mat& rows, const KdForestOptions& options = {});

  /// The `k` nearest rows of each row of `queries` (CV_32FC1, as many columns) among those compared, nearest
  /// first: `indices` (CV_32SC1) and `squared_distances` (CV_32FC1), each queries.rows x k; -1 and +inf where
  /// fewer than k rows were compared. A query compares about `checks` rows (whole leaves, at least k rows); with
  /// `checks` >= size() it compares every row, an exact search. Ties go to the lower row.
  void Search(const cv::Mat& queries, int k, int checks, cv::Mat* indices, cv::Mat* squared_distances) const;

  int size() const { return rows_.rows; }

 private:
  // A tree node in preorder: an inner node's left child follows it, `right` is its right child's index; a leaf
  // (dim < 0) holds the rows order_[tree][begin .. end).
  struct Node {
    int dim = -1;
    float value = 0.0F;
    int right = -1;
    int begin = 0, end = 0;
  };
  struct Builder;   // builds one tree (kd_forest.cpp)
  struct Searcher;  // searches for one query at a time (kd_forest.cpp)

  cv::Mat rows_;
  std::vector<std::vector<Node>> nodes_;  // per tree
  std::vector<std::vector<int>> order_;   // per tree, the rows grouped by leaf
};

}  // namespace ecv
