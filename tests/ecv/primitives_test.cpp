// ECV primitives on synthetic planes with known geometry, on a rotated real image and on the real
// YCB-Video frame against the ground-truth model.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "ecv/primitives.h"
#include "io/frame_io.h"
#include "io/points_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

constexpr double kDegree = M_PI / 180.0;
const PinholeCamera kCamera{520.0, 520.0, 159.5, 119.5, 320, 240};

// A plane through (0, 0, 0.8 m) whose normal is tilted from the optical axis.
struct TiltedPlane {
  Eigen::Vector3d normal =
      Eigen::AngleAxisd(35 * kDegree, Eigen::Vector3d(1, 0.4, 0).normalized()) * Eigen::Vector3d(0, 0, -1);
  Eigen::Vector3d point{0.0, 0.0, 0.8};

  // Point of the plane seen at `pixel`.
  Eigen::Vector3d Intersect(const Eigen::Vector2d& pixel) const {
    const Eigen::Vector3d ray = kCamera.BackProject(pixel, 1.0);
    return ray * (normal.dot(point) / normal.dot(ray));
  }

  // Depth image of the plane with Gaussian noise (metres, seeded).
  cv::Mat Depth(double noise_m, unsigned seed) const {
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, noise_m);
    cv::Mat depth(kCamera.height, kCamera.width, CV_32FC1);
    for (int v = 0; v < depth.rows; ++v) {
      for (int u = 0; u < depth.cols; ++u)
        depth.at<float>(v, u) = static_cast<float>(Intersect({u, v}).z() + noise(random));
    }
    return depth;
  }
};

RgbdFrame MakeFrame(const cv::Mat& grey, const cv::Mat& depth) {
  RgbdFrame frame;
  cv::cvtColor(grey, frame.color, cv::COLOR_GRAY2RGB);
  frame.depth = depth;
  frame.camera = kCamera;
  frame.name = "synthetic";
  return frame;
}

// Image angle (radians in [0, pi)) of the edge through the image.
constexpr double kEdgeAngle = 62 * kDegree;
const Eigen::Vector2d kEdgePoint(150.0, 110.0);

double DistanceToEdge(const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d along(std::cos(kEdgeAngle), std::sin(kEdgeAngle));
  const Eigen::Vector2d offset = pixel - kEdgePoint;
  return std::abs(offset.x() * along.y() - offset.y() * along.x());
}

cv::Mat StepEdgeImage() {
  cv::Mat grey(kCamera.height, kCamera.width, CV_8UC1);
  const Eigen::Vector2d normal(-std::sin(kEdgeAngle), std::cos(kEdgeAngle));
  for (int v = 0; v < grey.rows; ++v) {
    for (int u = 0; u < grey.cols; ++u) {
      // Pixel coverage of the bright side (anti-aliased as a camera would), then a little optical blur.
      const double coverage = std::clamp(0.5 + (Eigen::Vector2d(u, v) - kEdgePoint).dot(normal), 0.0, 1.0);
      grey.at<uchar>(v, u) = static_cast<uchar>(std::lround(60 + 130 * coverage));
    }
  }
  cv::GaussianBlur(grey, grey, cv::Size(0, 0), 0.7);
  return grey;
}

// Smallest angle between two lines (directions without sign), radians.
double LineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized()))));
}

TEST(EcvPrimitives, StepEdgeOnATiltedPlaneGivesSegmentsAlongIt) {
  const TiltedPlane plane;
  const ExtractionResult result = ExtractPrimitives(MakeFrame(StepEdgeImage(), plane.Depth(0.0003, 1)));
  // The edge's 3D direction: two of its image points intersected with the plane.
  const Eigen::Vector2d along(std::cos(kEdgeAngle), std::sin(kEdgeAngle));
  const Eigen::Vector3d truth_3d = plane.Intersect(kEdgePoint + 40 * along) - plane.Intersect(kEdgePoint - 40 * along);

  int on_edge = 0;
  for (const Primitive& primitive : result.primitives) {
    const Eigen::Vector2d pixel = primitive.pixel.cast<double>();
    const double distance = DistanceToEdge(pixel);
    // Away from the image border, homogeneous areas give nothing. (Within about two wavelengths of the border,
    // where the edge meets its reflection in the FFT padding, the band-pass sees a corner.)
    const bool interior = pixel.x() >= 24 && pixel.y() >= 24 && pixel.x() <= 295 && pixel.y() <= 215;
    if (!interior) continue;
    EXPECT_LT(distance, 8.0) << "no primitive away from the edge: " << pixel.transpose();
    if (distance > 2.0) continue;
    ++on_edge;
    EXPECT_EQ(primitive.type, PrimitiveType::kSegment) << pixel.transpose();
    // The monogenic orientation is normal to the edge.
    const double image_angle = std::fmod(primitive.image_orientation + M_PI / 2, M_PI);
    const double error_2d = std::min(std::abs(image_angle - kEdgeAngle), M_PI - std::abs(image_angle - kEdgeAngle));
    EXPECT_LT(error_2d, 3 * kDegree) << pixel.transpose();
    EXPECT_LT(LineAngle(primitive.orientation.cast<double>(), truth_3d), 5 * kDegree) << pixel.transpose();
    // On the plane: within 2 mm of it.
    EXPECT_LT(std::abs(plane.normal.dot(primitive.position.cast<double>() - plane.point)), 0.002);
  }
  EXPECT_GE(on_edge, 20);
}

TEST(EcvPrimitives, RandomTextureOnATiltedPlaneGivesTexletsWithItsNormal) {
  std::mt19937 random(3);
  cv::Mat noise(kCamera.height, kCamera.width, CV_32FC1);
  cv::randu(noise, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.5);
  cv::Mat grey;
  cv::normalize(noise, grey, 0, 255, cv::NORM_MINMAX, CV_8U);
  const TiltedPlane plane;
  const ExtractionResult result = ExtractPrimitives(MakeFrame(grey, plane.Depth(0.0003, 2)));
  ASSERT_GT(result.counts.texlets, 300);
  EXPECT_GT(result.counts.texlets, 4 * result.counts.segments);
  int within = 0;
  for (const Primitive& primitive : result.primitives) {
    if (primitive.type != PrimitiveType::kTexlet) continue;
    within += std::acos(std::min(1.0, primitive.orientation.cast<double>().dot(plane.normal))) < 5 * kDegree ? 1 : 0;
  }
  EXPECT_GT(within, 0.95 * result.counts.texlets) << "normals must face the camera and follow the plane";
}

TEST(EcvPrimitives, RotatingTheImageBy90DegreesKeepsTheCount) {
  const LoadedFrame loaded = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  RgbdFrame rotated;
  cv::rotate(loaded.rgbd.color, rotated.color, cv::ROTATE_90_CLOCKWISE);
  cv::rotate(loaded.rgbd.depth, rotated.depth, cv::ROTATE_90_CLOCKWISE);
  // Clockwise: new (u', v') = (H - 1 - v, u); x' = -y, y' = x.
  const PinholeCamera& c = loaded.rgbd.camera;
  rotated.camera = {c.fy, c.fx, c.height - 1 - c.cy, c.cx, c.height, c.width};
  const ExtractionResult original = ExtractPrimitives(loaded.rgbd);
  const ExtractionResult turned = ExtractPrimitives(rotated);
  const double count = static_cast<double>(original.primitives.size());
  EXPECT_GT(count, 1000);
  EXPECT_LT(std::abs(static_cast<double>(turned.primitives.size()) - count), 0.10 * count);
  EXPECT_LT(std::abs(turned.counts.segments - original.counts.segments), 0.15 * original.counts.segments);
}

TEST(EcvPrimitives, RealCrackerBoxPrimitivesLieOnItsModel) {
  const std::string prefix = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const LoadedFrame loaded = LoadYcbvFrame(prefix);
  cv::Mat mask = cv::imread(prefix + "-label.png", cv::IMREAD_UNCHANGED) == 2;  // 003_cracker_box
  cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(7, 7)));
  const ExtractionResult result = ExtractPrimitives(loaded.rgbd, {}, mask);

  const GroundTruth& truth = loaded.ground_truth.at(1);
  ASSERT_EQ(truth.object_name, "003_cracker_box");
  std::vector<Eigen::Vector3d> model;
  for (const Eigen::Vector3d& point : ReadXyzFile(test::DataPath("ycbv_subset/models/003_cracker_box/points.xyz"))) {
    model.push_back(truth.camera_from_object * point);
  }
  int near = 0;
  for (const Primitive& primitive : result.primitives) {
    double best = std::numeric_limits<double>::max();
    for (const Eigen::Vector3d& point : model)
      best = std::min(best, (point - primitive.position.cast<double>()).squaredNorm());
    near += std::sqrt(best) < 0.01 ? 1 : 0;
  }
  EXPECT_GT(result.counts.segments, 20);
  EXPECT_GT(result.counts.texlets, 20);
  EXPECT_GE(near, 0.9 * static_cast<double>(result.primitives.size()))
      << near << " of " << result.primitives.size() << " within 1 cm";
}

TEST(EcvPrimitives, DegenerateInputsGiveNoPrimitivesOrAClearError) {
  const TiltedPlane plane;
  // No valid depth: every kept cell is dropped and counted.
  const ExtractionResult no_depth = ExtractPrimitives(MakeFrame(StepEdgeImage(), cv::Mat::zeros(240, 320, CV_32FC1)));
  EXPECT_TRUE(no_depth.primitives.empty());
  EXPECT_GT(no_depth.counts.no_depth, 20);
  EXPECT_EQ(no_depth.counts.no_depth,
            no_depth.counts.edge_cells + no_depth.counts.texture_cells - no_depth.counts.suppressed);
  // A constant image: all homogeneous.
  const ExtractionResult constant =
      ExtractPrimitives(MakeFrame(cv::Mat(240, 320, CV_8UC1, cv::Scalar(128)), plane.Depth(0, 0)));
  EXPECT_TRUE(constant.primitives.empty());
  EXPECT_EQ(constant.counts.homogeneous, constant.counts.cells);
  // A 1x1 image.
  RgbdFrame tiny = MakeFrame(cv::Mat(1, 1, CV_8UC1, cv::Scalar(10)), cv::Mat(1, 1, CV_32FC1, cv::Scalar(1.0F)));
  tiny.camera = {500, 500, 0, 0, 1, 1};
  EXPECT_TRUE(ExtractPrimitives(tiny).primitives.empty());
  // NaN depth: a clear error naming the frame and the pixel.
  cv::Mat nan_depth = plane.Depth(0, 0);
  nan_depth.at<float>(5, 7) = std::numeric_limits<float>::quiet_NaN();
  try {
    ExtractPrimitives(MakeFrame(StepEdgeImage(), nan_depth));
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("synthetic: depth"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("(7, 5)"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace ecv
