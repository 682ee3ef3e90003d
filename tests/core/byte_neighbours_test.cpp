// ByteNeighbours against a brute force over the same 7-bit values: the same rows and distances, nearest first,
// ties to the lower row; the AVX-512 VNNI kernels and the plain loop agree to the bit.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "core/byte_neighbours.h"
#include "core/error.h"

namespace ecv {
namespace {

// `count` rows of `dims` values in [0, 1] (a few outside, which are clamped), around a few centres.
cv::Mat Rows(int count, int dims, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(-0.05F, 1.05F);
  std::normal_distribution<float> noise(0.0F, 0.08F);
  cv::Mat centres(8, dims, CV_32F), rows(count, dims, CV_32F);
  for (int c = 0; c < centres.rows; ++c) {
    for (int d = 0; d < dims; ++d) centres.at<float>(c, d) = uniform(random);
  }
  for (int r = 0; r < count; ++r) {
    const int c = static_cast<int>(random() % 8U);
    for (int d = 0; d < dims; ++d) rows.at<float>(r, d) = centres.at<float>(c, d) + noise(random);
  }
  return rows;
}

int Quantised(float value) {
  return static_cast<int>(std::lround(std::clamp(value, 0.0F, 1.0F) * 127.0F));
}

// The k nearest rows by the quantised squared distance, ties to the lower row: {distance, row} pairs.
std::vector<std::pair<int, int>> BruteForce(const cv::Mat& rows, const float* query, int k) {
  std::vector<std::pair<int, int>> all;
  for (int r = 0; r < rows.rows; ++r) {
    int distance = 0;
    for (int d = 0; d < rows.cols; ++d) {
      const int difference = Quantised(rows.at<float>(r, d)) - Quantised(query[d]);
      distance += difference * difference;
    }
    all.emplace_back(distance, r);
  }
  std::sort(all.begin(), all.end());
  all.resize(std::min(all.size(), static_cast<size_t>(k)));
  return all;
}

void ExpectBruteForce(const cv::Mat& rows, const cv::Mat& queries, int k, const std::string& what) {
  const ByteNeighbours index(rows);
  cv::Mat indices, squared;
  index.Search(queries, k, &indices, &squared);
  ASSERT_EQ(indices.rows, queries.rows);
  ASSERT_EQ(indices.cols, k);
  for (int q = 0; q < queries.rows; ++q) {
    const std::vector<std::pair<int, int>> expected = BruteForce(rows, queries.ptr<float>(q), k);
    for (int i = 0; i < k; ++i) {
      if (i >= static_cast<int>(expected.size())) {
        EXPECT_EQ(indices.at<int>(q, i), -1) << what;
        EXPECT_EQ(squared.at<float>(q, i), std::numeric_limits<float>::infinity()) << what;
        continue;
      }
      ASSERT_EQ(indices.at<int>(q, i), expected[static_cast<size_t>(i)].second)
          << what << ", query " << q << ", neighbour " << i;
      EXPECT_FLOAT_EQ(squared.at<float>(q, i),
                      static_cast<float>(expected[static_cast<size_t>(i)].first) / (127.0F * 127.0F))
          << what;
    }
  }
}

class ByteNeighboursTest : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override { ByteNeighbours::AllowVnni(GetParam()); }
  void TearDown() override { ByteNeighbours::AllowVnni(true); }
  std::string Kernel() const { return GetParam() ? "VNNI where available" : "plain loop"; }
};

TEST_P(ByteNeighboursTest, FindsWhatABruteForceOverTheSameBytesFinds) {
  // 96 values as the context descriptors; 37 and 5 values leave partial 4-byte groups; 1000 and 33 rows leave a
  // partial block of 16, 7 queries a partial block of queries.
  for (const auto& [rows, dims, queries] :
       std::vector<std::tuple<int, int, int>>{{1000, 96, 50}, {33, 37, 7}, {20, 5, 16}, {1, 96, 3}}) {
    const cv::Mat train = Rows(rows, dims, 1), query = Rows(queries, dims, 2);
    for (const int k : {1, 2, 5}) {
      ExpectBruteForce(
          train, query, k,
          Kernel() + ", " + std::to_string(rows) + " rows of " + std::to_string(dims) + ", k " + std::to_string(k));
    }
  }
}

TEST_P(ByteNeighboursTest, TiesGoToTheLowerRow) {
  cv::Mat rows = Rows(40, 96, 3);
  rows.row(7).copyTo(rows.row(30));  // the same values twice
  rows.row(7).copyTo(rows.row(12));
  cv::Mat indices, squared;
  ByteNeighbours(rows).Search(rows.row(30).clone(), 3, &indices, &squared);
  EXPECT_EQ(indices.at<int>(0, 0), 7) << Kernel();
  EXPECT_EQ(indices.at<int>(0, 1), 12) << Kernel();
  EXPECT_EQ(indices.at<int>(0, 2), 30) << Kernel();
  EXPECT_EQ(squared.at<float>(0, 0), 0.0F);
  // The nearest alone (the VNNI kernel's case, in lane order and across sweeps of 16 queries).
  cv::Mat queries;
  for (int i = 0; i < 20; ++i) queries.push_back(rows.row(30));
  ByteNeighbours(rows).Search(queries, 1, &indices, &squared);
  for (int q = 0; q < queries.rows; ++q) EXPECT_EQ(indices.at<int>(q, 0), 7) << Kernel() << ", query " << q;
}

INSTANTIATE_TEST_SUITE_P(Kernels, ByteNeighboursTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& kernel) { return kernel.param ? "Vnni" : "Plain"; });

TEST(ByteNeighbours, KernelsAgreeToTheBit) {
  const cv::Mat rows = Rows(3000, 96, 4), queries = Rows(300, 96, 5);
  cv::Mat fast_indices, fast_squared, plain_indices, plain_squared;
  const ByteNeighbours index(rows);
  index.Search(queries, 1, &fast_indices, &fast_squared);
  ByteNeighbours::AllowVnni(false);
  index.Search(queries, 1, &plain_indices, &plain_squared);
  ByteNeighbours::AllowVnni(true);
  EXPECT_EQ(cv::countNonZero(fast_indices != plain_indices), 0);
  EXPECT_EQ(cv::countNonZero(fast_squared != plain_squared), 0);
}

TEST(ByteNeighbours, NoRowsAndBadQueriesAreHandled) {
  cv::Mat indices, squared;
  ByteNeighbours(cv::Mat(0, 96, CV_32F)).Search(Rows(2, 96, 6), 1, &indices, &squared);
  EXPECT_EQ(indices.at<int>(0, 0), -1);
  EXPECT_EQ(squared.at<float>(1, 0), std::numeric_limits<float>::infinity());
  const ByteNeighbours index(Rows(10, 96, 7));
  EXPECT_THROW(index.Search(Rows(2, 95, 8), 1, &indices, &squared), InputError);
  EXPECT_THROW(index.Search(Rows(2, 96, 8), 0, &indices, &squared), InputError);
  EXPECT_THROW(ByteNeighbours(cv::Mat(3, 96, CV_64F, cv::Scalar(0.5))), InputError);
}

}  // namespace
}  // namespace ecv
