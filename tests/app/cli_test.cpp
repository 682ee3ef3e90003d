// The ecvpose tool as a user runs it: output, exit codes (0 ok, 1 bad input, 2 bad usage), JSON.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/version.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

TEST(Cli, VersionHelpAndUsageErrors) {
  const test::CommandResult version = test::RunCli("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_THAT(version.output, HasSubstr(std::string("ecvpose ") + kVersion));
  const test::CommandResult help = test::RunCli("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.output, HasSubstr("info"));
  EXPECT_EQ(test::RunCli("").exit_code, 2);
  const test::CommandResult unknown = test::RunCli("no-such-command");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output,
              AllOf(HasSubstr("unknown subcommand 'no-such-command'"), HasSubstr("info"), HasSubstr("recognize")));
  EXPECT_EQ(test::RunCli("info --no-such-flag").exit_code, 2);
  EXPECT_EQ(test::RunCli("info --unit inch x.obj").exit_code, 2);
  EXPECT_EQ(test::RunCli("info --help").exit_code, 0);
}

TEST(Cli, InfoDescribesARealFrameAndMesh) {
  const std::string frame = test::DataPath("ycbv_subset/Example-Scenes/0001/000001");
  const std::string mesh = test::DataPath("lmo_subset/data/bop/lmo/models/obj_000005.ply");
  test::TemporaryDirectory temporary;
  const std::string json_path = temporary.File("info.json");
  const test::CommandResult result = test::RunCli("info " + frame + " " + mesh + " --unit mm --out-json " + json_path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output,
              AllOf(HasSubstr("640 x 480"), HasSubstr("fx 1066.778"), HasSubstr("003_cracker_box"),
                    HasSubstr("22831 vertices"), HasSubstr("vertex colour"), HasSubstr("diameter  201.4 mm")));
  const nlohmann::json json = ReadJsonFile(json_path);
  ASSERT_EQ(json["items"].size(), 2U);
  EXPECT_EQ(json["items"][0]["ground_truth"].size(), 4U);
  EXPECT_NEAR(json["items"][0]["depth_valid_fraction"].get<double>(), 0.969, 0.001);
  EXPECT_NEAR(json["items"][1]["diameter_m"].get<double>(), 0.201404, 1e-5);
}

TEST(Cli, InfoReadsEveryFrameForm) {
  const std::string lmo = test::DataPath("lmo_subset/data/bop/lmo/test/000002");
  const std::string lmo_depth = test::DataPath("lmo_subset/SAM-6D/Data/Example/depth.png");
  const test::CommandResult bop = test::RunCli("info " + lmo + ":3 --depth " + lmo_depth);
  EXPECT_EQ(bop.exit_code, 0) << bop.output;
  EXPECT_THAT(bop.output, AllOf(HasSubstr("8 objects"), HasSubstr("obj_000012")));
  const test::CommandResult pcd =
      test::RunCli("info " + test::DataPath("pcl_milk_scene/test/milk_cartoon_all_small_clorox.pcd"));
  EXPECT_EQ(pcd.exit_code, 0) << pcd.output;
  EXPECT_THAT(pcd.output, HasSubstr("78.6 % valid"));
  const std::string prefix = test::DataPath("ycbv_subset/Example-Scenes/0000/000001");
  const test::CommandResult flags =
      test::RunCli("info --color " + prefix + "-color.png --depth " + prefix +
                   "-depth.png --depth-scale 10000 --camera 1066.778,1067.487,312.9869,241.3109");
  EXPECT_EQ(flags.exit_code, 0) << flags.output;
  EXPECT_THAT(flags.output, HasSubstr("cx 312.987"));
  EXPECT_THAT(flags.output, Not(HasSubstr("warning")));
  // YCB-Video's depth PNGs hold 10 000 values per metre; read with a scale of 1 the scene lies kilometres away.
  // The frame still loads (exit 0), with a warning naming the file.
  const test::CommandResult wrong_scale =
      test::RunCli("info --color " + prefix + "-color.png --depth " + prefix +
                   "-depth.png --depth-scale 1 --camera 1066.778,1067.487,312.9869,241.3109");
  EXPECT_EQ(wrong_scale.exit_code, 0) << wrong_scale.output;
  EXPECT_THAT(wrong_scale.output,
              AllOf(HasSubstr("warning: " + prefix + "-depth.png: median depth"), HasSubstr("depth scale")));
}

TEST(Cli, BadInputExitsWithOneAndNamesTheFile) {
  const test::CommandResult missing = test::RunCli("info /nonexistent/model.obj");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, AllOf(HasSubstr("/nonexistent/model.obj"), HasSubstr("no such file")));
  const std::string untextured = test::DataPath("ycbv_subset/models/003_cracker_box/textured_simple.obj");
  const test::CommandResult texture = test::RunCli("info " + untextured);
  EXPECT_EQ(texture.exit_code, 1);
  EXPECT_THAT(texture.output, HasSubstr("texture_map.png"));
  const test::CommandResult allowed = test::RunCli("info --allow-missing-textures " + untextured);
  EXPECT_EQ(allowed.exit_code, 0) << allowed.output;
  EXPECT_THAT(allowed.output,
              AllOf(HasSubstr("warning"), HasSubstr("texture_map.png"), HasSubstr("colour    vertex colour")));
}

// Counts, sizes and distances out of range are usage errors (exit 2) whose message names the flag and what it takes,
// before any file is read.
TEST(Cli, NumericFlagsOutOfRangeSayWhatTheyExpect) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"modeldb build x.obj --db x.sqlite --views 0", "--views: expected a whole number of at least 1, got 0"},
      {"modeldb build x.obj --db x.sqlite --threads 1.5", "--threads: expected a whole number from 1 to 256, got 1.5"},
      {"modeldb build x.obj --db x.sqlite --distance -1", "--distance: expected a number >= 0, got -1"},
      {"recognize --db x.sqlite frame --threads 0", "--threads: expected a whole number from 1 to 256, got 0"},
      {"register a b --threads many", "--threads: expected a whole number from 1 to 256, got many"},
      {"render x.obj --views 3 --out d --height 0", "--height: expected a whole number from 1 to 8192, got 0"},
      {"colorcal auto --db x.sqlite --model m frame --max-depth-difference 0",
       "--max-depth-difference: expected a number > 0, got 0"},
  };
  for (const auto& [arguments, message] : cases) {
    const test::CommandResult result = test::RunCli(arguments);
    EXPECT_EQ(result.exit_code, 2) << arguments << "\n" << result.output;
    EXPECT_THAT(result.output, HasSubstr(message)) << arguments;
  }
}

// A thread count the system cannot start is a usage error naming the flag and its range, not an abort.
TEST(Cli, ThreadCountsAreBounded) {
  for (const std::string command :
       {"modeldb build x.obj --db x.sqlite", "recognize --db x.sqlite frame", "register a b", "serve --db x.sqlite"}) {
    const test::CommandResult result = test::RunCli(command + " --threads 1000000");
    EXPECT_EQ(result.exit_code, 2) << command << "\n" << result.output;
    EXPECT_THAT(result.output, HasSubstr("--threads: expected a whole number from 1 to 256, got 1000000")) << command;
  }
}

}  // namespace
}  // namespace ecv
