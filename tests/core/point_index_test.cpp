// The nearest-neighbour indices against brute force.

#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/point_index.h"

namespace ecv {
namespace {

std::vector<Eigen::Vector3f> RandomPoints(int count, float extent, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> coordinate(-extent, extent);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < count; ++i) points.emplace_back(coordinate(random), coordinate(random), coordinate(random));
  return points;
}

std::pair<int, float> BruteNearest(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& query) {
  std::pair<int, float> best{-1, std::numeric_limits<float>::infinity()};
  for (size_t i = 0; i < points.size(); ++i) {
    const float squared = (points[i] - query).squaredNorm();
    if (squared < best.second) best = {static_cast<int>(i), squared};
  }
  return best;
}

TEST(PointIndex, NearestAgreesWithBruteForce) {
  const std::vector<Eigen::Vector3f> points = RandomPoints(3000, 0.5F, 1);
  const PointIndex index(points);
  for (const Eigen::Vector3f& query : RandomPoints(500, 0.6F, 2)) {
    const auto [found, squared] = index.Nearest(query);
    const auto [expected, expected_squared] = BruteNearest(points, query);
    EXPECT_EQ(found, expected);
    EXPECT_FLOAT_EQ(squared, expected_squared);
  }
  EXPECT_EQ(PointIndex({}).Nearest(Eigen::Vector3f::Zero()).first, -1);
}

TEST(RadiusGrid, NearestWithinAgreesWithBruteForce) {
  const std::vector<Eigen::Vector3f> points = RandomPoints(20000, 0.1F, 3);
  for (const float radius : {0.005F, 0.01F, 0.05F}) {
    const RadiusGrid grid(points, radius);
    int found_count = 0;
    for (const Eigen::Vector3f& query : RandomPoints(2000, 0.12F, 4)) {
      const auto [expected, expected_squared] = BruteNearest(points, query);
      const auto [found, squared] = grid.NearestWithin(query);
      if (expected_squared <= radius * radius) {
        ++found_count;
        EXPECT_EQ(found, expected) << "radius " << radius;
        EXPECT_FLOAT_EQ(squared, expected_squared);
      } else {
        EXPECT_EQ(found, -1) << "radius " << radius;
      }
    }
    EXPECT_GT(found_count, 100) << "radius " << radius << ": the test must see hits";
  }
  // Far outside the grid, empty sets and a huge spread (a coarser grid) stay correct.
  const RadiusGrid grid(points, 0.01F);
  EXPECT_EQ(grid.NearestWithin({1e9F, -1e9F, 1e9F}).first, -1);
  EXPECT_EQ(RadiusGrid({}, 0.01F).NearestWithin(Eigen::Vector3f::Zero()).first, -1);
  std::vector<Eigen::Vector3f> spread = RandomPoints(1000, 0.5F, 5);
  spread.emplace_back(500.0F, 500.0F, 500.0F);
  const RadiusGrid coarse(spread, 0.01F);
  for (size_t i = 0; i < spread.size(); i += 37) EXPECT_EQ(coarse.NearestWithin(spread[i]).first, static_cast<int>(i));
}

// Depth-like data: a tilted, gently curved sheet sampled every 4 mm, queried just off it (within and beyond the
// radius), where a query's nearest point often lies in a neighbouring cell of the grid.
TEST(RadiusGrid, NearestWithinOnASurfaceAgreesWithBruteForce) {
  std::vector<Eigen::Vector3f> sheet;
  for (int row = 0; row < 60; ++row) {
    for (int column = 0; column < 60; ++column) {
      const float x = -0.12F + 0.004F * static_cast<float>(column);
      const float y = -0.12F + 0.004F * static_cast<float>(row);
      sheet.emplace_back(x, y, 0.8F + 0.3F * x + 0.5F * x * y);
    }
  }
  std::mt19937 random(7);
  std::uniform_real_distribution<float> along(-0.13F, 0.13F), off(-0.015F, 0.015F);
  const RadiusGrid grid(sheet, 0.01F);
  int hits = 0, misses = 0;
  for (int i = 0; i < 5000; ++i) {
    const float x = along(random), y = along(random);
    const Eigen::Vector3f query(x, y, 0.8F + 0.3F * x + 0.5F * x * y + off(random));
    const auto [expected, expected_squared] = BruteNearest(sheet, query);
    const auto [found, squared] = grid.NearestWithin(query);
    if (expected_squared <= 0.01F * 0.01F) {
      ++hits;
      EXPECT_EQ(found, expected) << "query " << query.transpose();
      EXPECT_FLOAT_EQ(squared, expected_squared);
    } else {
      ++misses;
      EXPECT_EQ(found, -1) << "query " << query.transpose();
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_GT(misses, 100);
}

}  // namespace
}  // namespace ecv
