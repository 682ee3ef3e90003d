// Registration of real views with the ECV context and the prerejective RANSAC: PCL's milk scene and a
// YCB-Video frame pair made wide-baseline by a known rotation.

#include <random>

#include <gtest/gtest.h>

#include "core/point_index.h"
#include "core/pose.h"
#include "io/frame_io.h"
#include "io/points_io.h"
#include "registration/scene_registration.h"
#include "support/test_data.h"

namespace ecv {
namespace {

constexpr double kDegree = M_PI / 180.0;

Eigen::Isometry3d RandomPose(unsigned seed, double max_angle_rad, double max_shift_m) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d axis = Eigen::Vector3d(unit(random), unit(random), unit(random)).normalized();
  pose.linear() = Eigen::AngleAxisd(max_angle_rad * (0.5 + 0.5 * std::abs(unit(random))), axis).toRotationMatrix();
  pose.translation() = max_shift_m * Eigen::Vector3d(unit(random), unit(random), unit(random));
  return pose;
}

// The milk carton is an exact subset of the scene cloud: its pixels are those whose point is in milk.pcd.
TEST(SceneRegistration, FindsTheMovedMilkModelInItsScene) {
  const std::string scene_path = test::DataPath("pcl_milk_scene/test/milk_cartoon_all_small_clorox.pcd");
  const RgbdFrame scene = LoadPcdFrame(scene_path).rgbd;
  const std::vector<Eigen::Vector3f> milk = ReadPcdPoints(test::DataPath("pcl_milk_scene/test/milk.pcd"));
  ASSERT_EQ(milk.size(), 13704U);
  cv::Mat organized, color;
  ReadOrganizedPcd(scene_path, &organized, &color);
  const PointIndex milk_index(milk);
  cv::Mat mask(scene.depth.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < organized.rows; ++v) {
    for (int u = 0; u < organized.cols; ++u) {
      const cv::Vec3f& p = organized.at<cv::Vec3f>(v, u);
      if (std::isfinite(p[2]) && milk_index.Nearest({p[0], p[1], p[2]}).second < 1e-10F) mask.at<uchar>(v, u) = 255;
    }
  }
  ASSERT_EQ(cv::countNonZero(mask), 13704);

  RegistrationOptions options;
  options.ransac.required_inlier_fraction = 0.5;  // an object, not a scene
  RegistrationView model;
  model.primitives = ExtractPrimitives(scene, options.features, mask).primitives;
  model.dense_points = milk;
  const RegistrationView scene_view = PrepareRegistrationView(scene, options);
  ASSERT_GT(model.primitives.size(), 100U);

  for (const unsigned seed : {1U, 2U}) {
    const Eigen::Isometry3d moved_from_scene = RandomPose(seed, M_PI, 0.3);
    RegistrationView moved = model;
    TransformView(moved_from_scene, &moved);
    const RegistrationResult result = RegisterViews(moved, scene_view, options);
    ASSERT_TRUE(result.success) << "seed " << seed;
    const Eigen::Isometry3d truth = moved_from_scene.inverse();
    EXPECT_LT(TranslationDistance(result.b_from_a, truth), 0.005) << "seed " << seed;
    EXPECT_LT(RotationAngle(result.b_from_a, truth), 2.0 * kDegree) << "seed " << seed;
  }
}

// YCB-Video 0001 frames 1 and 19 are only about 2 cm and 1.3 degrees apart; frame 19 is turned by a known
// 30 degrees about its scene centre so that the pair needs a global method.
TEST(SceneRegistration, RegistersYcbVideoFramesThirtyDegreesApart) {
  const LoadedFrame first = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  const LoadedFrame last = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000019"));
  ASSERT_FALSE(first.ground_truth.empty());
  // The camera motion from the ground truth of one object (the others agree within a millimetre).
  const GroundTruth& object_in_first = first.ground_truth.front();
  Eigen::Isometry3d last_from_first = Eigen::Isometry3d::Identity();
  for (const GroundTruth& truth : last.ground_truth) {
    if (truth.object_id == object_in_first.object_id) {
      last_from_first = truth.camera_from_object * object_in_first.camera_from_object.inverse();
    }
  }
  ASSERT_GT(last_from_first.translation().norm(), 0.005) << "the two frames must differ";

  const RegistrationOptions options;
  const RegistrationView a = PrepareRegistrationView(first.rgbd, options);
  RegistrationView b = PrepareRegistrationView(last.rgbd, options);
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& point : b.dense_points) centre += point;
  centre /= static_cast<float>(b.dense_points.size());
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.rotate(Eigen::AngleAxisd(30.0 * kDegree, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()));
  turn = Eigen::Translation3d(centre.cast<double>()) * turn * Eigen::Translation3d(-centre.cast<double>());
  TransformView(turn, &b);
  const Eigen::Isometry3d truth = turn * last_from_first;

  const RegistrationResult result = RegisterViews(a, b, options);
  ASSERT_TRUE(result.success);
  EXPECT_LT(TranslationDistance(result.b_from_a, truth), 0.005);
  EXPECT_LT(RotationAngle(result.b_from_a, truth), 1.0 * kDegree);
  EXPECT_GT(RotationAngle(Eigen::Isometry3d::Identity(), truth), 29.0 * kDegree);
}

}  // namespace
}  // namespace ecv
