// BOP's pose errors and average recall against cases worked out by hand.

#include <cmath>
#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "recognize/bop_metrics.h"

namespace ecv {
namespace {

using ::testing::HasSubstr;

constexpr double kPi = 3.14159265358979323846;

// A box of 8 corners, 0.1 x 0.06 x 0.04 m about its centre.
std::vector<Eigen::Vector3f> BoxCorners() {
  std::vector<Eigen::Vector3f> corners;
  for (const float x : {-0.05F, 0.05F}) {
    for (const float y : {-0.03F, 0.03F}) {
      for (const float z : {-0.02F, 0.02F}) corners.emplace_back(x, y, z);
    }
  }
  return corners;
}

// 72 points on the rim of a can of radius 0.03 m about the axis z through (0.01, 0, 0), at z = +-0.05 m.
std::vector<Eigen::Vector3f> CanRim() {
  std::vector<Eigen::Vector3f> rim;
  for (int k = 0; k < 36; ++k) {
    const double angle = 2.0 * kPi * k / 36;
    for (const float z : {-0.05F, 0.05F}) {
      rim.emplace_back(static_cast<float>(0.01 + 0.03 * std::cos(angle)), static_cast<float>(0.03 * std::sin(angle)),
                       z);
    }
  }
  return rim;
}

Eigen::Isometry3d InFront() {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(0.05, -0.02, 0.8);
  return pose;
}

PinholeCamera SmallCamera() {
  PinholeCamera camera;
  camera.fx = camera.fy = 100.0;
  camera.cx = 31.5, camera.cy = 23.5;
  camera.width = 64, camera.height = 48;
  return camera;
}

TEST(BopMetrics, AnExactPoseHasNoError) {
  const std::vector<Eigen::Isometry3d> none = {Eigen::Isometry3d::Identity()};
  EXPECT_DOUBLE_EQ(Mssd(BoxCorners(), InFront(), InFront(), none), 0.0);
  EXPECT_DOUBLE_EQ(Mspd(BoxCorners(), InFront(), InFront(), none, SmallCamera()), 0.0);
  const cv::Mat depth(48, 64, CV_32F, cv::Scalar(0.8F));
  for (const double error : Vsd(depth, depth, depth, SmallCamera(), 0.015, {0.005, 0.05})) EXPECT_EQ(error, 0.0);
}

TEST(BopMetrics, AShiftedPoseHasTheShiftAsMssdAndItsLargestPixelShiftAsMspd) {
  const std::vector<Eigen::Isometry3d> none = {Eigen::Isometry3d::Identity()};
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  Eigen::Isometry3d shifted = truth;
  shifted.translation().x() += 0.012;
  EXPECT_NEAR(Mssd(BoxCorners(), shifted, truth, none), 0.012, 1e-9);
  // Along x at depth z a point moves fx * 0.012 / z pixels: most for the nearest corners, z = 0.48 m.
  EXPECT_NEAR(Mspd(BoxCorners(), shifted, truth, none, SmallCamera()), 100.0 * 0.012 / 0.48, 1e-6);
}

TEST(BopMetrics, AnObjectTurnedByOneOfItsSymmetriesHasNoMssdOrMspd) {
  // The box turned half a turn about its z axis looks the same: BOP lists it as a discrete symmetry (translations
  // in millimetres).
  const nlohmann::json box_info = {{"diameter", 124.0},
                                   {"symmetries_discrete", {{-1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}};
  const std::vector<Eigen::Isometry3d> box = BopSymmetries(box_info, 0.001, "models_info.json");
  ASSERT_EQ(box.size(), 2U);
  const Eigen::Isometry3d turned = InFront() * Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitZ());
  EXPECT_NEAR(Mssd(BoxCorners(), turned, InFront(), box), 0.0, 1e-9);
  EXPECT_NEAR(Mspd(BoxCorners(), turned, InFront(), box, SmallCamera()), 0.0, 1e-6);
  EXPECT_GT(Mssd(BoxCorners(), turned, InFront(), {Eigen::Isometry3d::Identity()}), 0.1) << "without the symmetry";

  // A can about its axis through (10, 0, 0) mm: any turn is within half a step (0.01 rad / 2 at 30 mm) of a symmetry.
  const nlohmann::json can_info = {{"symmetries_continuous", {{{"axis", {0, 0, 1}}, {"offset", {10, 0, 0}}}}}};
  const std::vector<Eigen::Isometry3d> can = BopSymmetries(can_info, 0.001, "models_info.json");
  EXPECT_EQ(can.size(), 315U) << "ceil(pi / 0.01) steps a turn, the identity among them";
  Eigen::Isometry3d about_axis = Eigen::Isometry3d::Identity();
  about_axis.translation() = Eigen::Vector3d(0.01, 0, 0);
  const Eigen::Isometry3d spun =
      InFront() * about_axis * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) * about_axis.inverse();
  const double half_step_m = 0.03 * (2.0 * kPi / 315) / 2.0;
  EXPECT_LE(Mssd(CanRim(), spun, InFront(), can), half_step_m + 1e-9);
  EXPECT_LE(Mspd(CanRim(), spun, InFront(), can, SmallCamera()), 100.0 * half_step_m / 0.7);
  EXPECT_GT(Mssd(CanRim(), spun, InFront(), {Eigen::Isometry3d::Identity()}), 0.015);
  EXPECT_NEAR(Mssd(CanRim(), InFront(), InFront(), can), 0.0, 1e-12) << "the identity is one of them";
}

TEST(BopMetrics, RefusesSymmetriesThatAreNotRigidNamingTheField) {
  const nlohmann::json scaled = {{"symmetries_discrete", {{2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}};
  EXPECT_THROW(BopSymmetries(scaled, 0.001, "models_info.json"), InputError);
  try {
    BopSymmetries({{"symmetries_continuous", {{{"axis", {0, 0}}, {"offset", {0, 0, 0}}}}}}, 0.001, "info.json");
    ADD_FAILURE() << "an axis of two numbers was taken";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), ::testing::AllOf(HasSubstr("info.json"), HasSubstr("symmetries_continuous[0].axis")));
  }
}

// Depth images of a small camera: a test surface at 1 m, the truth's square of 20 x 20 pixels on it.
struct VsdScene {
  PinholeCamera camera = SmallCamera();
  cv::Mat test = cv::Mat(48, 64, CV_32F, cv::Scalar(1.0F));
  cv::Mat truth = cv::Mat(48, 64, CV_32F, cv::Scalar(0.0F));
  VsdScene() { truth(cv::Rect(10, 10, 20, 20)).setTo(1.0F); }
};

TEST(BopMetrics, VsdIsTheShareOfTheVisibleUnionThatIsNotInBothOrNotClose) {
  const VsdScene scene;
  // The estimate 10 pixels to the right: 200 pixels in both, 200 in one only, of a union of 600.
  cv::Mat beside(48, 64, CV_32F, cv::Scalar(0.0F));
  beside(cv::Rect(20, 10, 20, 20)).setTo(1.0F);
  for (const double error : Vsd(beside, scene.truth, scene.test, scene.camera, 0.015, {0.01, 0.1})) {
    EXPECT_NEAR(error, 400.0 / 600.0, 1e-12);
  }
  // The estimate on the truth's pixels, 2 cm nearer: all 400 visible in both, each distance off by at least 2 cm.
  cv::Mat nearer = scene.truth.clone();
  nearer.setTo(0.98F, scene.truth > 0.0F);
  const std::vector<double> errors = Vsd(nearer, scene.truth, scene.test, scene.camera, 0.015, {0.01, 0.05});
  EXPECT_DOUBLE_EQ(errors[0], 1.0) << "tau 1 cm";
  EXPECT_DOUBLE_EQ(errors[1], 0.0) << "tau 5 cm: 2 cm along rays within 20 pixels of the centre is under 2.1 cm";
}

TEST(BopMetrics, VsdSeesOnlyWhatTheTestImageShows) {
  const VsdScene scene;
  // An estimate 5 cm behind the test surface is hidden, except where the truth is visible: there it counts.
  cv::Mat behind(48, 64, CV_32F, cv::Scalar(0.0F));
  behind(cv::Rect(20, 10, 20, 20)).setTo(1.05F);
  const std::vector<double> hidden = Vsd(behind, scene.truth, scene.test, scene.camera, 0.015, {0.2});
  EXPECT_NEAR(hidden[0], 200.0 / 400.0, 1e-12) << "200 of the truth's 400 pixels have no estimate";
  // Where the test image has no depth, both renderings are visible.
  cv::Mat holes = scene.test.clone();
  holes(cv::Rect(30, 10, 10, 20)).setTo(0.0F);
  const std::vector<double> partly = Vsd(behind, scene.truth, holes, scene.camera, 0.015, {0.2});
  EXPECT_NEAR(partly[0], 400.0 / 600.0, 1e-12) << "the 200 pixels of the truth without estimate and 200 in holes";
  // Nothing visible at all: the worst error.
  const cv::Mat none(48, 64, CV_32F, cv::Scalar(0.0F));
  EXPECT_EQ(Vsd(none, none, scene.test, scene.camera, 0.015, {0.05}).front(), 1.0);
  EXPECT_THROW(Vsd(cv::Mat(10, 10, CV_32F), none, none, scene.camera, 0.015, {0.05}), InputError);
}

BopPoseErrors Errors(double vsd, double mssd_m, double mspd_px) {
  BopPoseErrors errors;
  errors.vsd.assign(10, vsd);
  errors.mssd_m = mssd_m;
  errors.mspd_px = mspd_px;
  return errors;
}

TEST(BopMetrics, AverageRecallIsTheMeanOverThresholdsAndInstances) {
  // VSD 0.12 at every tau is below 8 of the 10 thresholds, MSSD 0.12 d and MSPD 12 px too.
  BopObjectErrors exact{0.1, 1, {{Errors(0.0, 0.0, 0.0)}}};
  BopObjectErrors fair{0.2, 1, {{Errors(0.12, 0.12 * 0.2, 12.0)}}};
  BopObjectErrors missed{0.1, 1, {}};
  const BopRecall recall = AverageRecall({exact, fair, missed}, 640);
  EXPECT_EQ(recall.instances, 3);
  EXPECT_NEAR(recall.ar_vsd, (1.0 + 0.8 + 0.0) / 3.0, 1e-12);
  EXPECT_NEAR(recall.ar_mssd, (1.0 + 0.8 + 0.0) / 3.0, 1e-12);
  EXPECT_NEAR(recall.ar_mspd, (1.0 + 0.8 + 0.0) / 3.0, 1e-12);
  EXPECT_NEAR(recall.ar, 0.6, 1e-12);
  // MSPD's thresholds scale with the image width: 12 px is below 9 of 10 at 1280 pixels (10, 20, ... 100 px).
  EXPECT_NEAR(AverageRecall({fair}, 1280).ar_mspd, 0.9, 1e-12);
  fair.errors.front().push_back(Errors(0.0, 0.0, 0.0));
  EXPECT_THROW(AverageRecall({fair}, 640), InputError) << "two errors for one instance";
}

TEST(BopMetrics, EachEstimateBestScoreFirstTakesTheClosestInstanceLeftAtEachThreshold) {
  // Two instances; the first estimate (best score) is 8 px from instance 0 and 3 px from instance 1, the second 4 px
  // from instance 1 and far from 0. At every threshold the first takes instance 1, its closest, and the second finds
  // nothing left.
  const double far = 1000.0;
  BopObjectErrors two{0.1, 2, {{Errors(1, far, 8.0), Errors(1, far, 3.0)}, {Errors(1, far, far), Errors(1, far, 4.0)}}};
  EXPECT_NEAR(AverageRecall({two}, 640).ar_mspd, 0.5, 1e-12) << "1 of 2 at every threshold";
  // The second estimate close to instance 0 instead: the first takes 1 (3 px), the second 0 (6 px) from 10 px on.
  two.errors[1] = {Errors(1, far, 6.0), Errors(1, far, far)};
  EXPECT_NEAR(AverageRecall({two}, 640).ar_mspd, (1 * 1 + 9 * 2) / 20.0, 1e-12) << "5 px: 1 of 2, 10..50 px: 2 of 2";
}

}  // namespace
}  // namespace ecv
