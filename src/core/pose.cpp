#include "core/pose.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/SVD>

#include "core/error.h"

namespace ecv {

Eigen::Isometry3d RigidFromMatrix(const Eigen::Matrix4d& matrix, const std::string& source, const std::string& field,
                                  double tolerance) {
  if (!matrix.allFinite()) ThrowInputError(source, field, "a finite 4x4 matrix", "NaN or infinity");
  if (!matrix.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1), tolerance)) {
    ThrowInputError(source, field, "last row [0, 0, 0, 1]");
  }
  const Eigen::Matrix3d rotation = matrix.topLeftCorner<3, 3>();
  const double orthogonality = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
  if (orthogonality > tolerance || rotation.determinant() < 0.0) {
    std::ostringstream got;
    got << "|R^T R - I| = " << orthogonality << ", det R = " << rotation.determinant();
    ThrowInputError(source, field, "a rotation (orthonormal, det +1) in the upper-left 3x3", got.str());
  }
  Eigen::Isometry3d rigid = Eigen::Isometry3d::Identity();
  // The nearest rotation (SVD projection), so that rounding in files does not spread.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  rigid.linear() = svd.matrixU() * svd.matrixV().transpose();
  rigid.translation() = matrix.topRightCorner<3, 1>();
  return rigid;
}

Eigen::Isometry3d TurnedHalfWayAbout(const Eigen::Isometry3d& camera_from_object, const Eigen::Vector3d& centre,
                                     const Eigen::Vector3d& axis) {
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(M_PI, axis.normalized()).toRotationMatrix();
  turn.translation() = centre - turn.linear() * centre;  // the line through `centre` stays in place
  return camera_from_object * turn;
}

double RotationAngle(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Matrix3d relative = a.linear().transpose() * b.linear();
  const double cosine = std::clamp((relative.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cosine);
}

double TranslationDistance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

}  // namespace ecv
