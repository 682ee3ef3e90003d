// ECV context descriptors and their matching: invariance, normalisation, constructed matches, and the
// correspondence score of a real view against itself.

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <tuple>

#include <gtest/gtest.h>

#include "core/error.h"
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
    p.magnitude = 0.02F + 0.3F * unit(random);
    p.image_orientation = 3.14159F * unit(random);
  }
  return primitives;
}

// The descriptor variants beyond the paper's (issue 5), each with one option changed from the field defaults, and
// the libraries' default (SourceShells: source pairs, 4 shells, 4.5 cm).
std::vector<std::pair<std::string, DescriptorOptions>> Variants() {
  std::vector<std::pair<std::string, DescriptorOptions>> variants(7);
  variants[0].first = "defaults";
  variants[1].first = "source pairs";
  variants[1].second.pairs = DescriptorPairs::kSource;
  variants[2].first = "closeness weight";
  variants[2].second.closeness_weight = 0.7;
  variants[3].first = "RGB log ratios";
  variants[3].second.appearance = DescriptorAppearance::kRgbLogRatio;
  variants[4].first = "monogenic";
  variants[4].second.appearance = DescriptorAppearance::kMonogenic;
  variants[5].first = "two shells";
  variants[5].second.shells = 2;
  variants[6] = {"source pairs in 4 shells (library default)", DescriptorOptions::SourceShells()};
  return variants;
}

// One histogram (0..5) of a descriptor row, as a vector.
std::vector<float> Histogram(const Descriptors& descriptors, int row, int h) {
  const float* values = descriptors.values.ptr<float>(row) + h * kDescriptorBins;
  return std::vector<float>(values, values + kDescriptorBins);
}

// A histogram with the given (bin, value) entries.
std::vector<float> Expected(std::initializer_list<std::pair<int, float>> entries) {
  std::vector<float> histogram(kDescriptorBins, 0.0F);
  for (const auto& [bin, value] : entries) histogram[static_cast<size_t>(bin)] = value;
  return histogram;
}

void ExpectHistogram(const std::vector<float>& actual, const std::vector<float>& expected, const std::string& what) {
  for (int bin = 0; bin < kDescriptorBins; ++bin) {
    EXPECT_NEAR(actual[static_cast<size_t>(bin)], expected[static_cast<size_t>(bin)], 1e-5) << what << " bin " << bin;
  }
}

// Hard bins and plain sums, so that each pair adds its weight to exactly one bin.
DescriptorOptions CountingOptions() {
  DescriptorOptions options;
  options.soft_binning = false;
  options.hellinger = false;
  return options;
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

TEST(EcvDescriptor, VariantsInvariantToRigidMotionAndNormalised) {
  const std::vector<Primitive> primitives = RandomPrimitives(300, 5);
  for (const auto& [name, options] : Variants()) {
    const Descriptors original = ComputeDescriptors(primitives, options);
    const Descriptors moved = ComputeDescriptors(Moved(primitives, SomeRigidMotion()), options);
    ASSERT_EQ(original.primitive, moved.primitive) << name;
    ASSERT_GT(original.values.rows, 280) << name;
    EXPECT_LT(cv::norm(original.values, moved.values, cv::NORM_L1) / original.values.rows, 1e-3) << name;
    for (int row = 0; row < original.values.rows; ++row) {
      for (int h = 0; h < 6; ++h) {
        const cv::Mat histogram = original.values.row(row).colRange(h * kDescriptorBins, (h + 1) * kDescriptorBins);
        ASSERT_NEAR(histogram.dot(histogram), 1.0, 1e-5) << name << " row " << row << " histogram " << h;
      }
    }
  }
}

TEST(EcvDescriptor, SameDescriptorsWithAnyNumberOfThreads) {
  std::vector<Primitive> primitives = RandomPrimitives(500, 7);
  primitives[3].position = {1.0F, 1.0F, 1.0F};  // isolated: its row is dropped whatever the thread that saw it
  for (const auto& [name, options] : Variants()) {
    const Descriptors serial = ComputeDescriptors(primitives, options);
    ASSERT_EQ(std::count(serial.primitive.begin(), serial.primitive.end(), 3), 0) << name;
    for (const int threads : {2, 3, 8}) {
      const Descriptors threaded = ComputeDescriptors(primitives, options, threads);
      ASSERT_EQ(threaded.primitive, serial.primitive) << name << ", " << threads << " threads";
      EXPECT_EQ(cv::norm(threaded.values, serial.values, cv::NORM_INF), 0.0) << name << ", " << threads << " threads";
    }
  }
  EXPECT_THROW(ComputeDescriptors(primitives, {}, 0), InputError);
}

TEST(EcvDescriptor, ASourceStepDescribesEveryNthPrimitiveAsTheFullRunDoes) {
  std::vector<Primitive> primitives = RandomPrimitives(500, 7);
  primitives[3].position = {1.0F, 1.0F, 1.0F};  // isolated, and a source with step 3
  for (const auto& [name, options] : Variants()) {
    const Descriptors all = ComputeDescriptors(primitives, options);
    for (const int step : {2, 3, 7}) {
      const Descriptors some = ComputeDescriptors(primitives, options, 2, step);
      std::vector<int> expected;
      for (size_t row = 0; row < all.primitive.size(); ++row) {
        if (all.primitive[row] % step != 0) continue;
        expected.push_back(all.primitive[row]);
        const int found = static_cast<int>(std::find(some.primitive.begin(), some.primitive.end(), all.primitive[row]) -
                                           some.primitive.begin());
        ASSERT_LT(found, some.values.rows) << name << ", step " << step;
        EXPECT_EQ(cv::norm(some.values.row(found), all.values.row(static_cast<int>(row)), cv::NORM_INF), 0.0)
            << name << ", step " << step << ", primitive " << all.primitive[row];
      }
      EXPECT_EQ(some.primitive, expected) << name << ", step " << step;
      EXPECT_EQ(some.values.rows, static_cast<int>((500 + step - 1) / step) - (step == 3 ? 1 : 0)) << name;
    }
  }
  EXPECT_THROW(ComputeDescriptors(primitives, {}, 1, 0), InputError);
}

TEST(EcvDescriptor, IsolatedPrimitivesGetNone) {
  std::vector<Primitive> primitives = RandomPrimitives(3, 2);
  primitives[0].position = {0, 0, 1};
  primitives[1].position = {0.01F, 0, 1};  // 1 cm from the first: a context of two
  primitives[2].position = {0.5F, 0, 1};   // alone
  for (const auto& [name, options] : Variants()) {
    const Descriptors descriptors = ComputeDescriptors(primitives, options);
    EXPECT_EQ(descriptors.primitive, (std::vector<int>{0, 1})) << name;
    EXPECT_TRUE(ComputeDescriptors({}, options).primitive.empty()) << name;
    EXPECT_TRUE(ComputeDescriptors({primitives[2]}, options).primitive.empty()) << name;
  }
}

// A source s with two neighbours 1 and 2 cm away whose cosines avoid bin edges (bins of 1/8 over [-1, 1]):
// pair {s, n1}: o_s.o_n1 = 0.8 (bin 14), o_s.d = 0.8 (14), o_n1.d = 1 (15);
// pair {s, n2}: o_s.o_n2 = 0.8 (14), o_s.d = 0.8 (14), o_n2.d = 0.28 (10);
// pair {n1, n2}: o_n1.o_n2 = 0.64 (13), o_n1.d = 0.18 (9), o_n2.d = -0.05 (7).
std::vector<Primitive> SourceWithTwoNeighbours() {
  std::vector<Primitive> primitives(3);
  const Eigen::Vector3f origin(0.1F, -0.05F, 0.9F);
  primitives[0].position = origin;
  primitives[0].orientation = Eigen::Vector3f(0.0F, 0.0F, 1.0F);
  primitives[1].position = origin + 0.01F * Eigen::Vector3f(0.6F, 0.0F, 0.8F);
  primitives[1].orientation = Eigen::Vector3f(0.6F, 0.0F, 0.8F);
  primitives[2].position = origin + 0.02F * Eigen::Vector3f(0.0F, -0.6F, 0.8F);
  primitives[2].orientation = Eigen::Vector3f(0.0F, 0.6F, 0.8F);
  return primitives;
}

TEST(EcvDescriptor, AllPairsAndSourcePairsFillTheirBins) {
  const std::vector<Primitive> primitives = SourceWithTwoNeighbours();
  DescriptorOptions options = CountingOptions();
  Descriptors all = ComputeDescriptors(primitives, options);
  ASSERT_EQ(all.primitive, (std::vector<int>{0, 1, 2}));
  const float third = 1.0F / 3.0F;
  ExpectHistogram(Histogram(all, 0, 0), Expected({{14, 2 * third}, {13, third}}), "all pairs R_G1");
  ExpectHistogram(Histogram(all, 0, 1), Expected({{14, 2 * third}, {9, third}}), "all pairs R_G2");
  ExpectHistogram(Histogram(all, 0, 2), Expected({{15, third}, {10, third}, {7, third}}), "all pairs R_G3");

  options.pairs = DescriptorPairs::kSource;  // only {s, n1} and {s, n2}
  const Descriptors source = ComputeDescriptors(primitives, options);
  ASSERT_EQ(source.primitive, (std::vector<int>{0, 1, 2}));
  ExpectHistogram(Histogram(source, 0, 0), Expected({{14, 1.0F}}), "source pairs R_G1");
  ExpectHistogram(Histogram(source, 0, 1), Expected({{14, 1.0F}}), "source pairs R_G2");
  ExpectHistogram(Histogram(source, 0, 2), Expected({{15, 0.5F}, {10, 0.5F}}), "source pairs R_G3");
  // Seen from n2, its pairs are {n2, s} and {n2, n1}: o_n2.o_s = 0.8 and o_n2.o_n1 = 0.64.
  ExpectHistogram(Histogram(source, 2, 0), Expected({{14, 0.5F}, {13, 0.5F}}), "source pairs of n2, R_G1");

  options.closeness_weight = 1.0;  // weights 1 - 0.01/0.025 = 0.6 for n1 and 1 - 0.02/0.025 = 0.2 for n2
  const Descriptors weighted = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(weighted, 0, 2), Expected({{15, 0.75F}, {10, 0.25F}}), "weighted source pairs R_G3");

  // Two shells split at 2.5 cm / sqrt 2 = 1.77 cm: n1 (1 cm) fills bins 0-7, n2 (2 cm) bins 8-15, 8 bins each
  // over [-1, 1]: 0.8 -> bin 7, 1 -> bin 7, 0.28 -> bin 5.
  options.closeness_weight = 0.0;
  options.shells = 2;
  const Descriptors shells = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(shells, 0, 0), Expected({{7, 0.5F}, {8 + 7, 0.5F}}), "two shells R_G1");
  ExpectHistogram(Histogram(shells, 0, 2), Expected({{7, 0.5F}, {8 + 5, 0.5F}}), "two shells R_G3");
  // Four shells of equal area, 4 bins each: (1 / 2.5)^2 = 0.16 -> shell 0 and (2 / 2.5)^2 = 0.64 -> shell 2
  // (by distance instead of area n1 would fall into shell 1); 0.8 -> bin 3.
  options.shells = 4;
  const Descriptors four = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(four, 0, 0), Expected({{3, 0.5F}, {2 * 4 + 3, 0.5F}}), "four shells R_G1");
}

TEST(EcvDescriptor, AppearanceVariantsFillTheirBins) {
  std::vector<Primitive> primitives(2);
  primitives[1].position = {0.01F, 0.0F, 0.0F};
  // Colours + 0.02 (the floor before logarithms): s (0.2, 0.4, 0.3), n (0.3, 0.1, 0.36): ratios 1.5, 0.25, 1.2.
  primitives[0].color = {0.18F, 0.38F, 0.28F};
  primitives[1].color = {0.28F, 0.08F, 0.34F};
  primitives[0].magnitude = 0.08F;  // + 0.02: ratio 3
  primitives[1].magnitude = 0.28F;
  primitives[0].image_orientation = 0.1F;  // 2.9 rad apart = -0.2416 rad modulo pi
  primitives[1].image_orientation = 3.0F;
  DescriptorOptions options = CountingOptions();

  // Differences of the source's context: 0.1, -0.3, 0.06 (the paper's R_Ak).
  Descriptors descriptors = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(descriptors, 0, 3), Expected({{8, 1.0F}}), "RGB difference R");
  ExpectHistogram(Histogram(descriptors, 0, 4), Expected({{5, 1.0F}}), "RGB difference G");
  ExpectHistogram(Histogram(descriptors, 0, 5), Expected({{8, 1.0F}}), "RGB difference B");

  // ln(ratio) / ln 4: 0.292 (bin 10), -1 (bin 0), 0.132 (bin 9).
  options.appearance = DescriptorAppearance::kRgbLogRatio;
  descriptors = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(descriptors, 0, 3), Expected({{10, 1.0F}}), "RGB log ratio R");
  ExpectHistogram(Histogram(descriptors, 0, 4), Expected({{0, 1.0F}}), "RGB log ratio G");
  ExpectHistogram(Histogram(descriptors, 0, 5), Expected({{9, 1.0F}}), "RGB log ratio B");

  // ln 3 / ln 8 = 0.528 (bin 12); -0.2416 / (pi / 2) = -0.154 (bin 6; unwrapped 1.85 would clamp to 15);
  // lightness with the floor 0.30 -> 0.2533: ln(0.8444) / ln 4 = -0.122 (bin 7).
  options.appearance = DescriptorAppearance::kMonogenic;
  descriptors = ComputeDescriptors(primitives, options);
  ExpectHistogram(Histogram(descriptors, 0, 3), Expected({{12, 1.0F}}), "monogenic magnitude ratio");
  ExpectHistogram(Histogram(descriptors, 0, 4), Expected({{6, 1.0F}}), "monogenic orientation difference");
  ExpectHistogram(Histogram(descriptors, 0, 5), Expected({{7, 1.0F}}), "monogenic lightness ratio");
  // Seen from n: the same pair reversed mirrors each value (bins 3, 9).
  ExpectHistogram(Histogram(descriptors, 1, 3), Expected({{3, 1.0F}}), "monogenic magnitude ratio, reversed");
  ExpectHistogram(Histogram(descriptors, 1, 4), Expected({{9, 1.0F}}), "monogenic orientation, reversed");
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

// A square of surface samples on the plane z = 0.8 (camera frame), 2 mm apart, normals facing the camera.
SurfaceSamples PlaneSurface() {
  SurfaceSamples surface;
  for (int i = -40; i <= 40; ++i) {
    for (int j = -40; j <= 40; ++j) {
      surface.points.emplace_back(0.002F * static_cast<float>(i), 0.002F * static_cast<float>(j), 0.8F);
      surface.normals.emplace_back(0.0F, 0.0F, -1.0F);
    }
  }
  return surface;
}

// On a plane every sample's normal is the local normal: each of the 2 x 4 regions' 6-bin histograms has all of its
// weight in the last bin (cosine 1), and the shape half, as square roots, has the squared length 3 x surface_weight.
TEST(SurfaceContext, APlaneFillsTheLastCosineBinOfEveryRegion) {
  std::vector<Primitive> primitives = RandomPrimitives(60, 9);
  for (Primitive& p : primitives) p.position = Eigen::Vector3f(p.position.x() - 0.06F, p.position.y() - 0.06F, 0.8F);
  const SurfaceSamples plane = PlaneSurface();
  DescriptorOptions options = DescriptorOptions::SurfaceShells();
  options.surface_weight = 1.5;
  const Descriptors descriptors = ComputeDescriptors(primitives, options, 1, 1, &plane);
  ASSERT_GT(descriptors.values.rows, 50);
  constexpr int kBins = 6;
  for (int row = 0; row < descriptors.values.rows; ++row) {
    const float* values = descriptors.values.ptr<float>(row);
    float squared = 0.0F;
    for (int k = 0; k < 3 * kDescriptorBins; ++k) {
      squared += values[k] * values[k];
      if (k % kBins != kBins - 1) {
        ASSERT_EQ(values[k], 0.0F) << "row " << row << " value " << k;
      }
    }
    EXPECT_NEAR(squared, 3.0 * 1.5, 1e-4) << "row " << row;
  }
}

// The surface context on a real frame: the primitives and the surface moved together give the same descriptors,
// the colour histograms still sum to 1, and the primitives' orientations play no part, so a segment's sign (which
// follows the camera's roll) cannot change them.
TEST(SurfaceContext, InvariantToRigidMotionAndBlindToSegmentSigns) {
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  const std::vector<Primitive> primitives = ExtractPrimitives(frame.rgbd).primitives;
  const SurfaceSamples surface = SampleSurface(frame.rgbd);
  ASSERT_GT(surface.size(), 5000U);
  const DescriptorOptions options = DescriptorOptions::SurfaceShells();
  const Descriptors original = ComputeDescriptors(primitives, options, 2, 7, &surface);
  ASSERT_GT(original.values.rows, 500);

  const Eigen::Isometry3d motion = SomeRigidMotion();
  const SurfaceSamples moved_surface = MovedSurface(surface, motion.cast<float>());
  const Descriptors moved = ComputeDescriptors(Moved(primitives, motion), options, 2, 7, &moved_surface);
  ASSERT_EQ(original.primitive, moved.primitive);
  // A row changes only where a sample sits on a region's edge to float precision, or where the surface is so
  // symmetric about the source that its frame's x axis is not defined.
  int same = 0;
  for (int row = 0; row < original.values.rows; ++row) {
    same += cv::norm(original.values.row(row), moved.values.row(row), cv::NORM_L1) < 1e-2 ? 1 : 0;
    for (int h = 3; h < 6; ++h) {
      const cv::Mat histogram = original.values.row(row).colRange(h * kDescriptorBins, (h + 1) * kDescriptorBins);
      ASSERT_NEAR(histogram.dot(histogram), 1.0, 1e-5) << "row " << row << " histogram " << h;
    }
  }
  EXPECT_GT(same, original.values.rows * 98 / 100);

  std::vector<Primitive> flipped = primitives;
  for (Primitive& p : flipped) p.orientation = -p.orientation;
  EXPECT_EQ(cv::norm(original.values, ComputeDescriptors(flipped, options, 2, 7, &surface).values, cv::NORM_L1), 0.0);
}

TEST(SurfaceContext, NeedsTheSurface) {
  const std::vector<Primitive> primitives = RandomPrimitives(50, 4);
  const DescriptorOptions options = DescriptorOptions::SurfaceShells();
  EXPECT_THROW(ComputeDescriptors(primitives, options), InputError);
  SurfaceSamples broken = PlaneSurface();
  broken.normals.pop_back();
  EXPECT_THROW(ComputeDescriptors(primitives, options, 1, 1, &broken), InputError);
  DescriptorOptions weightless = options;
  weightless.surface_weight = 0.0;
  const SurfaceSamples plane = PlaneSurface();
  EXPECT_THROW(ComputeDescriptors(primitives, weightless, 1, 1, &plane), InputError);
}

// The paper's definition written out pair by pair, with the defaults' soft bins and square roots: the
// neighbours within the radius by distance to the source, every pair {a, b} with a the closer, three cosines
// and three colour differences, each shared linearly between its two nearest of 16 bins over [-1, 1].
std::vector<float> ReferenceDescriptor(const std::vector<Primitive>& primitives, int source, double radius) {
  std::vector<std::pair<float, int>> neighbours;  // (distance, index)
  for (size_t i = 0; i < primitives.size(); ++i) {
    const float distance = (primitives[i].position - primitives[static_cast<size_t>(source)].position).norm();
    if (distance <= radius) neighbours.emplace_back(distance, static_cast<int>(i));
  }
  std::sort(neighbours.begin(), neighbours.end());
  std::vector<double> histograms(kDescriptorSize, 0.0);
  for (size_t i = 0; i < neighbours.size(); ++i) {
    for (size_t j = i + 1; j < neighbours.size(); ++j) {
      const Primitive& a = primitives[static_cast<size_t>(neighbours[i].second)];
      const Primitive& b = primitives[static_cast<size_t>(neighbours[j].second)];
      const Eigen::Vector3d d = (b.position - a.position).cast<double>().normalized();
      const Eigen::Vector3d oa = a.orientation.cast<double>(), ob = b.orientation.cast<double>();
      const Eigen::Vector3d color = (b.color - a.color).cast<double>();
      const double values[6] = {oa.dot(ob), oa.dot(d), ob.dot(d), color[0], color[1], color[2]};
      for (int k = 0; k < 6; ++k) {
        const double position = std::clamp((values[k] + 1.0) / 2.0 * kDescriptorBins - 0.5, 0.0, kDescriptorBins - 1.0);
        const int lower = std::min(static_cast<int>(position), kDescriptorBins - 2);
        histograms[static_cast<size_t>(k * kDescriptorBins + lower)] += 1.0 - (position - lower);
        histograms[static_cast<size_t>(k * kDescriptorBins + lower + 1)] += position - lower;
      }
    }
  }
  std::vector<float> descriptor(kDescriptorSize);
  for (int k = 0; k < 6; ++k) {
    const auto begin = histograms.begin() + k * kDescriptorBins;
    const double sum = std::accumulate(begin, begin + kDescriptorBins, 0.0);
    for (int bin = 0; bin < kDescriptorBins; ++bin) {
      descriptor[static_cast<size_t>(k * kDescriptorBins + bin)] = static_cast<float>(std::sqrt(begin[bin] / sum));
    }
  }
  return descriptor;
}

// The optimised computation (gathered members, precomputed bin scales, worker threads) against the reference
// on every 37th primitive of a real frame, whose densest contexts have a few hundred members.
TEST(EcvDescriptor, MatchesAPairByPairReferenceOnARealFrame) {
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"));
  const std::vector<Primitive> primitives = ExtractPrimitives(frame.rgbd).primitives;
  const DescriptorOptions options;
  const Descriptors descriptors = ComputeDescriptors(primitives, options, 2, 37);
  ASSERT_GT(descriptors.values.rows, 100);
  size_t largest_context = 0;
  for (int row = 0; row < descriptors.values.rows; ++row) {
    const int source = descriptors.primitive[static_cast<size_t>(row)];
    const std::vector<float> expected = ReferenceDescriptor(primitives, source, options.radius_m);
    const float* actual = descriptors.values.ptr<float>(row);
    // Float against double: the largest difference seen is 3e-6 (square roots of nearly empty bins).
    for (int i = 0; i < kDescriptorSize; ++i) {
      ASSERT_NEAR(actual[i], expected[static_cast<size_t>(i)], 1e-4) << "primitive " << source << ", value " << i;
    }
    size_t members = 0;
    for (const Primitive& p : primitives) {
      members += (p.position - primitives[static_cast<size_t>(source)].position).norm() <= options.radius_m ? 1 : 0;
    }
    largest_context = std::max(largest_context, members);
  }
  EXPECT_GT(largest_context, 100U);  // the dense contexts the optimisation is for were covered
}

TEST(EcvMatching, FindsTheMovedCopyOfEachPrimitive) {
  const std::vector<Primitive> scene = RandomPrimitives(1000, 4);
  const Eigen::Isometry3d motion = SomeRigidMotion();
  const std::vector<Primitive> object = Moved(scene, motion.inverse());  // the same primitives, elsewhere
  const Descriptors scene_descriptors = ComputeDescriptors(scene), object_descriptors = ComputeDescriptors(object);
  for (const MatchIndex index : {MatchIndex::kFlann, MatchIndex::kKdForest}) {
    for (const int exact_below : {100000, 10}) {  // exact, then approximate (randomised kd-trees)
      MatchOptions options;
      options.index = index;
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
      EXPECT_GT(right, 0.95 * static_cast<double>(object_descriptors.primitive.size()))
          << "index " << static_cast<int>(index) << ", exact_below " << exact_below;
      EXPECT_NEAR(ScoreCorrespondences(object, scene, matches, motion).Score(),
                  static_cast<double>(right) / object_descriptors.primitive.size(), 1e-9);
    }
  }
}

TEST(EcvMatching, RealViewAgainstItselfScoresOne) {
  const LoadedFrame frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0000/000001"));
  const std::vector<Primitive> primitives = ExtractPrimitives(frame.rgbd).primitives;
  const SurfaceSamples surface = SampleSurface(frame.rgbd);
  for (const bool surface_context : {false, true}) {
    SCOPED_TRACE(surface_context ? "surface context" : "field defaults");
    const Descriptors descriptors =
        surface_context ? ComputeDescriptors(primitives, DescriptorOptions::SurfaceShells(), 2, 1, &surface)
                        : ComputeDescriptors(primitives);
    ASSERT_GT(descriptors.primitive.size(), 1000U);
    const DescriptorMatcher matcher(primitives, descriptors);  // approximate: more than exact_below rows
    const CorrespondenceScore score = ScoreCorrespondences(
        primitives, primitives, matcher.Match(primitives, descriptors), Eigen::Isometry3d::Identity());
    EXPECT_EQ(score.hypotheses, static_cast<int>(descriptors.primitive.size()));
    EXPECT_GT(score.Score(), 0.99);
    EXPECT_NEAR(TruePartnerFraction(primitives, descriptors.primitive, primitives, Eigen::Isometry3d::Identity()), 1.0,
                1e-12);
  }
}

// The recognizer matches a view's ranking subset first and the other rows later, and needs the merged matches
// in the order of one Match call (its RANSAC draws samples by index).
TEST(EcvMatching, MatchingInPartsGivesTheSameMatchesInMatchOrder) {
  const LoadedFrame scene_frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  const LoadedFrame query_frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000019"));
  const std::vector<Primitive> scene = ExtractPrimitives(scene_frame.rgbd).primitives;
  const std::vector<Primitive> query = ExtractPrimitives(query_frame.rgbd).primitives;
  const Descriptors all = ComputeDescriptors(query);
  ASSERT_GT(all.values.rows, 1000);
  std::vector<int> rows(static_cast<size_t>(all.values.rows));
  std::iota(rows.begin(), rows.end(), 0);
  std::shuffle(rows.begin(), rows.end(), std::mt19937(3));
  const std::vector<int> first(rows.begin(), rows.begin() + 200), rest(rows.begin() + 200, rows.end());
  auto part = [&](std::vector<int> part_rows) {
    std::sort(part_rows.begin(), part_rows.end());
    Descriptors some;
    for (const int row : part_rows) {
      some.values.push_back(all.values.row(row));
      some.primitive.push_back(all.primitive[static_cast<size_t>(row)]);
    }
    return some;
  };
  for (const MatchIndex index : {MatchIndex::kFlann, MatchIndex::kKdForest}) {
    for (const bool structure_specific : {true, false}) {
      MatchOptions options;
      options.index = index;
      options.structure_specific = structure_specific;
      options.k = 2;
      const DescriptorMatcher matcher(scene, ComputeDescriptors(scene), options);  // approximate: > exact_below rows
      const std::vector<DescriptorMatch> whole = matcher.Match(query, all);
      std::vector<DescriptorMatch> merged = matcher.Match(query, part(rest));
      const std::vector<DescriptorMatch> ranked = matcher.Match(query, part(first));
      merged.insert(merged.end(), ranked.begin(), ranked.end());
      std::stable_sort(merged.begin(), merged.end(), [&](const DescriptorMatch& a, const DescriptorMatch& b) {
        return MatchOrderLess(query, structure_specific, a.query, b.query);
      });
      ASSERT_EQ(merged.size(), whole.size()) << "structure_specific " << structure_specific;
      for (size_t i = 0; i < whole.size(); ++i) {
        ASSERT_EQ(std::tie(merged[i].query, merged[i].train, merged[i].rank),
                  std::tie(whole[i].query, whole[i].train, whole[i].rank))
            << "match " << i << ", index " << static_cast<int>(index) << ", structure_specific " << structure_specific;
        ASSERT_EQ(merged[i].distance, whole[i].distance);
      }
    }
  }
}

// The recognizer ranks views with fewer checks per query than it matches with: a call's `checks` replaces the
// options' for that call only, and as many checks as rows is an exact search.
TEST(EcvMatching, ChecksOfOneCallReplaceTheOptionsForThatCall) {
  const LoadedFrame scene_frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000001"));
  const LoadedFrame query_frame = LoadYcbvFrame(test::DataPath("ycbv_subset/Example-Scenes/0001/000019"));
  const std::vector<Primitive> scene = ExtractPrimitives(scene_frame.rgbd).primitives;
  const std::vector<Primitive> query = ExtractPrimitives(query_frame.rgbd).primitives;
  const Descriptors scene_descriptors = ComputeDescriptors(scene), query_descriptors = ComputeDescriptors(query);
  ASSERT_GT(scene_descriptors.values.rows, 1000);
  auto same = [](const std::vector<DescriptorMatch>& a, const std::vector<DescriptorMatch>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i) {
      if (std::tie(a[i].query, a[i].train, a[i].distance) != std::tie(b[i].query, b[i].train, b[i].distance)) {
        return false;
      }
    }
    return true;
  };
  MatchOptions options;  // the kd-forest, 128 checks
  MatchOptions fewer = options;
  fewer.checks = 32;
  MatchOptions exact = options;
  exact.exact_below = scene_descriptors.values.rows + 1;
  const DescriptorMatcher matcher(scene, scene_descriptors, options);
  const std::vector<DescriptorMatch> default_checks = matcher.Match(query, query_descriptors);
  const std::vector<DescriptorMatch> few_checks = matcher.Match(query, query_descriptors, 32);
  EXPECT_TRUE(same(few_checks, DescriptorMatcher(scene, scene_descriptors, fewer).Match(query, query_descriptors)));
  EXPECT_FALSE(same(few_checks, default_checks));
  EXPECT_TRUE(same(matcher.Match(query, query_descriptors), default_checks));  // the options again, after the call
  EXPECT_TRUE(same(matcher.Match(query, query_descriptors, scene_descriptors.values.rows),
                   DescriptorMatcher(scene, scene_descriptors, exact).Match(query, query_descriptors)));
  // Fewer checks find the exact neighbour less often.
  const std::vector<DescriptorMatch> exact_matches =
      DescriptorMatcher(scene, scene_descriptors, exact).Match(query, query_descriptors);
  auto exact_share = [&](const std::vector<DescriptorMatch>& matches) {
    int found = 0;
    for (size_t i = 0; i < matches.size(); ++i) found += matches[i].train == exact_matches[i].train ? 1 : 0;
    return static_cast<double>(found) / static_cast<double>(matches.size());
  };
  EXPECT_LT(exact_share(few_checks), exact_share(default_checks));
}

}  // namespace
}  // namespace ecv
