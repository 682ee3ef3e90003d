// The recognizer's scores on constructed data: the consistent-set size of planted true correspondences
// among false ones, the colour correlation's invariance to gain and offset, and how much of a pose's outline
// runs along the scene's depth steps, and how many of a model's texture edges the scene shows.

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "recognize/scoring.h"

namespace ecv {
namespace {

Primitive RandomPrimitive(std::mt19937& random, float extent) {
  std::uniform_real_distribution<float> coordinate(0.0F, extent);
  std::normal_distribution<float> normal(0.0F, 1.0F);
  Primitive primitive;
  primitive.position = {coordinate(random), coordinate(random), coordinate(random)};
  primitive.orientation = Eigen::Vector3f(normal(random), normal(random), normal(random)).normalized();
  return primitive;
}

// `true_count` object primitives seen in the scene under a rigid motion (2 mm noise), then `false_count`
// correspondences to random scene primitives in a 1 m cube; correspondence i pairs object i with scene i.
struct Planted {
  std::vector<Primitive> object, scene;
  std::vector<Correspondence> correspondences;
};

Planted Plant(int true_count, int false_count, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<float> noise(0.0F, 0.002F);
  const Eigen::Isometry3f motion = Eigen::Translation3f(0.1F, -0.2F, 0.7F) *
                                   Eigen::AngleAxisf(1.1F, Eigen::Vector3f(1.0F, 2.0F, -0.5F).normalized());
  Planted planted;
  for (int i = 0; i < true_count + false_count; ++i) {
    planted.object.push_back(RandomPrimitive(random, 0.2F));
    Primitive seen = i < true_count ? planted.object.back() : RandomPrimitive(random, 1.0F);
    if (i < true_count) {
      seen.position = motion * seen.position + Eigen::Vector3f(noise(random), noise(random), noise(random));
      seen.orientation = motion.linear() * seen.orientation;
    }
    planted.scene.push_back(seen);
    planted.correspondences.push_back({i, i});
  }
  return planted;
}

TEST(ConsistentSetSize, FindsPlantedTrueCorrespondencesAmongManyFalseOnes) {
  ConsistencyOptions options;
  options.max_distance_m = 0.35;  // the object's diameter
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Planted planted = Plant(25, 300, seed);
    const int size = ConsistentSetSize(planted.object, planted.scene, planted.correspondences, options);
    EXPECT_GE(size, 22) << "seed " << seed;
    EXPECT_LE(size, 28) << "seed " << seed;
  }
}

TEST(ConsistentSetSize, StaysSmallWithoutTrueCorrespondences) {
  ConsistencyOptions options;
  options.max_distance_m = 0.35;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Planted planted = Plant(0, 325, seed);
    EXPECT_LE(ConsistentSetSize(planted.object, planted.scene, planted.correspondences, options), 8) << seed;
  }
}

TEST(ConsistentSetSize, CountsEveryExactCorrespondenceAtTightTolerances) {
  // A 4 x 5 grid 4 cm apart (every pair beyond the 2 cm minimum), moved without noise: all 20 agree.
  std::mt19937 random(3);
  const Eigen::Isometry3f motion =
      Eigen::Translation3f(0.3F, 0.1F, 0.9F) * Eigen::AngleAxisf(2.0F, Eigen::Vector3f::UnitY());
  std::vector<Primitive> object, scene;
  std::vector<Correspondence> correspondences;
  for (int i = 0; i < 20; ++i) {
    Primitive primitive = RandomPrimitive(random, 0.1F);
    primitive.position = {0.04F * static_cast<float>(i % 4), 0.04F * static_cast<float>(i / 4), 0.0F};
    object.push_back(primitive);
    primitive.position = motion * primitive.position;
    primitive.orientation = motion.linear() * primitive.orientation;
    scene.push_back(primitive);
    correspondences.push_back({i, i});
  }
  ConsistencyOptions options;
  options.tolerance_m = 0.001;
  options.angle_tolerance = 0.01;
  EXPECT_EQ(ConsistentSetSize(object, scene, correspondences, options), 20);
  scene[7].orientation = -scene[7].orientation;  // a direction's sign carries no meaning
  EXPECT_EQ(ConsistentSetSize(object, scene, correspondences, options), 20);
  scene[7].position.x() += 0.01F;  // now 1 cm off: it disagrees with the others
  EXPECT_EQ(ConsistentSetSize(object, scene, correspondences, options), 19);
}

TEST(ConsistentSetSize, RejectsBadOptions) {
  ConsistencyOptions options;
  options.tolerance_m = 0.0;
  const Planted planted = Plant(5, 0, 1);
  EXPECT_THROW(ConsistentSetSize(planted.object, planted.scene, planted.correspondences, options), InputError);
}

std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> Colors(int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> value(0.0F, 1.0F);
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> colors;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3f model(value(random), value(random), value(random));
    colors.emplace_back(model, model);
  }
  return colors;
}

TEST(ColorCorrelation, IgnoresBrightnessAndAWhiteBalance) {
  auto colors = Colors(500, 1);
  for (auto& [model, scene] : colors) {
    scene = 0.7F * Eigen::Vector3f(0.85F, 1.0F, 1.15F).cwiseProduct(model).array() + 0.05F;
  }
  EXPECT_GT(ColorCorrelation(colors), 0.95);  // 0.97: the cast costs a little
}

// The same light-dark pattern in red on the model and in blue in the scene: each channel alone correlates
// perfectly, the colours do not.
TEST(ColorCorrelation, IsLowForTheSamePatternInAnotherHue) {
  std::mt19937 random(6);
  std::uniform_real_distribution<float> brightness(0.2F, 1.0F);
  const Eigen::Vector3f red(0.9F, 0.3F, 0.1F), blue(0.1F, 0.3F, 0.9F);
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> other_hue, same_hue;
  for (int i = 0; i < 500; ++i) {
    const float b = brightness(random);
    other_hue.emplace_back(b * red, b * blue);
    same_hue.emplace_back(b * red, (1.3F * b * red).array() + 0.05F);
  }
  EXPECT_LT(ColorCorrelation(other_hue), 0.2);
  EXPECT_GT(ColorCorrelation(same_hue), 0.99);
}

// A plain yellow side (the model's colours within a render's noise): its hue decides. The scene's plain yellow under
// a warmer light agrees; plain blue, grey and a printed pattern do not.
TEST(ColorCorrelation, APlainModelIsJudgedByItsHue) {
  std::mt19937 random(7);
  std::normal_distribution<float> noise(0.0F, 0.005F);
  std::uniform_real_distribution<float> value(0.0F, 1.0F);
  const Eigen::Vector3f yellow(0.8F, 0.7F, 0.15F), warm(1.15F, 1.0F, 0.85F);
  std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> same, blue, grey, printed;
  for (int i = 0; i < 500; ++i) {
    const Eigen::Vector3f model = yellow + Eigen::Vector3f(noise(random), noise(random), noise(random));
    const Eigen::Vector3f jitter(noise(random), noise(random), noise(random));
    same.emplace_back(model, 0.6F * warm.cwiseProduct(yellow) + 4.0F * jitter);
    blue.emplace_back(model, Eigen::Vector3f(0.15F, 0.3F, 0.8F) + 4.0F * jitter);
    grey.emplace_back(model, Eigen::Vector3f::Constant(0.6F) + 4.0F * jitter);
    printed.emplace_back(model, Eigen::Vector3f(value(random), value(random), value(random)));
  }
  EXPECT_GT(ColorCorrelation(same), 0.9);
  EXPECT_EQ(ColorCorrelation(blue), 0.0);
  EXPECT_LT(ColorCorrelation(grey), 0.2);
  EXPECT_LT(ColorCorrelation(printed), 0.2);
}

TEST(ColorCorrelation, IsNearZeroForUnrelatedColoursAndZeroWhenInverted) {
  auto unrelated = Colors(2000, 2);
  const auto others = Colors(2000, 3);
  for (size_t i = 0; i < unrelated.size(); ++i) unrelated[i].second = others[i].first;
  EXPECT_LT(ColorCorrelation(unrelated), 0.1);
  auto inverted = Colors(500, 4);
  for (auto& [model, scene] : inverted) scene = Eigen::Vector3f::Ones() - model;
  EXPECT_EQ(ColorCorrelation(inverted), 0.0);
  EXPECT_EQ(ColorCorrelation(Colors(9, 5)), 0.0);  // too few pairs to say
}

// Points on the plane z = 0.8 + slope * x (camera frame, metres) with 3 mm noise: a disc of radius 3 cm about
// (0, 0) when `disc`, else a ring from 3.5 to 6 cm.
std::vector<Eigen::Vector3f> PlanePoints(bool disc, float slope, float offset, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> coordinate(-0.06F, 0.06F);
  std::normal_distribution<float> noise(0.0F, 0.003F);
  std::vector<Eigen::Vector3f> points;
  while (points.size() < 300) {
    const float x = coordinate(random), y = coordinate(random), r = std::hypot(x, y);
    if (disc ? r > 0.03F : (r < 0.035F || r > 0.06F)) continue;
    points.emplace_back(x, y, 0.8F + slope * x + offset + noise(random));
  }
  return points;
}

TEST(PatchOfLargerPlane, AFlatSurfaceWhosePlaneGoesOnAroundItIsAPatch) {
  // A can sunk into a tilted table, its lid flush with the table top.
  EXPECT_TRUE(PatchOfLargerPlane(PlanePoints(true, 0.5F, 0.0F, 1), PlanePoints(false, 0.5F, 0.0F, 2)));
}

TEST(PatchOfLargerPlane, AFaceAboveItsSurroundingsOrACurvedSurfaceIsNot) {
  // A box's top face 3 cm above the table around it.
  EXPECT_FALSE(PatchOfLargerPlane(PlanePoints(true, 0.5F, -0.03F, 1), PlanePoints(false, 0.5F, 0.0F, 2)));
  // A corrugated surface (1.5 cm waves) whose least-squares plane is the table's: not one plane.
  std::vector<Eigen::Vector3f> waves = PlanePoints(true, 0.0F, 0.0F, 1);
  for (Eigen::Vector3f& point : waves) point.z() += 0.015F * std::cos(point.x() * 300.0F);
  EXPECT_FALSE(PatchOfLargerPlane(waves, PlanePoints(false, 0.0F, 0.0F, 2)));
  // Too few points to say.
  std::vector<Eigen::Vector3f> few = PlanePoints(true, 0.0F, 0.0F, 1);
  few.resize(10);
  EXPECT_FALSE(PatchOfLargerPlane(few, PlanePoints(false, 0.0F, 0.0F, 2)));
  PlanePatchOptions bad;
  bad.min_share = 0.0;
  EXPECT_THROW(PatchOfLargerPlane(waves, waves, bad), InputError);
}

// A table 1 m away (CV_32FC1, 80 x 60 pixels) with a box face 4 cm nearer on the pixels of `box`.
cv::Mat TableWithBox(const cv::Rect& box) {
  cv::Mat depth(60, 80, CV_32FC1, cv::Scalar(1.0F));
  depth(box).setTo(0.96F);
  return depth;
}

// The same box face rendered at a pose (the table not rendered: 0 off the object).
cv::Mat Rendered(const cv::Rect& box) {
  cv::Mat depth = cv::Mat::zeros(60, 80, CV_32FC1);
  depth(box).setTo(0.96F);
  return depth;
}

TEST(DepthSteps, MarksBothSidesOfAStepAndOfMissingDepthButNotSmallSteps) {
  cv::Mat depth = TableWithBox({20, 20, 20, 20});
  depth(cv::Rect(60, 0, 20, 60)).setTo(1.005F);  // a 5 mm step: the table goes on
  depth.at<float>(5, 5) = 0.0F;                  // one pixel without depth
  const cv::Mat steps = DepthSteps(depth, 0.01, 0);
  EXPECT_EQ(steps.at<uchar>(20, 30), 255);  // the box's top row and the table row above it
  EXPECT_EQ(steps.at<uchar>(19, 30), 255);
  EXPECT_EQ(steps.at<uchar>(30, 39), 255);  // its right column and the table to the right
  EXPECT_EQ(steps.at<uchar>(30, 40), 255);
  EXPECT_EQ(steps.at<uchar>(30, 30), 0);  // inside the face
  EXPECT_EQ(steps.at<uchar>(30, 60), 0);  // the small step
  EXPECT_EQ(steps.at<uchar>(5, 5), 255);  // the hole and its neighbours
  EXPECT_EQ(steps.at<uchar>(5, 6), 255);
  EXPECT_EQ(steps.at<uchar>(5, 7), 0);
  // Counted exactly: the box's outline of 4 x 20 - 4 pixels and the 4 x 20 + 4 table pixels around it (without the
  // corners), the hole and its 4 neighbours.
  EXPECT_EQ(cv::countNonZero(steps), 76 + 80 + 5);
  const cv::Mat grown = DepthSteps(depth, 0.01, 2);
  EXPECT_EQ(grown.at<uchar>(30, 42), 255);
  EXPECT_EQ(grown.at<uchar>(30, 43), 0);
  cv::Mat millimetres;
  depth.convertTo(millimetres, CV_16UC1, 1000.0);
  EXPECT_THROW(DepthSteps(millimetres, 0.01, 0), InputError);
  EXPECT_THROW(DepthSteps(depth, 0.0, 0), InputError);
  EXPECT_THROW(OutlineOnDepthSteps(Rendered({20, 20, 20, 20}), 1, depth, steps(cv::Rect(0, 0, 40, 30)), 0.015),
               InputError);
}

TEST(OutlineOnDepthSteps, IsOneForABoxStandingOutAndZeroForOneLyingFlatOnALargerFace) {
  const cv::Rect box(20, 20, 20, 20);
  const cv::Mat scene = TableWithBox(box);
  const cv::Mat steps = DepthSteps(scene, 0.01, 2);
  EXPECT_DOUBLE_EQ(OutlineOnDepthSteps(Rendered(box), 1, scene, steps, 0.015).Share(), 1.0);
  // Rendered a pixel off, the grown steps still take the outline.
  EXPECT_DOUBLE_EQ(OutlineOnDepthSteps(Rendered(box + cv::Point(1, 1)), 1, scene, steps, 0.015).Share(), 1.0);
  // A smaller box on the big box's face: its whole outline lies on the face, away from the steps.
  const cv::Rect inner(25, 25, 10, 10);
  const OutlineOnSteps flat = OutlineOnDepthSteps(Rendered(inner), 1, scene, steps, 0.015);
  EXPECT_EQ(flat.seen, 36);
  EXPECT_EQ(flat.on_step, 0);
  // Sampled every 2nd pixel (rendered at half the scene's size), the same.
  cv::Mat half;
  cv::resize(Rendered(box), half, cv::Size(40, 30), 0.0, 0.0, cv::INTER_NEAREST);
  EXPECT_DOUBLE_EQ(OutlineOnDepthSteps(half, 2, scene, steps, 0.015).Share(), 1.0);
}

TEST(SurfaceContinuation, IsZeroForABoxStandingOutAndOneForABoxLaidOnALargerFace) {
  const cv::Rect box(20, 20, 20, 20);
  const cv::Mat scene = TableWithBox(box);
  const OutlineContinuation standing = SurfaceContinuation(Rendered(box), 1, scene, 0.015);
  EXPECT_EQ(standing.tested, 76);  // every outline pixel: the face is one plane, the table 4 cm behind
  EXPECT_EQ(standing.continued, 0);
  cv::Mat half;
  cv::resize(Rendered(box), half, cv::Size(40, 30), 0.0, 0.0, cv::INTER_NEAREST);
  EXPECT_DOUBLE_EQ(SurfaceContinuation(half, 2, scene, 0.015).Share(), 0.0);  // sampled every 2nd pixel, the same
  // A smaller box laid on a big box's face, 20 pixels from its edges: the face runs on beyond its whole outline.
  const cv::Rect big(10, 10, 60, 40), small(30, 30, 20, 10);
  const cv::Mat face = TableWithBox(big);
  const OutlineContinuation laid = SurfaceContinuation(Rendered(small), 1, face, 0.015);
  EXPECT_EQ(laid.tested, 56);
  EXPECT_DOUBLE_EQ(laid.Share(), 1.0);
  cv::resize(Rendered(small), half, cv::Size(40, 30), 0.0, 0.0, cv::INTER_NEAREST);
  EXPECT_DOUBLE_EQ(SurfaceContinuation(half, 2, face, 0.015).Share(), 1.0);
  // Near one edge of the face (2 pixels off it), the outline on that side ends with the face.
  const OutlineContinuation edge = SurfaceContinuation(Rendered(cv::Rect(12, 30, 20, 10)), 1, face, 0.015);
  EXPECT_GT(edge.Share(), 0.5);
  EXPECT_LT(edge.Share(), 0.9);
}

TEST(OccludingContourSteps, IsOneForABoxStandingOutAndZeroLaidOnAFaceShiftedOntoTheTableOrBehindAnEdge) {
  const cv::Rect box(20, 20, 20, 20);
  const cv::Mat scene = TableWithBox(box);
  const OccludingContour standing = OccludingContourSteps(Rendered(box), 1, scene, cv::Mat(), 0.015);
  EXPECT_EQ(standing.seen, 76);  // every outline pixel, the table 4 cm behind all round
  EXPECT_EQ(standing.stepping_back, 76);
  cv::Mat half;  // sampled every 2nd pixel, the same
  cv::resize(Rendered(box), half, cv::Size(40, 30), 0.0, 0.0, cv::INTER_NEAREST);
  EXPECT_DOUBLE_EQ(OccludingContourSteps(half, 2, scene, cv::Mat(), 0.015).SteppingBack(), 1.0);
  // A pose 2 pixels off still finds the step within 3 samples beyond its outline, on its three sides on the face.
  const OccludingContour off = OccludingContourSteps(Rendered(box + cv::Point(2, 0)), 1, scene, cv::Mat(), 0.015);
  EXPECT_EQ(off.seen, 76);
  EXPECT_EQ(off.stepping_back, 76 - 22);  // the right column and the 2 pixels beside it lie on the table
  // A smaller box laid on the face: the face goes on beyond its outline.
  const OccludingContour laid = OccludingContourSteps(Rendered({25, 25, 10, 10}), 1, scene, cv::Mat(), 0.015);
  EXPECT_EQ(laid.seen, 36);
  EXPECT_EQ(laid.stepping_back, 0);
  // The box posed on the table beside the real one, at the table's depth: the table on both sides of its outline,
  // but where the real box lies beyond, the scene steps nearer, not back.
  cv::Mat on_table = cv::Mat::zeros(60, 80, CV_32FC1);
  on_table(cv::Rect(41, 20, 20, 20)).setTo(1.0F);
  const OccludingContour beside = OccludingContourSteps(on_table, 1, scene, cv::Mat(), 0.015);
  EXPECT_EQ(beside.seen, 76);
  EXPECT_EQ(beside.stepping_back, 0);
  // Missing depth beyond the outline (the sensor's shadow at an occluding edge) counts as stepping back.
  cv::Mat shadowed = scene.clone();
  shadowed(cv::Rect(40, 20, 2, 20)).setTo(0.0F);
  EXPECT_EQ(OccludingContourSteps(Rendered(box), 1, shadowed, cv::Mat(), 0.015).stepping_back, 76);
  OccludingContourOptions no_gap;
  no_gap.gap = 0;
  EXPECT_THROW(OccludingContourSteps(Rendered(box), 1, scene, cv::Mat(), 0.015, no_gap), InputError);
  EXPECT_THROW(OccludingContourSteps(Rendered(box), 0, scene, cv::Mat(), 0.015), InputError);
  EXPECT_THROW(OccludingContourSteps(Rendered(box), 1, scene, cv::Mat(30, 40, CV_32FC3), 0.015), InputError);
}

// The camera of the 80 x 60 test images: 100 pixels focal length, centred.
PinholeCamera TestCamera() {
  PinholeCamera camera;
  camera.fx = camera.fy = 100.0;
  camera.cx = 39.5;
  camera.cy = 29.5;
  camera.width = 80;
  camera.height = 60;
  return camera;
}

TEST(OccludingContourSteps, CountsACreaseWhereTheSurfaceTurnsWithoutAStep) {
  // The box's face stands on a table that comes towards the camera below it, 1 cm per pixel (1 cm at 1 m): no
  // depth step along the bottom edge, but the table turns 45 degrees away from the face's plane.
  const cv::Rect box(20, 20, 20, 20);
  cv::Mat scene = TableWithBox(box);
  for (int v = 40; v < scene.rows; ++v) scene.row(v).setTo(0.96F - 0.01F * static_cast<float>(v - 39));
  const cv::Mat normals = DepthNormals(scene, TestCamera(), 2, 0.03);
  const OccludingContour standing = OccludingContourSteps(Rendered(box), 1, scene, normals, 0.015);
  EXPECT_EQ(standing.seen, 76);
  EXPECT_EQ(standing.stepping_back, 76 - 20);  // all but the bottom row step back
  // The bottom row's crease is judged where the face's normal 3 samples inside is defined (2 pixels from its
  // sides): 16 of its 20 pixels.
  EXPECT_EQ(standing.creased, 16);
  EXPECT_EQ(OccludingContourSteps(Rendered(box), 1, scene, cv::Mat(), 0.015).creased, 0);  // without normals
  // A smaller box laid on the face: the face goes on, flat, beyond its outline.
  const OccludingContour laid = OccludingContourSteps(Rendered({25, 25, 10, 10}), 1, scene, normals, 0.015);
  EXPECT_EQ(laid.seen, 36);
  EXPECT_EQ(laid.stepping_back + laid.creased, 0);
}

TEST(DepthNormals, FaceTheCameraOnPlanesAndAreZeroAcrossSteps) {
  PinholeCamera camera = TestCamera();
  const cv::Mat scene = TableWithBox({20, 20, 20, 20});
  const cv::Mat normals = DepthNormals(scene, camera, 2, 0.01);
  // The table and the box face are fronto-parallel: (0, 0, -1), towards the camera.
  for (const cv::Point& p : {cv::Point(30, 30), cv::Point(10, 10), cv::Point(60, 50)}) {
    EXPECT_NEAR(normals.at<cv::Vec3f>(p)[2], -1.0F, 1e-5F) << p;
  }
  EXPECT_EQ(normals.at<cv::Vec3f>(30, 21), cv::Vec3f()) << "2 pixels reach across the box's left edge";
  EXPECT_EQ(normals.at<cv::Vec3f>(0, 0), cv::Vec3f()) << "no neighbours beyond the image";
  // A plane tilted about the vertical axis by 45 degrees: z grows by as much as x does.
  cv::Mat tilted(60, 80, CV_32FC1);
  for (int v = 0; v < tilted.rows; ++v) {
    for (int u = 0; u < tilted.cols; ++u) {
      // On the plane z = 1 + x: along the ray (u - cx) / fx, z = 1 / (1 - (u - cx) / fx).
      tilted.at<float>(v, u) = static_cast<float>(1.0 / (1.0 - (u - camera.cx) / camera.fx));
    }
  }
  const cv::Vec3f n = DepthNormals(tilted, camera, 2, 0.05).at<cv::Vec3f>(30, 40);
  EXPECT_NEAR(n[0], std::sqrt(0.5F), 1e-3F);
  EXPECT_NEAR(n[2], -std::sqrt(0.5F), 1e-3F);
  EXPECT_THROW(DepthNormals(scene, camera, 0, 0.01), InputError);
  camera.width = 40;
  EXPECT_THROW(DepthNormals(scene, camera, 2, 0.01), InputError);
}

TEST(SurfaceContinuation, TakesACreaseAsAnEndAndLeavesOutCurvesAndHiddenOutline) {
  // The box's face stands on a table that comes towards the camera below it: no depth step at the contact, but the
  // table turns away from the face's plane (2 mm per pixel).
  const cv::Rect box(20, 20, 20, 20);
  cv::Mat scene = TableWithBox(box);
  for (int v = 40; v < scene.rows; ++v) scene.row(v).setTo(0.96F - 0.002F * static_cast<float>(v - 39));
  const OutlineContinuation crease = SurfaceContinuation(Rendered(box), 1, scene, 0.015);
  EXPECT_EQ(crease.tested, 76);
  EXPECT_EQ(crease.continued, 0);
  // Within 4 mm of the face's plane the table would run on from it: 0.25 mm per pixel.
  for (int v = 40; v < scene.rows; ++v) scene.row(v).setTo(0.96F - 0.00025F * static_cast<float>(v - 39));
  const OutlineContinuation shallow = SurfaceContinuation(Rendered(box), 1, scene, 0.015);
  EXPECT_GE(shallow.continued, 20);  // the bottom row ...
  EXPECT_LE(shallow.continued, 30);  // ... and the lowest 5 of each side column, whose band reaches below the box
  // A face that is not one plane under the window decides nothing: a 5 mm ridge in every other column.
  cv::Mat ridged = TableWithBox(box);
  for (int u = box.x; u < box.x + box.width; u += 2) ridged(cv::Rect(u, box.y, 1, box.height)) -= 0.005F;
  EXPECT_EQ(SurfaceContinuation(Rendered(box), 1, ridged, 0.015).tested, 0);
  // Hidden outline (something 10 cm in front of all of it) is not judged.
  cv::Mat hidden(scene.size(), CV_32FC1, cv::Scalar(0.86F));
  EXPECT_EQ(SurfaceContinuation(Rendered(box), 1, hidden, 0.015).tested, 0);
}

TEST(SurfaceContinuation, RejectsImagesThatDoNotFitAndBadOptions) {
  const cv::Mat scene = TableWithBox(cv::Rect(20, 20, 20, 20));
  EXPECT_THROW(SurfaceContinuation(Rendered(cv::Rect(20, 20, 20, 20)), 2, scene, 0.015), InputError);
  cv::Mat millimetres;
  scene.convertTo(millimetres, CV_16UC1, 1000.0);
  EXPECT_THROW(SurfaceContinuation(Rendered(cv::Rect(20, 20, 20, 20)), 1, millimetres, 0.015), InputError);
  ContinuationOptions options;
  options.max_gap_px = options.window_px + 1;
  EXPECT_THROW(SurfaceContinuation(Rendered(cv::Rect(20, 20, 20, 20)), 1, scene, 0.015, options), InputError);
}

TEST(ContinuationFactor, FallsFromFreeOverFalloffAndIsOneWhenTooFewAreJudged) {
  EXPECT_DOUBLE_EQ(ContinuationFactor({100, 20}, 0.25, 0.25, 20), 1.0);
  EXPECT_DOUBLE_EQ(ContinuationFactor({100, 40}, 0.25, 0.25, 20), 1.0 - 0.15 / 0.25);
  EXPECT_DOUBLE_EQ(ContinuationFactor({100, 60}, 0.25, 0.25, 20), 0.0);
  EXPECT_DOUBLE_EQ(ContinuationFactor({10, 10}, 0.25, 0.25, 20), 1.0);   // too few judged
  EXPECT_DOUBLE_EQ(ContinuationFactor({100, 100}, 0.25, 0.0, 20), 1.0);  // no factor
}

TEST(OutlineOnDepthSteps, LeavesOutHiddenOutlineAndTheImageBorder) {
  const cv::Rect box(20, 20, 20, 20);
  cv::Mat scene = TableWithBox(box);
  const cv::Rect inner(25, 25, 10, 10);
  // Something 10 cm in front covers the table and the big box up to column 27, and so the small box's left column
  // and two pixels of its top and bottom rows: 14 of its 36 outline pixels, all near the new step (columns 25-30),
  // are hidden and not counted. Of the 22 seen, the 6 in columns 28-30 of its top and bottom rows lie on that step.
  cv::Mat hidden = scene.clone();
  hidden(cv::Rect(0, 0, 28, 60)).setTo(0.86F);
  const OutlineOnSteps partly = OutlineOnDepthSteps(Rendered(inner), 1, hidden, DepthSteps(hidden, 0.01, 2), 0.015);
  EXPECT_EQ(partly.seen, 22);
  EXPECT_EQ(partly.on_step, 6);
  // Nothing of it seen: 0.
  hidden.setTo(0.5F);
  EXPECT_EQ(OutlineOnDepthSteps(Rendered(inner), 1, hidden, DepthSteps(hidden, 0.01, 2), 0.015).seen, 0);
  // A box cut off by the image's left border: the border is not outline, the rest is on steps.
  const cv::Rect cut(0, 20, 10, 20);
  scene = TableWithBox(cut);
  EXPECT_DOUBLE_EQ(OutlineOnDepthSteps(Rendered(cut), 1, scene, DepthSteps(scene, 0.01, 2), 0.015).Share(), 1.0);
  // A box filling the image has no outline at all.
  const cv::Rect all(0, 0, 80, 60);
  scene = TableWithBox(all);
  EXPECT_EQ(OutlineOnDepthSteps(Rendered(all), 1, scene, DepthSteps(scene, 0.01, 2), 0.015).seen, 0);
}

TEST(ContourFactor, OneFromTheFreeShareZeroBelowTheFalloffAndOneWhenTooLittleOutlineIsSeen) {
  EXPECT_DOUBLE_EQ(ContourFactor({100, 30}, 0.3, 0.2, 20), 1.0);
  EXPECT_DOUBLE_EQ(ContourFactor({100, 90}, 0.3, 0.2, 20), 1.0);
  EXPECT_NEAR(ContourFactor({100, 20}, 0.3, 0.2, 20), 0.5, 1e-12);
  EXPECT_NEAR(ContourFactor({100, 10}, 0.3, 0.2, 20), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(ContourFactor({100, 0}, 0.3, 0.2, 20), 0.0);
  EXPECT_DOUBLE_EQ(ContourFactor({19, 0}, 0.3, 0.2, 20), 1.0);  // too little outline to tell
  EXPECT_DOUBLE_EQ(ContourFactor({0, 0}, 0.3, 0.2, 20), 1.0);
  EXPECT_DOUBLE_EQ(ContourFactor({100, 0}, 0.3, 0.0, 20), 1.0);  // no factor
}

// A grey image of `size` with a step from `low` to `high` grey levels at column (vertical: row) `at`.
cv::Mat Step(cv::Size size, int at, int low, int high, bool vertical = false) {
  cv::Mat image(size, CV_8UC1, cv::Scalar(low));
  if (vertical) {
    image.rowRange(at, size.height).setTo(high);
  } else {
    image.colRange(at, size.width).setTo(high);
  }
  return image;
}

std::vector<cv::Point> AllPixels(cv::Size size) {
  std::vector<cv::Point> pixels;
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) pixels.emplace_back(u, v);
  }
  return pixels;
}

TEST(CompareEdges, CountsTheModelsEdgePixelsAndFindsThemInTheSameStepOfAnyContrastOrSign) {
  const cv::Size size(20, 20);
  const cv::Mat model = GreyGradient(Step(size, 10, 50, 150));
  // A step of 100 grey levels gives |Sobel| 400 on the two columns beside it, 20 rows each, and 0 elsewhere.
  const EdgeAgreement same = CompareEdges(model, model, AllPixels(size));
  EXPECT_EQ(same.predicted, 40);
  EXPECT_EQ(same.shown, 40);
  EXPECT_DOUBLE_EQ(same.Share(), 1.0);
  // The scene's step is fainter (|Sobel| 4 x 10 = 40 >= weak 20) and dark to bright the other way: still shown.
  EXPECT_EQ(CompareEdges(model, GreyGradient(Step(size, 10, 120, 110)), AllPixels(size)).shown, 40);
  // Too faint (|Sobel| 4 x 4 = 16 < 20), one column off (the step's other column only), across it, or no step.
  EXPECT_EQ(CompareEdges(model, GreyGradient(Step(size, 10, 100, 104)), AllPixels(size)).shown, 0);
  EXPECT_EQ(CompareEdges(model, GreyGradient(Step(size, 11, 50, 150)), AllPixels(size)).shown, 20);
  EXPECT_EQ(CompareEdges(model, GreyGradient(Step(size, 10, 50, 150, true)), AllPixels(size)).shown, 0);
  EXPECT_EQ(CompareEdges(model, GreyGradient(Step(size, 10, 90, 90)), AllPixels(size)).shown, 0);
  // Only the given pixels count: the left column of the step.
  std::vector<cv::Point> left;
  for (int v = 0; v < size.height; ++v) left.emplace_back(9, v);
  EXPECT_EQ(CompareEdges(model, model, left).predicted, 20);
  // A model step below `strong` predicts nothing.
  EXPECT_EQ(CompareEdges(GreyGradient(Step(size, 10, 100, 110)), model, AllPixels(size)).predicted, 0);
}

TEST(CompareEdges, RejectsImagesThatDoNotFitAndPixelsOutside) {
  const cv::Mat gradient = GreyGradient(Step(cv::Size(20, 20), 10, 50, 150));
  EXPECT_THROW(CompareEdges(gradient, GreyGradient(Step(cv::Size(21, 20), 10, 50, 150)), {}), InputError);
  EXPECT_THROW(CompareEdges(gradient, cv::Mat(20, 20, CV_32FC1, cv::Scalar(0)), {}), InputError);
  EXPECT_THROW(CompareEdges(gradient, gradient, {cv::Point(20, 3)}), InputError);
  EXPECT_THROW(GreyGradient(cv::Mat(4, 4, CV_8UC3)), InputError);
  EdgeOptions options;
  options.min_cos = 1.5;
  EXPECT_THROW(CompareEdges(gradient, gradient, {}, options), InputError);
}

TEST(Appearance, WeighsColourAndEdgesWhenEnoughEdgesArePredicted) {
  const EdgeAgreement edges{100, 25};  // a quarter of 100 predicted edges shown
  EXPECT_DOUBLE_EQ(Appearance(0.64, edges, 0.5, 50), std::sqrt(0.64 * 0.25));
  EXPECT_DOUBLE_EQ(Appearance(0.64, edges, 1.0, 50), 0.25);
  EXPECT_DOUBLE_EQ(Appearance(0.64, edges, 0.0, 50), 0.64);   // no weight: colour alone
  EXPECT_DOUBLE_EQ(Appearance(0.64, edges, 0.5, 101), 0.64);  // too few edges to tell: colour alone
  EXPECT_DOUBLE_EQ(Appearance(0.64, EdgeAgreement{}, 0.5, 0), 0.64);
}

}  // namespace
}  // namespace ecv
