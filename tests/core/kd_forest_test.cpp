// KdForest against brute force: exact when asked to compare every row, never worse for more checks, near the
// exact neighbour on clustered data, repeatable, safe to search from several threads.

#include <algorithm>
#include <limits>
#include <random>
#include <thread>
#include <tuple>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/kd_forest.h"

namespace ecv {
namespace {

// `count` rows of `dims` values: noisy copies of `centres` random centres (so that near neighbours are
// meaningful, as for descriptors), each value in [0, 1].
cv::Mat ClusteredRows(int count, int dims, int centres, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(0.0F, 1.0F);
  std::normal_distribution<float> noise(0.0F, 0.05F);
  cv::Mat centre_rows(centres, dims, CV_32F), rows(count, dims, CV_32F);
  for (int c = 0; c < centres; ++c) {
    for (int d = 0; d < dims; ++d) centre_rows.at<float>(c, d) = uniform(random);
  }
  for (int r = 0; r < count; ++r) {
    const int c = static_cast<int>(random() % static_cast<unsigned>(centres));
    for (int d = 0; d < dims; ++d) rows.at<float>(r, d) = centre_rows.at<float>(c, d) + noise(random);
  }
  return rows;
}

// Each row of `rows` moved by a little noise.
cv::Mat Jittered(const cv::Mat& rows, float sigma, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.0F, sigma);
  cv::Mat moved = rows.clone();
  for (int r = 0; r < moved.rows; ++r) {
    for (int d = 0; d < moved.cols; ++d) moved.at<float>(r, d) += noise(random);
  }
  return moved;
}

// The k nearest rows by brute force, ties to the lower row: (squared distance, row), nearest first.
std::vector<std::pair<float, int>> BruteNearest(const cv::Mat& rows, const float* query, int k) {
  std::vector<std::pair<float, int>> all;
  for (int r = 0; r < rows.rows; ++r) {
    float squared = 0.0F;
    for (int d = 0; d < rows.cols; ++d)
      squared += (rows.at<float>(r, d) - query[d]) * (rows.at<float>(r, d) - query[d]);
    all.emplace_back(squared, r);
  }
  std::sort(all.begin(), all.end());
  all.resize(std::min(all.size(), static_cast<size_t>(k)));
  return all;
}

TEST(KdForest, ComparingEveryRowIsTheExactSearch) {
  cv::Mat rows = ClusteredRows(600, 24, 30, 1);
  rows.row(17).copyTo(rows.row(400));  // a duplicate: the tie goes to the lower row
  const KdForest forest(rows);
  const cv::Mat queries = Jittered(rows.rowRange(0, 200), 0.02F, 2);
  cv::Mat indices, squared;
  forest.Search(queries, 3, forest.size(), &indices, &squared);
  ASSERT_EQ(indices.size(), cv::Size(3, 200));
  for (int q = 0; q < queries.rows; ++q) {
    const std::vector<std::pair<float, int>> expected = BruteNearest(rows, queries.ptr<float>(q), 3);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(indices.at<int>(q, i), expected[static_cast<size_t>(i)].second) << "query " << q << ", rank " << i;
      EXPECT_NEAR(squared.at<float>(q, i), expected[static_cast<size_t>(i)].first, 1e-5F);
    }
  }
  forest.Search(rows.row(400), 1, forest.size(), &indices, &squared);
  EXPECT_EQ(indices.at<int>(0), 17);
  EXPECT_EQ(squared.at<float>(0), 0.0F);
}

// The search with more checks takes the same steps and then goes on, so no query gets a farther neighbour.
TEST(KdForest, MoreChecksNeverFindAFartherNeighbourAndFindTheExactOneMoreOften) {
  const cv::Mat rows = ClusteredRows(5000, 96, 200, 3);
  const cv::Mat queries = ClusteredRows(1000, 96, 1000, 4);  // elsewhere: no row stands out as the nearest
  const KdForest forest(rows);
  cv::Mat exact_indices, exact_squared;
  forest.Search(queries, 1, forest.size(), &exact_indices, &exact_squared);
  std::vector<int> exact_found;
  cv::Mat previous;
  for (const int checks : {8, 32, 128, 512}) {
    cv::Mat indices, squared;
    forest.Search(queries, 1, checks, &indices, &squared);
    int exact = 0;
    for (int q = 0; q < queries.rows; ++q) {
      EXPECT_GE(squared.at<float>(q), exact_squared.at<float>(q)) << "checks " << checks << ", query " << q;
      if (!previous.empty()) {
        EXPECT_LE(squared.at<float>(q), previous.at<float>(q)) << "checks " << checks << ", query " << q;
      }
      exact += indices.at<int>(q) == exact_indices.at<int>(q) ? 1 : 0;
    }
    exact_found.push_back(exact);
    previous = squared;
  }
  // Found 22, 34, 129 and 380 times of 1000. Comparing `checks` random rows of the 5000 would find it
  // checks / 5000 of the time: 26 and 102 times for the last two.
  for (size_t i = 1; i < exact_found.size(); ++i) EXPECT_GT(exact_found[i], exact_found[i - 1]) << "level " << i;
  EXPECT_GT(exact_found[2], 100) << "128 checks";
  EXPECT_GT(exact_found[3], 300) << "512 checks";
}

TEST(KdForest, SameRowsAndSeedGiveTheSameNeighboursOnAnyThread) {
  const cv::Mat rows = ClusteredRows(3000, 32, 100, 5);
  const cv::Mat queries = Jittered(rows.rowRange(0, 500), 0.05F, 6);
  KdForestOptions options;
  options.trees = 2;
  const KdForest forest(rows, options), again(rows, options);
  cv::Mat indices, squared, again_indices, again_squared;
  forest.Search(queries, 2, 32, &indices, &squared);
  again.Search(queries, 2, 32, &again_indices, &again_squared);
  EXPECT_EQ(cv::countNonZero(indices != again_indices), 0);
  std::vector<cv::Mat> threaded(4), threaded_squared(4);
  std::vector<std::thread> threads;
  for (size_t t = 0; t < threaded.size(); ++t) {
    threads.emplace_back([&, t] { forest.Search(queries, 2, 32, &threaded[t], &threaded_squared[t]); });
  }
  for (std::thread& thread : threads) thread.join();
  for (const cv::Mat& result : threaded) EXPECT_EQ(cv::countNonZero(result != indices), 0);
  options.seed = 2;  // other trees: the approximate search finds other neighbours for some queries
  const KdForest other(rows, options);
  other.Search(queries, 2, 32, &again_indices, &again_squared);
  EXPECT_GT(cv::countNonZero(indices != again_indices), 0);
}

TEST(KdForest, FewRowsAndIdenticalRows) {
  const cv::Mat same(50, 8, CV_32F, cv::Scalar(0.5F));  // no split separates them: the trees must still end
  const KdForest forest(same);
  cv::Mat indices, squared;
  forest.Search(same.rowRange(0, 1), 3, 4, &indices, &squared);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(indices.at<int>(i), 0);
    EXPECT_EQ(squared.at<float>(i), 0.0F);
  }
  const KdForest two(ClusteredRows(2, 8, 2, 7));
  two.Search(same.rowRange(0, 1), 4, 100, &indices, &squared);
  EXPECT_EQ(std::make_tuple(indices.at<int>(2), indices.at<int>(3)), std::make_tuple(-1, -1));
  EXPECT_EQ(squared.at<float>(3), std::numeric_limits<float>::infinity());
  const KdForest empty(cv::Mat(0, 8, CV_32F));
  empty.Search(same.rowRange(0, 2), 1, 10, &indices, &squared);
  EXPECT_EQ(std::make_tuple(indices.at<int>(0), indices.at<int>(1)), std::make_tuple(-1, -1));
}

TEST(KdForest, BadInputIsRefused) {
  const cv::Mat rows = ClusteredRows(20, 8, 2, 8);
  KdForestOptions options;
  options.leaf_size = 0;
  EXPECT_THROW(KdForest(rows, options), InputError);
  EXPECT_THROW(KdForest(cv::Mat(10, 8, CV_64F, cv::Scalar(0.0))), InputError);
  const KdForest forest(rows);
  cv::Mat indices, squared;
  EXPECT_THROW(forest.Search(cv::Mat(1, 7, CV_32F, cv::Scalar(0.0F)), 1, 8, &indices, &squared), InputError);
  EXPECT_THROW(forest.Search(rows, 0, 8, &indices, &squared), InputError);
}

}  // namespace
}  // namespace ecv
