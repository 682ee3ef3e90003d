#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/pose.h"

namespace ecv {
namespace {

Eigen::Isometry3d MakePose(double angle_rad, const Eigen::Vector3d& axis, const Eigen::Vector3d& translation) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

TEST(Pose, RotationAngleAndTranslationDistance) {
  const Eigen::Isometry3d a = MakePose(0.3, {1, 2, 3}, {0.1, 0.2, 0.3});
  const Eigen::Isometry3d b = a * MakePose(0.25, {0, 1, 0}, {0, 0, 0});
  EXPECT_NEAR(RotationAngle(a, b), 0.25, 1e-12);
  EXPECT_NEAR(RotationAngle(a, a), 0.0, 1e-7);
  EXPECT_NEAR(RotationAngle(Eigen::Isometry3d::Identity(), MakePose(M_PI, {0, 0, 1}, {0, 0, 0})), M_PI, 1e-7);
  EXPECT_NEAR(TranslationDistance(a, MakePose(0.0, {1, 0, 0}, {0.1, 0.2, 0.35})), 0.05, 1e-12);
}

// A pose turned half way about a line of the object keeps that line's points where they were, moves the others
// (turned 180 degrees) and turned twice is the pose again.
TEST(Pose, TurnedHalfWayAboutKeepsTheLineInPlace) {
  const Eigen::Isometry3d pose = MakePose(0.4, {0, 1, 1}, {0.1, 0.0, 0.8});
  const Eigen::Vector3d centre(0.02, 0.03, -0.01), axis(0.0, 0.0, 2.0);
  const Eigen::Isometry3d turned = TurnedHalfWayAbout(pose, centre, axis);
  EXPECT_NEAR(RotationAngle(pose, turned), M_PI, 1e-9);
  for (const double along : {-0.1, 0.0, 0.05}) {
    const Eigen::Vector3d on_line = centre + along * axis.normalized();
    EXPECT_NEAR((turned * on_line - pose * on_line).norm(), 0.0, 1e-12);
  }
  const Eigen::Vector3d off = centre + Eigen::Vector3d(0.03, 0.0, 0.0);  // 3 cm off the line: 6 cm across
  EXPECT_NEAR((turned * off - pose * off).norm(), 0.06, 1e-12);
  EXPECT_NEAR((TurnedHalfWayAbout(turned, centre, axis).matrix() - pose.matrix()).norm(), 0.0, 1e-12);
}

TEST(Pose, RigidFromMatrixKeepsRigidTransforms) {
  const Eigen::Isometry3d pose = MakePose(1.1, {0.2, -1, 0.5}, {0.4, -0.3, 1.2});
  const Eigen::Isometry3d parsed = RigidFromMatrix(pose.matrix(), "test", "pose");
  EXPECT_LT((parsed.matrix() - pose.matrix()).norm(), 1e-12);
}

TEST(Pose, RigidFromMatrixProjectsRoundedRotations) {
  Eigen::Matrix4d rounded = MakePose(0.7, {1, 1, 0}, {0, 0, 1}).matrix();
  rounded(0, 0) += 0.002;  // as a file with few digits
  const Eigen::Isometry3d parsed = RigidFromMatrix(rounded, "test", "pose");
  EXPECT_LT((parsed.linear().transpose() * parsed.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(parsed.linear().determinant(), 1.0, 1e-12);
}

TEST(Pose, RigidFromMatrixRejectsNonRigidMatrices) {
  Eigen::Matrix4d scaled = Eigen::Matrix4d::Identity();
  scaled(0, 0) = 1.5;
  EXPECT_THROW(RigidFromMatrix(scaled, "f.json", "camera_from_object"), InputError);
  Eigen::Matrix4d mirrored = Eigen::Matrix4d::Identity();
  mirrored(2, 2) = -1.0;
  EXPECT_THROW(RigidFromMatrix(mirrored, "f.json", "camera_from_object"), InputError);
  Eigen::Matrix4d bad_row = Eigen::Matrix4d::Identity();
  bad_row(3, 0) = 1.0;
  EXPECT_THROW(RigidFromMatrix(bad_row, "f.json", "camera_from_object"), InputError);
  Eigen::Matrix4d not_finite = Eigen::Matrix4d::Identity();
  not_finite(1, 3) = std::nan("");
  try {
    RigidFromMatrix(not_finite, "f.json", "camera_from_object");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("f.json: camera_from_object"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace ecv
