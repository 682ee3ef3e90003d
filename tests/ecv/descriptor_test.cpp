// ECV context descriptors and their matching: invariance, normalisation, constructed matches, and the
// correspondence score of a real view against itself.

#include <random>

#include <gtest/gtest.h>

#include "ecv/descriptor.h"
#include "ecv/matching.h"
#include "io/frame_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

// Random primitives in a 12 cm cube: positions, unit orientations, colours; both types.
std::vector<Primitive> RandomPrimitives(int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  std::normal_distribution<float> normal(0.0F, 1.0F);
  std::vector<Primitive> primitives(static_cast<size_t>(count));
  for (Primitive& p : primitives) {
    p.type = unit(random) < 0.3F ? PrimitiveType::kSegment : PrimitiveType::kTexlet;
    p.position = Eigen::Vector3f(unit(random), unit(random), unit(random)) * 0.12F + Eigen::Vector3f(0, 0, 0.8F);
    p.orientation = Eigen::Vector3f(normal(random), normal(random), normal(random)).normalized();
    p.color = Eigen::Vector3f(unit(random), unit(random), unit(random));
  }
  return primitives;
}

Eigen::Isometry3d SomeRigidMotion() {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  motion.linear() = Eigen::AngleAxisd(1.3, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  motion.translation() = Eigen::Vector3d(0.2, -0.1, 0.4);
  return motion;
}

std::vector<Primitive> Moved(std::vector<Primitive> primitives, const Eigen::Isometry3d& motion) {
  const Eigen::Isometry3f m = motion.cast<float>();
  for (Primitive& p : primitives) {
    p.position = m * p.position;
    p.orientation = m.linear() * p.orientation;
  }
  return primitives;
}

TEST(EcvDescriptor, InvariantToRigidMotionAndNormalised) {
  const std::vector<Primitive> primitives = RandomPrimitives(400, 1);
  for (const bool soft : {false, true}) {
    DescriptorOptions options;
    options.soft_binning = soft;
    options.hellinger = !soft;  // both forms of each option once
    const Descriptors original = ComputeDescriptors(primitives, options);
    const Descriptors moved = ComputeDescriptors(Moved(primitives, SomeRigidMotion()), options);
    ASSERT_EQ(original.primitive, moved.primitive);
    ASSERT_EQ(original.values.cols, kDescriptorSize);
    ASSERT_GT(original.values.rows, 390);
    // Histogram counts only move across bins when a cosine sits on a bin edge to float precision.
    EXPECT_LT(cv::norm(original.values, moved.values, cv::NORM_L1) / original.values.rows, 1e-3);
    for (int row = 0; row < original.values.rows; ++row) {
      for (int h = 0; h < 6; ++h) {
        const cv::Mat histogram = original.values.row(row).colRange(h * kDescriptorBins, (h + 1) * kDescriptorBins);
        // Each histogram sums to 1; stored as square roots (Hellinger), their squares do.
        const double sum = options.hellinger ? histogram.dot(histogram) : cv::sum(histogram)[0];
        ASSERT_NEAR(sum, 1.0, 1e-5) << "row " << row << " histogram " << h;
      }
    }
  }
}

TEST(EcvDescriptor, IsolatedPrimitivesGetNone) {
  std::vector<Primitive> primitives = RandomPrimitives(3, 2);
  primitives[0].position = {0, 0, 1};
  primitives[1].position = {0.01F, 0, 1};  // 1 cm from the first: a context of two
  primitives[2].position = {0.5F, 0, 1};   // alone
  const Descriptors descriptors = ComputeDescriptors(primitives);
  EXPECT_EQ(descriptors.primitive, (std::vector<int>{0, 1}));
  EXPECT_TRUE(ComputeDescriptors({}).primitive.empty());
  EXPECT_TRUE(ComputeDescriptors({primitives[2]}).primitive.empty());
}

TEST(EcvDescriptor, SegmentSignMattersOnlyWhenSigned) {
  std::vector<Primitive> primitives = RandomPrimitives(200, 3);
  std::vector<Primitive> flipped = primitives;
  for (Primitive& p : flipped) {
    if (p.type == PrimitiveType::kSegment) p.orientation = -p.orientation;
  }
  DescriptorOptions unsigned_options;
  unsigned_options.unsigned_segments = true;
  EXPECT_LT(cv::norm(ComputeDescriptors(primitives, unsigned_options).values,
                     ComputeDescriptors(flipped, unsigned_options).values, cv::NORM_L1),
            1e-3);
  EXPECT_GT(cv::norm(ComputeDescriptors(primitives).values, ComputeDescriptors(flipped).values, cv::NORM_L1), 1.0);
}

TEST(EcvMatching, FindsTheMovedCopyOfEachPrimitive) {
  const std::vector<Primitive> scene = RandomPrimitives(1000, 4);
  const Eigen::Isometry3d motion = SomeRigidMotion();
  const std::vector<Primitive> object = Moved(scene, motion.inverse());  // the same primitives, elsewhere
  const Descriptors scene_descriptors = ComputeDescriptors(scene), object_descriptors = ComputeDescriptors(object);
  for (const int exact_below : {100000, 10}) {  // exact, then approximate (randomised kd-trees)
    MatchOptions options;
    options.exact_below = exact_below;
    options.k = 2;
    const DescriptorMatcher matcher(scene, scene_descriptors, options);
    const std::vector<DescriptorMatch> matches = matcher.Match(object, object_descriptors);
    ASSERT_EQ(matches.size(), 2 * object_descriptors.primitive.size());
    int right = 0;
    for (const DescriptorMatch& match : matches) {
      if (match.rank != 0) continue;
      EXPECT_EQ(scene[static_cast<size_t>(match.train)].type, object[static_cast<size_t>(match.query)].type);
      right += match.train == match.query ? 1 : 0;
    }
    EXPECT_GT(right, 0.95 * static_cast<double>(object_descriptors.primitive.size())) << "exact_below " << exact_below;
    EXPECT_NEAR(ScoreCorrespondences(object, scene, matches, motion).Score(),
                static_cast<double>(right) / object_descriptors.primitive.size(), 1e-9);
  }
}

TEST(EcvMatching, RealViewAgainstItselfScoresOne) {
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"));
  const std::vector<Primitive> primitives = ExtractPrimitives(frame.rgbd).primitives;
  const Descriptors descriptors = ComputeDescriptors(primitives);
  ASSERT_GT(descriptors.primitive.size(), 1000U);
  const DescriptorMatcher matcher(primitives, descriptors);  // approximate: more than exact_below rows
  const CorrespondenceScore score = ScoreCorrespondences(primitives, primitives, matcher.Match(primitives, descriptors),
                                                         Eigen::Isometry3d::Identity());
  EXPECT_EQ(score.hypotheses, static_cast<int>(descriptors.primitive.size()));
  EXPECT_GT(score.Score(), 0.99);
  EXPECT_NEAR(TruePartnerFraction(primitives, descriptors.primitive, primitives, Eigen::Isometry3d::Identity()), 1.0,
              1e-12);
}

}  // namespace
}  // namespace ecv
