// The paper's prerejective RANSAC and standard RANSAC on constructed correspondences with a known pose.

#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/parallel.h"
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

// Local sampling (sample_radius_m): the object is small in a large cluttered scene, 5 % of the correspondences
// are true and the false ones lead into the clutter, at least 0.5 m away. Drawing a sample's later members
// within the object's size of its first makes a true first member enough; uniform sampling needs all three.
TEST(Ransac, LocalSamplingFindsASmallObjectInClutterWithFewIterations) {
  Problem problem = MakeProblem(300, 0, 0, 0.0005, 4);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> coordinate(-1.0F, 1.0F);
  const Eigen::Vector3f centre = problem.scene_from_object.cast<float>() * Eigen::Vector3f::Constant(0.075F);
  while (problem.scene.size() < 3300) {  // clutter, none within 0.5 m of the object
    const Eigen::Vector3f point = centre + Eigen::Vector3f(coordinate(random), coordinate(random), coordinate(random));
    if ((point - centre).norm() > 0.5F) problem.scene.push_back(point);
  }
  std::uniform_int_distribution<int> object(0, 299), clutter(300, 3299);
  for (int i = 0; i < 600; ++i) {
    const int o = object(random);
    problem.correspondences.push_back({o, i < 30 ? o : clutter(random)});
  }
  std::shuffle(problem.correspondences.begin(), problem.correspondences.end(), random);

  RansacOptions options;
  options.max_iterations = 400;
  options.inlier_threshold_m = 0.003;
  RansacOptions local = options;
  local.sample_radius_m = 0.3;  // about twice the object's size
  const RansacResult found = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, local);
  ASSERT_TRUE(found.success);
  EXPECT_LT(TranslationDistance(found.scene_from_object, problem.scene_from_object), 0.001);
  EXPECT_LT(RotationAngle(found.scene_from_object, problem.scene_from_object), 0.5 * kDegree);

  const RansacResult uniform = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  EXPECT_FALSE(uniform.success && TranslationDistance(uniform.scene_from_object, problem.scene_from_object) < 0.001)
      << "uniform sampling: an all-true sample has probability 0.05^3 per iteration";

  local.sample_radius_m = -0.1;
  EXPECT_THROW(EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, local), InputError);
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
  options.seed = 2;  // each thread keeps the seeded generators of its last seed: they must follow the seed
  const RansacResult other = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  options.seed = 1;
  const RansacResult second = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  ASSERT_TRUE(first.success);
  EXPECT_EQ(first.scene_from_object.matrix(), second.scene_from_object.matrix());
  EXPECT_EQ(first.rejected_by_polygon, second.rejected_by_polygon);
  EXPECT_EQ(first.fit_error_m, second.fit_error_m);
  EXPECT_NE(first.rejected_by_polygon, other.rejected_by_polygon);
}

// The support test (min_support, min_support_share) drops the poses of wrong samples before their inliers are
// counted and leaves the result as it was: the right pose has a hundred agreeing correspondences.
TEST(Ransac, TheSupportTestDropsWrongPosesBeforeTheirInlierCountAndKeepsTheResult) {
  const Problem problem = MakeProblem(500, 100, 1000, 0.0005, 5);
  RansacOptions options;
  options.expected_inlier_ratio = 0.1;
  options.inlier_threshold_m = 0.003;
  options.prefer_agreeing = true;
  options.polygon_threshold = 0.0;
  const RansacResult plain = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  ASSERT_TRUE(plain.success);
  EXPECT_EQ(plain.rejected_by_support, 0);

  options.min_support = 3;  // 3 correspondences besides the sample's own
  const RansacResult tested = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  ASSERT_TRUE(tested.success);
  EXPECT_EQ(tested.scene_from_object.matrix(), plain.scene_from_object.matrix());
  EXPECT_EQ(tested.inlier_fraction, plain.inlier_fraction);
  EXPECT_EQ(tested.iterations, plain.iterations);
  // A sample is all true with probability 0.1^3, so nearly every pose is wrong and dropped.
  EXPECT_GT(tested.rejected_by_support, tested.iterations * 95 / 100);

  // The same bar as a share: ceil(0.0021 x 1000) = 3; the larger of the two counts.
  options.min_support = 1;
  options.min_support_share = 0.0021;
  const RansacResult shared = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  EXPECT_EQ(shared.rejected_by_support, tested.rejected_by_support);
  EXPECT_EQ(shared.scene_from_object.matrix(), plain.scene_from_object.matrix());

  // More than there are: every pose is dropped. The polygon test takes the degenerate samples (a correspondence
  // drawn twice, two with one object point), so every other sample reaches the support test.
  options.min_support = 998;
  options.polygon_threshold = 0.25;
  const RansacResult none = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  EXPECT_FALSE(none.success);
  EXPECT_GT(none.rejected_by_support, 0);
  EXPECT_EQ(none.rejected_by_support + none.rejected_by_polygon, none.iterations);

  options.min_support = -1;
  EXPECT_THROW(options.Check(), InputError);
  options.min_support = 0;
  options.min_support_share = 1.5;
  EXPECT_THROW(options.Check(), InputError);
}
// A grid built once for many runs (the recognizer's, one per frame) gives what each run's own grid gives; a grid
// over other points, or of another radius, is refused by name.
TEST(Ransac, ASharedSceneGridGivesTheSameResultAndAWrongOneIsRefused) {
  const Problem problem = MakeProblem(300, 60, 400, 0.001, 4);
  RansacOptions options;
  options.max_iterations = 3000;
  options.expected_inlier_ratio = 0.15;
  const RadiusGrid grid(problem.scene, static_cast<float>(options.inlier_threshold_m));
  const RansacResult own = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  const RansacResult shared = EstimatePoseRansac(problem.object, problem.scene, grid, problem.correspondences, options);
  ASSERT_TRUE(own.success);
  EXPECT_EQ(own.scene_from_object.matrix(), shared.scene_from_object.matrix());
  EXPECT_EQ(own.fit_error_m, shared.fit_error_m);
  EXPECT_EQ(own.inlier_fraction, shared.inlier_fraction);

  const RadiusGrid wider(problem.scene, 2.0F * static_cast<float>(options.inlier_threshold_m));
  const std::vector<Eigen::Vector3f> fewer(problem.scene.begin(), problem.scene.end() - 1);
  const RadiusGrid other(fewer, static_cast<float>(options.inlier_threshold_m));
  for (const RadiusGrid* wrong : {&wider, &other}) {
    try {
      EstimatePoseRansac(problem.object, problem.scene, *wrong, problem.correspondences, options);
      ADD_FAILURE() << "a grid that does not fit was accepted";
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("scene_grid"), std::string::npos) << error.what();
    }
  }
}

TEST(Ransac, ThreadCountsBeyondTheBoundAreRefusedByName) {
  RansacOptions options;
  options.threads = kMaxThreads;
  EXPECT_NO_THROW(options.Check());
  options.threads = 1000000;
  try {
    options.Check();
    ADD_FAILURE() << "a million threads were accepted";
  } catch (const InputError& error) {
    EXPECT_STREQ(error.what(), "RANSAC options: threads: expected 1 to 256, got 1000000");
  }
}

TEST(Ransac, TwoThreadsGiveTheSameResultAsOne) {
  const Problem problem = MakeProblem(300, 40, 400, 0.001, 6);
  for (const auto& [early_stop, adaptive] : {std::pair{0.0, false}, {0.002, false}, {0.0, true}}) {
    RansacOptions options;
    options.max_iterations = 5000;
    options.early_stop_fit_error_m = early_stop;
    options.adaptive = adaptive;
    options.seed = 11;
    const RansacResult one = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
    options.threads = 2;
    const RansacResult two = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
    ASSERT_TRUE(one.success) << "early stop " << early_stop;
    EXPECT_EQ(one.scene_from_object.matrix(), two.scene_from_object.matrix()) << "early stop " << early_stop;
    EXPECT_EQ(one.iterations, two.iterations);
    EXPECT_EQ(one.rejected_by_polygon, two.rejected_by_polygon);
    EXPECT_EQ(one.fit_error_m, two.fit_error_m);
    if (early_stop > 0 || adaptive) {
      EXPECT_LT(one.iterations, 5000) << "the early stop must have cut the run short";
    }
    if (adaptive) {  // 40 of 400 correspondences are true: w = 0.1 gives k = log(0.01) / log(1 - 0.001)
      EXPECT_NEAR(one.correspondence_inlier_ratio, 0.1, 0.02);
      EXPECT_GE(one.iterations, 4000);
    }
    options.seed = 12;  // another seed draws other samples
    const RansacResult other = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
    EXPECT_NE(one.rejected_by_polygon, other.rejected_by_polygon);
  }
}

// A flat 20 x 20 cm object 1 m in front of the camera and a wall behind it; the scene sees the object's
// left 40 % and, in front of the rest, an occluder 20 cm closer.
struct OccludedProblem {
  std::vector<Eigen::Vector3f> object, scene;
  std::vector<Correspondence> correspondences;
  Eigen::Isometry3d scene_from_object = Eigen::Isometry3d::Identity();
  SceneVisibility visibility;
};

OccludedProblem MakeOccludedProblem() {
  OccludedProblem problem;
  problem.visibility.camera = {500.0, 500.0, 159.5, 119.5, 320, 240};
  problem.visibility.depth = cv::Mat(240, 320, CV_32FC1, cv::Scalar(1.0F));
  problem.scene_from_object.translation() = Eigen::Vector3d(-0.1, -0.1, 1.0);
  const double occluder_x = -0.1 + 0.4 * 0.2;  // camera-frame x beyond which the object is hidden
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 320; ++u) {
      const Eigen::Vector3d ray = problem.visibility.camera.BackProject({u, v}, 1.0);
      const bool on_object = ray.x() >= -0.1 && ray.y() >= -0.1 && ray.y() <= 0.1;
      problem.visibility.depth.at<float>(v, u) = ray.x() > occluder_x ? 0.8F : on_object ? 1.0F : 1.5F;
      const float z = problem.visibility.depth.at<float>(v, u);
      if (u % 2 == 0 && v % 2 == 0 && z != 1.0F) problem.scene.push_back((ray * z).cast<float>());
    }
  }
  for (int i = 0; i <= 20; ++i) {
    for (int j = 0; j <= 20; ++j) problem.object.emplace_back(0.01F * i, 0.01F * j, 0.0F);
  }
  for (int i = 0; i < static_cast<int>(problem.object.size()); ++i) {  // the visible part is seen and matched
    const Eigen::Vector3f in_scene = problem.scene_from_object.cast<float>() * problem.object[i];
    if (in_scene.x() > occluder_x) continue;
    problem.correspondences.push_back({i, static_cast<int>(problem.scene.size())});
    problem.scene.push_back(in_scene);
  }
  return problem;
}

// The settings the occluded problem is solved with: few samples, an inlier within 5 mm.
RansacOptions OccludedOptions() {
  RansacOptions options;
  options.max_iterations = 500;
  options.inlier_threshold_m = 0.005;
  return options;
}

// `found` is the occluded problem's pose, judged by the 43 % of the object that is visible.
void ExpectVisiblePartFound(const RansacResult& found, const OccludedProblem& problem) {
  ASSERT_TRUE(found.success);
  EXPECT_LT(TranslationDistance(found.scene_from_object, problem.scene_from_object), 0.002);
  EXPECT_LT(RotationAngle(found.scene_from_object, problem.scene_from_object), 1.0 * kDegree);
  EXPECT_NEAR(found.visible_fraction, 0.43, 0.05);
  EXPECT_GT(found.inlier_fraction, 0.9);
}

TEST(Ransac, APartlyHiddenObjectIsJudgedByItsVisiblePoints) {
  const OccludedProblem problem = MakeOccludedProblem();
  ASSERT_GT(problem.correspondences.size(), 100U);
  const RansacOptions options = OccludedOptions();
  const RansacResult blind = EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options);
  EXPECT_FALSE(blind.success) << "only about 40 % of the object points can be inliers";
  ExpectVisiblePartFound(
      EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options, &problem.visibility),
      problem);

  SceneVisibility wrong_size = problem.visibility;
  wrong_size.depth = cv::Mat(10, 10, CV_32FC1, cv::Scalar(1.0F));
  EXPECT_THROW(EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options, &wrong_size),
               InputError);
}

TEST(Ransac, InliersLookedForInTheDepthImageFindTheSamePose) {
  const OccludedProblem problem = MakeOccludedProblem();
  RansacOptions options = OccludedOptions();
  options.projective_stride_px = 2;
  const RansacResult found =
      EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options, &problem.visibility);
  ExpectVisiblePartFound(found, problem);
  EXPECT_LT(found.fit_error_m, 0.002);  // the depth samples lie on the object's plane, 5 mm apart at most
}

TEST(Ransac, InliersLookedForInTheDepthImageComeFromItAlone) {
  // The sensor saw the object's surface 2 cm behind where the matched scene points put it: the nearest scene
  // point in 3D still confirms the pose, the depth samples along the rays do not.
  OccludedProblem problem = MakeOccludedProblem();
  cv::Mat& depth = problem.visibility.depth;
  depth.setTo(1.02F, depth == 1.0F);
  RansacOptions options = OccludedOptions();
  EXPECT_TRUE(
      EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options, &problem.visibility).success);
  options.projective_stride_px = 2;
  EXPECT_FALSE(
      EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options, &problem.visibility).success);

  EXPECT_THROW(EstimatePoseRansac(problem.object, problem.scene, problem.correspondences, options), InputError)
      << "no depth image to look in";
  const RadiusGrid grid(problem.scene, static_cast<float>(options.inlier_threshold_m));
  EXPECT_THROW(
      EstimatePoseRansac(problem.object, problem.scene, grid, problem.correspondences, options, &problem.visibility),
      InputError)
      << "a grid that would not be used";
  options.projective_stride_px = -1;
  EXPECT_THROW(options.Check(), InputError);
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
