// The paper's prerejective RANSAC and standard RANSAC on constructed correspondences with a known pose.

#include <random>

#include <gtest/gtest.h>

#include "core/pose.h"
#include "registration/ransac.h"

namespace ecv {
namespace {

constexpr double kDegree = M_PI / 180.0;

struct Problem {
  std::vector<Eigen::Vector3f> object, scene;
  std::vector<Correspondence> correspondences;
  Eigen::Isometry3d scene_from_object;
};

// `points` object points in a 15 cm box, seen in the scene under a known pose with `noise_m` Gaussian
// noise; `true_count` true correspondences among `total`, the rest random.
Problem MakeProblem(int points, int true_count, int total, double noise_m, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0F, 0.15F);
  std::normal_distribution<float> noise(0.0F, static_cast<float>(noise_m));
  Problem problem;
  problem.scene_from_object = Eigen::Isometry3d::Identity();
  problem.scene_from_object.linear() =
      Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  problem.scene_from_object.translation() = Eigen::Vector3d(0.1, -0.05, 0.9);
  const Eigen::Isometry3f transform = problem.scene_from_object.cast<float>();
  for (int i = 0; i < points; ++i) {
    problem.object.emplace_back(unit(random), unit(random), unit(random));
    problem.scene.push_back(transform * problem.object.back() +
                            Eigen::Vector3f(noise(random), noise(random), noise(random)));
  }
  std::uniform_int_distribution<int> any(0, points - 1);
  for (int i = 0; i < total; ++i) {
    const int object = any(random);
    problem.correspondences.push_back({object, i < true_count ? object : any(random)});
  }
  std::shuffle(problem.correspondences.begin(), problem.correspondences.end(), random);
  return problem;
}

TEST(Ransac, IterationCountFollowsThePaper) {
  EXPECT_NEAR(RansacOptions{}.Iterations(), 36839, 1);  // p = 0.99, w = 0.05, n = 3: about 37 000
  RansacOptions fixed;
  fixed.max_iterations = 5000;
  EXPECT_EQ(fixed.Iterations(), 5000);
}

TEST(Ransac, FindsThePoseAmongNinetyPercentOutliers) {
  const Problem problem = MakeProblem(500, 100, 1000, 0.0005, 1);
  for (const double polygon : {0.25, 0.0}) {  // prerejective, then standard
    RansacOptions options;
    options.polygon_threshold = polygon;
    options.expected_inlier_ratio = 0.1;
    options.inlier_threshold_m = 0.003;
    const RansacResult result = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
    ASSERT_TRUE(result.success) << "polygon " << polygon;
    EXPECT_LT(TranslationDistance(result.scene_from_object, problem.scene_from_object), 0.001);
    EXPECT_LT(RotationAngle(result.scene_from_object, problem.scene_from_object), 0.5 * kDegree);
    EXPECT_GT(result.inlier_fraction, 0.95);
    EXPECT_LT(result.fit_error_m, 0.0015);
    EXPECT_EQ(result.iterations, options.Iterations());
    if (polygon > 0) {
      EXPECT_GT(result.rejected_by_polygon, result.iterations / 2) << "most random samples fail the polygon test";
    } else {
      EXPECT_EQ(result.rejected_by_polygon, 0);
    }
  }
}

TEST(Ransac, PolygonTestKeepsTrueSamplesAndRejectsRandomOnes) {
  const Problem problem = MakeProblem(400, 0, 0, 0.002, 2);  // 2 mm noise
  const PolygonEdgeCheck check(0.25);
  std::mt19937 random(3);
  std::uniform_int_distribution<int> any(0, 399);
  int true_samples = 0, random_rejected = 0, random_samples = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int a = any(random), b = any(random), c = any(random);
    const std::vector<Eigen::Vector3f> object = {problem.object[a], problem.object[b], problem.object[c]};
    const float shortest =
        std::min({(object[0] - object[1]).norm(), (object[1] - object[2]).norm(), (object[2] - object[0]).norm()});
    if (shortest >= 0.03F) {  // true correspondences with edges of at least 3 cm: never rejected
      ++true_samples;
      ASSERT_TRUE(check(object, {problem.scene[a], problem.scene[b], problem.scene[c]})) << trial;
    }
    ++random_samples;
    random_rejected +=
        check(object, {problem.scene[any(random)], problem.scene[any(random)], problem.scene[any(random)]}) ? 0 : 1;
  }
  EXPECT_GT(true_samples, 5000);
  EXPECT_GT(random_rejected, 0.7 * random_samples);
}

TEST(Ransac, SameSeedSameResult) {
  const Problem problem = MakeProblem(300, 60, 400, 0.001, 4);
  RansacOptions options;
  options.max_iterations = 3000;
  options.expected_inlier_ratio = 0.15;
  const RansacResult first = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  const RansacResult second = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  ASSERT_TRUE(first.success);
  EXPECT_EQ(first.scene_from_object.matrix(), second.scene_from_object.matrix());
  EXPECT_EQ(first.rejected_by_polygon, second.rejected_by_polygon);
  EXPECT_EQ(first.fit_error_m, second.fit_error_m);
}

TEST(Ransac, DegenerateInputsFailWithoutACrash) {
  const Problem problem = MakeProblem(50, 50, 50, 0.0, 5);
  EXPECT_FALSE(EstimatePoseRansac({}, {}, {}).success);
  EXPECT_FALSE(EstimatePoseRansac(problem.object, problem.scene, {{0, 0}, {1, 1}}).success);  // fewer than 3
  const std::vector<Eigen::Vector3f> same(50, Eigen::Vector3f(0.1F, 0.2F, 0.3F));
  RansacOptions options;
  options.max_iterations = 200;
  const RansacResult identical = EstimatePoseRansac(same, same, problem.correspondences, options);
  EXPECT_FALSE(identical.success);
  EXPECT_EQ(identical.iterations, 200);
}

}  // namespace
}  // namespace ecv
