// The ecvpose tool as a user runs it: output, exit codes (0 ok, 1 bad input, 2 bad usage), JSON.

#include <sys/stat.h>
#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>

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
      {"features frame --wavelength 1e9", "--wavelength: expected a number above 2 and at most 1024, got 1e9"},
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

std::string BigEndian32(uint32_t value) {
  return {static_cast<char>(value >> 24), static_cast<char>(value >> 16), static_cast<char>(value >> 8),
          static_cast<char>(value)};
}

// Writes a valid PNG of `width` x `height` zeros (grey, `bit_depth` bits): a file of a few hundred KB that decodes to
// width x height x bit_depth / 8 bytes.
void WriteZeroPng(const std::string& path, uint32_t width, uint32_t height, int bit_depth) {
  const auto chunk = [](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    const auto crc = static_cast<uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(body.data()), body.size()));
    return BigEndian32(static_cast<uint32_t>(data.size())) + body + BigEndian32(crc);
  };
  std::string compressed;
  z_stream stream{};
  ASSERT_EQ(deflateInit(&stream, 1), Z_OK);
  std::vector<unsigned char> row(1 + width * static_cast<uint32_t>(bit_depth / 8), 0);  // filter byte 0, then zeros
  std::vector<unsigned char> out(1 << 16);
  for (uint32_t y = 0; y <= height; ++y) {
    stream.next_in = row.data();
    stream.avail_in = y < height ? static_cast<uInt>(row.size()) : 0;
    do {
      stream.next_out = out.data();
      stream.avail_out = static_cast<uInt>(out.size());
      deflate(&stream, y < height ? Z_NO_FLUSH : Z_FINISH);
      compressed.append(reinterpret_cast<char*>(out.data()), out.size() - stream.avail_out);
    } while (stream.avail_out == 0);
  }
  deflateEnd(&stream);
  const std::string header = BigEndian32(width) + BigEndian32(height) + static_cast<char>(bit_depth) + '\0' + '\0' +
                             '\0' + '\0';  // grey, deflate, adaptive filtering, no interlace
  std::ofstream(path, std::ios::binary) << std::string("\x89PNG\r\n\x1a\n", 8) << chunk("IHDR", header)
                                        << chunk("IDAT", compressed) << chunk("IEND", "");
}

// Files that claim gigabytes or never end: each refused by name with exit 1 (not a hang: `timeout` would give 124),
// the command's peak memory (its processes' ru_maxrss, the mesh importer's included) under 1 GB.
TEST(Cli, HostileFilesAreRefusedByNameWithinMemoryAndTime) {
  namespace fs = std::filesystem;
  test::TemporaryDirectory temporary;
  const std::string frame = std::string(ECV_SOURCE_DIR) + "/models/frame/000001";
  // A valid 20000 x 20000 16-bit depth PNG: 2.4 GB once decoded and converted to metres.
  const std::string huge_depth = temporary.File("huge-depth.png"), json = temporary.File("huge.json");
  WriteZeroPng(huge_depth, 20000, 20000, 16);
  WriteJsonFile(json, {{"color", frame + "-color.png"},
                       {"depth", huge_depth},
                       {"depth_scale", 1000},
                       {"camera", {1066.778, 1067.487, 312.9869, 241.3109}}});
  // A GLB whose JSON chunk claims 0xFFFFFFF0 bytes.
  const std::string glb = temporary.File("chunk.glb");
  const std::string glb_body = std::string("\xF0\xFF\xFF\xFFJSON", 8) + R"({"asset":{"version":"2.0"}} )";
  std::ofstream(glb, std::ios::binary) << "glTF" << std::string("\2\0\0\0", 4)
                                       << static_cast<char>(12 + glb_body.size()) << std::string(3, '\0') << glb_body;
  const std::string zero = temporary.File("zero.ply"), fifo_mesh = temporary.File("fifo.obj");
  const std::string fifo_json = temporary.File("fifo.json");
  fs::create_symlink("/dev/zero", zero);
  ASSERT_EQ(mkfifo(fifo_mesh.c_str(), 0600), 0);
  ASSERT_EQ(mkfifo(fifo_json.c_str(), 0600), 0);

  const std::vector<std::pair<std::string, std::string>> cases = {
      {json, huge_depth + ": depth image: expected a PNG of 1 to 8192 pixels a side, got 20000 x 20000"},
      {glb, glb + ": GLB chunk 0 length: expected at most the 28 bytes left of the file's length, got 4294967280"},
      {zero, zero + ": mesh: expected a regular file, got a device"},
      {fifo_mesh, fifo_mesh + ": mesh: expected a regular file, got a named pipe (FIFO)"},
      {fifo_json, fifo_json + ": JSON file: expected a regular file, got a named pipe (FIFO)"},
  };
  for (const auto& [path, message] : cases) {
    const test::CommandResult result = test::RunCli("info " + path, "timeout 60 ");
    EXPECT_EQ(result.exit_code, 1) << path << "\n" << result.output;
    EXPECT_THAT(result.output, HasSubstr(message)) << path;
    EXPECT_GT(result.peak_rss_kb, 0) << path;
    EXPECT_LT(result.peak_rss_kb, 1 << 20) << path << ": KB at the peak";
  }
}

// Running out of memory while a frame is read (OpenCV's "Failed to allocate", std::bad_alloc) is an error naming the
// frame, exit 1. The address space is limited to what `info` needs on the demo frame plus about 450 MB: a frame of two
// 8192 x 8192 images, within every bound, needs about 600 MB more.
TEST(Cli, RunningOutOfMemoryNamesTheFrame) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space: ulimit -v cannot apply";
#endif
  test::TemporaryDirectory temporary;
  const std::string color = temporary.File("big-color.png"), depth = temporary.File("big-depth.png");
  const std::string json = temporary.File("big.json");
  WriteZeroPng(color, 8192, 8192, 8);
  WriteZeroPng(depth, 8192, 8192, 16);
  WriteJsonFile(json, {{"color", color}, {"depth", depth}, {"depth_scale", 1000}, {"camera", {500, 500, 4096, 4096}}});
  const std::string frame = std::string(ECV_SOURCE_DIR) + "/models/frame/000001";
  long needed_kb = 0;  // the address space `info` needs on a small frame, rounded up to 50 MB
  for (long limit_kb = 300 << 10; limit_kb <= 4L << 20 && needed_kb == 0; limit_kb += 50 << 10) {
    const std::string limit = "ulimit -v " + std::to_string(limit_kb) + "; ";
    if (test::RunCli("info " + frame, limit).exit_code == 0) needed_kb = limit_kb;
  }
  ASSERT_GT(needed_kb, 0) << "info did not run in 4 GB of address space";
  const test::CommandResult result =
      test::RunCli("info " + json, "ulimit -v " + std::to_string(needed_kb + (450 << 10)) + "; ");
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, AllOf(HasSubstr(json + ": memory: expected a file whose contents fit in the memory left, "
                                                    "got out of memory")))
      << result.output;
}

}  // namespace
}  // namespace ecv
