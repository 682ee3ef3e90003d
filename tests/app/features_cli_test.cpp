// `ecvpose features` as a user runs it: counts, picture, PLY and JSON agree with each other.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "io/ply_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::HasSubstr;

TEST(FeaturesCli, WritesOverlayPlyAndCounts) {
  test::TemporaryDirectory temporary;
  const std::string frame = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const test::CommandResult result =
      test::RunCli("features " + frame + " --overlay " + temporary.File("overlay.png") + " --ply " +
                   temporary.File("primitives.ply") + " --out-json " + temporary.File("counts.json"));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("segments"));

  const nlohmann::json counts = ReadJsonFile(temporary.File("counts.json"));
  const int segments = counts["segments"].get<int>(), texlets = counts["texlets"].get<int>();
  EXPECT_GT(segments, 100);
  EXPECT_GT(texlets, 100);
  EXPECT_EQ(counts["cells"].get<int>(),
            counts["homogeneous"].get<int>() + counts["edge_cells"].get<int>() + counts["texture_cells"].get<int>());

  const std::vector<Primitive> primitives = ReadPrimitivesPly(temporary.File("primitives.ply"));
  ASSERT_EQ(static_cast<int>(primitives.size()), segments + texlets);
  int ply_segments = 0;
  for (const Primitive& primitive : primitives) {
    ply_segments += primitive.type == PrimitiveType::kSegment ? 1 : 0;
    EXPECT_NEAR(primitive.orientation.norm(), 1.0F, 1e-4F);
    EXPECT_GT(primitive.position.z(), 0.5F);  // the table scene is 0.9 to 1.9 m away
  }
  EXPECT_EQ(ply_segments, segments);

  const cv::Mat overlay = cv::imread(temporary.File("overlay.png"));
  EXPECT_EQ(overlay.size(), cv::Size(640, 480));
}

TEST(FeaturesCli, BadOptionsAreUsageOrInputErrors) {
  const std::string frame = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  // A wavelength out of range is a usage error naming the flag and its range, before the frame is read (1e9 asked
  // OpenCV for 16 EB of padding).
  for (const std::string wavelength : {"1", "1e9"}) {
    const test::CommandResult result = test::RunCli("features " + frame + " --wavelength " + wavelength);
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_THAT(result.output,
                HasSubstr("--wavelength: expected a number above 2 and at most 1024, got " + wavelength));
  }
  EXPECT_EQ(test::RunCli("features " + frame + " --spacing abc").exit_code, 2);
  EXPECT_EQ(test::RunCli("features /nonexistent/0001/000001").exit_code, 1);
}

}  // namespace
}  // namespace ecv
