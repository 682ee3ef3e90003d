// Composites of real YCB-Video frames (bench/scenes/composites.h): the pasted object lies at its new ground truth
// (silhouette and depth against its model points), on the target's table, hides and is hidden consistently, and the
// same seed gives the same composite.

#include "scenes/composites.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/point_index.h"
#include "io/points_io.h"
#include "support/test_data.h"

namespace ecv::bench {
namespace {

class Composites : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    for (const char* video : {"0000", "0001", "0002"}) {
      frames_.push_back(LoadSourceFrame(test::DataPath("ycbv_subset/Example-Scenes/") + video + "/000001"));
    }
  }
  static void TearDownTestSuite() { frames_.clear(); }

  static const SourceFrame& Video(int index) { return frames_[static_cast<size_t>(index)]; }

  // The gelatin box of 0000/000001 beside the potted meat can of 0002/000001.
  static Composite GelatinBoxBesideTheCan(uint32_t seed) {
    Composite composite;
    EXPECT_TRUE(MakeComposite(Video(0), "009_gelatin_box", Video(2), "010_potted_meat_can", seed, CompositeOptions(),
                              &composite));
    return composite;
  }

  static std::vector<SourceFrame> frames_;
};

std::vector<SourceFrame> Composites::frames_;

std::vector<Eigen::Vector3d> ModelPoints(const std::string& name) {
  return ReadXyzFile(test::DataPath("ycbv_subset/models/" + name + "/points.xyz"));
}

std::vector<Eigen::Vector3f> Moved(const std::vector<Eigen::Vector3d>& points, const Eigen::Isometry3d& pose) {
  std::vector<Eigen::Vector3f> moved;
  for (const Eigen::Vector3d& point : points) moved.push_back((pose * point).cast<float>());
  return moved;
}

// The silhouette of `points` (camera frame): a disc at each projected point, closed, then widened by 3 px.
cv::Mat Silhouette(const std::vector<Eigen::Vector3f>& points, const PinholeCamera& camera) {
  cv::Mat silhouette = cv::Mat::zeros(camera.height, camera.width, CV_8U);
  for (const Eigen::Vector3f& point : points) {
    const Eigen::Vector2d pixel = camera.Project(point.cast<double>());
    cv::circle(silhouette,
               cv::Point(static_cast<int>(std::lround(pixel.x())), static_cast<int>(std::lround(pixel.y()))), 2,
               cv::Scalar(255), cv::FILLED);
  }
  const cv::Mat square5 = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5));
  cv::morphologyEx(silhouette, silhouette, cv::MORPH_CLOSE, square5);
  cv::dilate(silhouette, silhouette, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  return silhouette;
}

const GroundTruth& TruthOf(const LoadedFrame& frame, const std::string& name) {
  const auto found = std::find_if(frame.ground_truth.begin(), frame.ground_truth.end(),
                                  [&](const GroundTruth& truth) { return truth.object_name == name; });
  if (found == frame.ground_truth.end()) throw std::runtime_error("no ground truth of " + name);
  return *found;
}

// Centroid of the model points at `pose`, and their largest distance from it along `table`.
std::pair<Eigen::Vector3d, double> CentreAndRadius(const std::vector<Eigen::Vector3d>& points,
                                                   const Eigen::Isometry3d& pose, const TablePlane& table) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& point : points) centre += pose * point;
  centre /= static_cast<double>(points.size());
  double radius = 0.0;
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector3d offset = pose * point - centre;
    radius = std::max(radius, (offset - table.normal * table.normal.dot(offset)).norm());
  }
  return {centre, radius};
}

// The YCB-Video tables: each plane faces the camera and carries the objects standing on it (their lowest model
// points within 1.5 cm; the pudding box of 0002 lies on the wood block, 8 cm up).
TEST_F(Composites, EachTablePlaneCarriesTheObjectsStandingOnIt) {
  for (const SourceFrame& frame : frames_) {
    EXPECT_GT(frame.table.offset, 0.2) << frame.prefix;
    EXPECT_GT(frame.table.inliers, 5000) << frame.prefix;
    for (const GroundTruth& truth : frame.frame.ground_truth) {
      double lowest = 1e9;
      for (const Eigen::Vector3d& point : ModelPoints(truth.object_name)) {
        lowest = std::min(lowest, frame.table.Height(truth.camera_from_object * point));
      }
      if (truth.object_name == "008_pudding_box") {
        EXPECT_GT(lowest, 0.05) << frame.prefix;
      } else {
        EXPECT_LT(std::abs(lowest), 0.015) << frame.prefix << " " << truth.object_name;
      }
    }
  }
}

TEST_F(Composites, TheGelatinBoxBesideThePottedMeatCanLiesOnTheTableAtItsPose) {
  const Composite composite = GelatinBoxBesideTheCan(1);
  const SourceFrame& target = Video(2);
  EXPECT_EQ(composite.frame.rgbd.name, "composite/0000-000001-009_gelatin_box-into-0002-000001");
  EXPECT_EQ(composite.beside, "010_potted_meat_can");
  ASSERT_EQ(composite.frame.ground_truth.size(), target.frame.ground_truth.size() + 1);
  const GroundTruth& box = composite.frame.ground_truth.back();
  EXPECT_EQ(box.object_name, "009_gelatin_box");
  EXPECT_EQ(box.object_id, 8);
  const std::vector<Eigen::Vector3d> points = ModelPoints("009_gelatin_box");
  const Eigen::Isometry3d& source_pose = TruthOf(Video(0).frame, "009_gelatin_box").camera_from_object;
  EXPECT_TRUE(box.camera_from_object.isApprox(composite.target_from_source * source_pose, 1e-12));
  // Its move takes the source table's normal to the target's and turns it by at most 15 degrees about it.
  const Eigen::Matrix3d& rotation = composite.target_from_source.linear();
  EXPECT_LT((rotation * Video(0).table.normal - target.table.normal).norm(), 1e-9);
  const Eigen::Matrix3d turn =
      rotation * Eigen::Quaterniond::FromTwoVectors(Video(0).table.normal, target.table.normal).inverse();
  EXPECT_LT(Eigen::AngleAxisd(turn).angle(), 15.0 * M_PI / 180.0 + 1e-9);

  // On the table: its lowest point on the plane; beside the can: centres apart by the radii plus a gap of 0-3 cm.
  double lowest = 1e9;
  for (const Eigen::Vector3d& point : points)
    lowest = std::min(lowest, target.table.Height(box.camera_from_object * point));
  EXPECT_LT(std::abs(lowest), 0.01);
  const auto [box_centre, box_radius] = CentreAndRadius(points, box.camera_from_object, target.table);
  const auto [can_centre, can_radius] =
      CentreAndRadius(ModelPoints("010_potted_meat_can"),
                      TruthOf(target.frame, "010_potted_meat_can").camera_from_object, target.table);
  Eigen::Vector3d apart = box_centre - can_centre;
  apart -= target.table.normal * target.table.normal.dot(apart);
  EXPECT_GT(apart.norm(), box_radius + can_radius - 1e-3);
  EXPECT_LT(apart.norm(), box_radius + can_radius + 0.03 + 1e-3);
  // Seen from within 12 degrees of its source view (object frame directions to its centre).
  const Eigen::Vector3d source_centre = composite.target_from_source.inverse() * box_centre;
  const Eigen::Vector3d seen = source_pose.linear().transpose() * source_centre.normalized();
  const Eigen::Vector3d seen_now = box.camera_from_object.linear().transpose() * box_centre.normalized();
  EXPECT_LT(std::acos(std::min(1.0, seen.dot(seen_now))) * 180.0 / M_PI, 12.0);

  // Its pixels lie in the silhouette of its model points and their depth on its surface.
  const std::vector<Eigen::Vector3f> surface = Moved(points, box.camera_from_object);
  const PinholeCamera& camera = composite.frame.rgbd.camera;
  const cv::Mat pasted = composite.labels == box.object_id;
  const int pasted_pixels = cv::countNonZero(pasted);
  EXPECT_GT(pasted_pixels, 2000);
  EXPECT_EQ(pasted_pixels, composite.pasted_pixels);
  EXPECT_GE(cv::countNonZero(pasted & Silhouette(surface, camera)), 0.95 * pasted_pixels);
  const PointIndex index(surface);
  std::vector<float> distances;  // of the pasted pixels with depth to the nearest model point
  for (int v = 0; v < pasted.rows; ++v) {
    for (int u = 0; u < pasted.cols; ++u) {
      const float z = composite.frame.rgbd.depth.at<float>(v, u);
      if (pasted.at<uint8_t>(v, u) == 0 || z <= 0.0F) continue;
      const Eigen::Vector3f point = camera.BackProject(Eigen::Vector2d(u, v), z).cast<float>();
      distances.push_back(std::sqrt(index.Nearest(point).second));
    }
  }
  ASSERT_GT(distances.size(), 0.8 * pasted_pixels);
  std::sort(distances.begin(), distances.end());
  // As close as the source's own pixels are to its ground truth (model points about 3 mm apart, sensor noise).
  EXPECT_LT(distances[distances.size() / 2], 0.003);
  EXPECT_LT(distances[distances.size() * 9 / 10], 0.006);
}

// Over free places in the crowded 0002 and the open 0001: no pasted pixel lies more than 1 cm behind the target's
// depth, every other pixel keeps the target's colour, depth and label, and some composite shows the pasted object
// partly hidden by the target's objects in front of it.
TEST_F(Composites, OcclusionIsConsistentAndOnlyThePastedPixelsChange) {
  int made = 0, partly_hidden = 0;
  for (const auto& [source, object] : {std::pair{0, "061_foam_brick"}, std::pair{2, "040_large_marker"}}) {
    for (const int target_index : {1, 2}) {
      if (source == target_index) continue;
      for (uint32_t seed = 1; seed <= 4; ++seed) {
        const SourceFrame& target = Video(target_index);
        Composite composite;
        if (!MakeComposite(Video(source), object, target, "", seed, CompositeOptions(), &composite)) continue;
        ++made;
        const cv::Mat pasted = composite.labels == composite.frame.ground_truth.back().object_id;
        const cv::Mat& depth = composite.frame.rgbd.depth;
        const cv::Mat& target_depth = target.frame.rgbd.depth;
        int behind = 0;
        for (int v = 0; v < pasted.rows; ++v) {
          for (int u = 0; u < pasted.cols; ++u) {
            if (pasted.at<uint8_t>(v, u) == 0) continue;
            const float z = depth.at<float>(v, u), target_z = target_depth.at<float>(v, u);
            behind += z > 0.0F && target_z > 0.0F && z > target_z + 0.01F ? 1 : 0;
          }
        }
        EXPECT_EQ(behind, 0) << composite.frame.rgbd.name << " seed " << seed;
        const cv::Mat kept = pasted == 0;
        EXPECT_EQ(cv::norm(composite.frame.rgbd.color, target.frame.rgbd.color, cv::NORM_INF, kept), 0.0);
        EXPECT_EQ(cv::norm(depth, target_depth, cv::NORM_INF, kept), 0.0);
        EXPECT_EQ(cv::norm(composite.labels, target.labels, cv::NORM_INF, kept), 0.0);
        partly_hidden += composite.frame.ground_truth.back().visible_fraction < 0.9 ? 1 : 0;
      }
    }
  }
  EXPECT_GE(made, 8);
  EXPECT_GE(partly_hidden, 1);
}

TEST_F(Composites, TheSameSeedGivesTheSameCompositeAndKeepsTheTargetsGroundTruth) {
  const Composite first = GelatinBoxBesideTheCan(3), again = GelatinBoxBesideTheCan(3);
  EXPECT_EQ(cv::norm(first.frame.rgbd.color, again.frame.rgbd.color, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first.frame.rgbd.depth, again.frame.rgbd.depth, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first.labels, again.labels, cv::NORM_INF), 0.0);
  EXPECT_TRUE(first.target_from_source.isApprox(again.target_from_source, 0.0));
  const Composite other = GelatinBoxBesideTheCan(4);
  EXPECT_GT((other.target_from_source.translation() - first.target_from_source.translation()).norm(), 1e-3);

  const std::vector<GroundTruth>& target_truth = Video(2).frame.ground_truth;
  ASSERT_EQ(first.frame.ground_truth.size(), target_truth.size() + 1);
  for (size_t i = 0; i < target_truth.size(); ++i) {
    EXPECT_EQ(first.frame.ground_truth[i].object_name, target_truth[i].object_name);
    EXPECT_EQ(first.frame.ground_truth[i].object_id, target_truth[i].object_id);
    EXPECT_TRUE(first.frame.ground_truth[i].camera_from_object.isApprox(target_truth[i].camera_from_object, 0.0));
  }
}

TEST_F(Composites, RefusesASecondInstanceOfAModelAndAnObjectNotWholeInItsSource) {
  Composite untouched;
  untouched.object_name = "unchanged";
  CompositeAttempts attempts;
  // 0002 holds the mustard bottle already; the mug of 0000 stands behind the foam brick.
  EXPECT_FALSE(
      MakeComposite(Video(1), "006_mustard_bottle", Video(2), "", 1, CompositeOptions(), &untouched, &attempts));
  EXPECT_NE(attempts.refused.find("holds 006_mustard_bottle"), std::string::npos) << attempts.refused;
  EXPECT_FALSE(MakeComposite(Video(0), "025_mug", Video(2), "", 1, CompositeOptions(), &untouched, &attempts));
  EXPECT_NE(attempts.refused.find("not whole"), std::string::npos) << attempts.refused;
  EXPECT_EQ(attempts.tried, 0);
  EXPECT_EQ(untouched.object_name, "unchanged");
}

TEST_F(Composites, BrokenRequestsAndOptionsAreInputErrors) {
  Composite composite;
  EXPECT_THROW(MakeComposite(Video(0), "003_cracker_box", Video(2), "", 1, CompositeOptions(), &composite), InputError);
  EXPECT_THROW(MakeComposite(Video(0), "009_gelatin_box", Video(2), "025_mug", 1, CompositeOptions(), &composite),
               InputError);
  CompositeOptions inverted;
  inverted.min_gap_m = 0.05;
  EXPECT_THROW(inverted.Check(), InputError);
  CompositeOptions no_attempts;
  no_attempts.attempts = 0;
  EXPECT_THROW(MakeComposite(Video(0), "009_gelatin_box", Video(2), "", 1, no_attempts, &composite), InputError);
  EXPECT_THROW(LoadSourceFrame(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"), "/no/such/models"),
               InputError);
}

}  // namespace
}  // namespace ecv::bench
