#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace ecv {

/// Exact nearest neighbours (Euclidean) among rows of values in [0, 1] quantised to 7 bits (round(127 v), values
/// outside clamped): every row is compared, in integer arithmetic, so the result does not depend on the CPU. For
/// the nearest row alone (k = 1), on a CPU with AVX-512 VNNI, 16 queries lie in the lanes of one register per
/// 4-byte group and each row's group is broadcast into one VNNI instruction, so that a row is read once for 16
/// queries; otherwise a plain loop (about 50x slower) gives the same integers. Made for the context descriptors,
/// whose values are square roots of histogram shares. Thread-safe to search once built.
class ByteNeighbours {
 public:
  /// Indexes the rows of `rows` (CV_32FC1, one point per row).
  explicit ByteNeighbours(const cv::Mat& rows);

  /// The `k` nearest rows of each row of `queries` (CV_32FC1, as many columns), nearest first, ties to the lower
  /// row: `indices` (CV_32SC1) and `squared_distances` (CV_32FC1, between the quantised values, in the units of
  /// the input), each queries.rows x k; -1 and +inf where there are fewer than k rows.
  void Search(const cv::Mat& queries, int k, cv::Mat* indices, cv::Mat* squared_distances) const;

  int size() const { return rows_; }

  /// False: Search takes the plain loop even where AVX-512 VNNI is available (tests compare the two).
  static void AllowVnni(bool allow);
  /// True when this CPU has AVX-512 VNNI: without it Search takes the plain loop (bench/matching_bench).
  static bool CpuHasVnni();

 private:
  int rows_ = 0;
  int cols_ = 0;
  int groups_ = 0;              // 4-byte groups per row: ceil(cols / 4)
  std::vector<uint8_t> bytes_;  // the quantised rows one after the other, groups_ x 4 bytes each (zero-padded)
  std::vector<int32_t> norms_;  // squared norm of each quantised row
};

}  // namespace ecv
