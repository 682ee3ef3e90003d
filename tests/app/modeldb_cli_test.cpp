// `ecvpose modeldb` as a user runs it: a library of two demo meshes built by one process and read back by
// others bit for bit; list, info, remove, replace, verify, export; a bad mesh in a directory; a read-only
// location; files that are not libraries, or of another schema version.

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/ply_io.h"
#include "io/pose_io.h"
#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"
#include "modeldb/modeldb_test_util.h"
#include "modeldb/sql.h"
#include "support/test_data.h"

namespace ecv {
namespace {

namespace fs = std::filesystem;
using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::Not;

const char* const kModels[] = {"003_cracker_box", "006_mustard_bottle"};
constexpr int kViews = 3;

// The flags of a quick build: few views of half the YCB-Video camera.
std::string QuickFlags(int views = kViews) {
  const PinholeCamera c = test::SmallCamera();
  char camera[128];
  std::snprintf(camera, sizeof(camera), "%.17g,%.17g,%.17g,%.17g", c.fx, c.fy, c.cx, c.cy);
  return " --views " + std::to_string(views) + " --size 320x240 --camera " + camera;
}

ModelBuildOptions QuickOptions(int views = kViews) {
  ModelBuildOptions options;
  options.sampling.num_views = views;
  options.camera = test::SmallCamera();
  return options;
}

// A directory with links to model folders of the demo meshes.
void LinkModels(const fs::path& directory, const std::vector<std::string>& names) {
  fs::create_directories(directory);
  for (const std::string& name : names)
    fs::create_directory_symlink(test::DemoMeshDirectory() + "/" + name, directory / name);
}

// Runs ecvpose with `arguments`, as an unprivileged user when we are root (so that file permissions hold).
// A copy of the ecvpose binary, its own libraries and the mesh importer program beside them in a folder every user can
// read: the unprivileged user may not reach the build tree (a checkout under /root, or in a private folder). The shell
// command that runs the copy.
std::string CliCopyForEveryone() {
  static test::TemporaryDirectory folder;
  static const std::string command = [] {
    const fs::path bin = folder.path();
    const auto everyone = fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                          fs::perms::others_read | fs::perms::others_exec;
    const fs::path lib = bin / "lib";
    fs::create_directories(lib / "ecvpose");
    fs::copy_file(ECV_CLI_PATH, bin / "ecvpose", fs::copy_options::overwrite_existing);
    FILE* ldd = popen(("ldd " + std::string(ECV_CLI_PATH)).c_str(), "r");
    char line[4096];
    while (ldd != nullptr && std::fgets(line, sizeof(line), ldd) != nullptr) {
      std::istringstream words(line);
      std::string name, arrow, path;
      words >> name >> arrow >> path;  // "libecv_core.so.0 => /path/libecv_core.so.0 (0x...)"
      if (name.rfind("libecv_", 0) == 0 && arrow == "=>") {
        fs::copy_file(path, lib / name, fs::copy_options::overwrite_existing);
        if (name.rfind("libecv_core", 0) == 0) {
          const fs::path importer = fs::path(path).parent_path() / "ecvpose" / "ecvpose-mesh-import";
          fs::copy_file(importer, lib / "ecvpose" / importer.filename(), fs::copy_options::overwrite_existing);
        }
      }
    }
    if (ldd != nullptr) pclose(ldd);
    for (const auto& entry : fs::recursive_directory_iterator(bin)) fs::permissions(entry.path(), everyone);
    fs::permissions(bin, everyone);
    return "env LD_LIBRARY_PATH=" + lib.string() + " " + (bin / "ecvpose").string();
  }();
  return command;
}

// Runs the CLI as user nobody (when we are root) from a copy every user can read.
test::CommandResult RunCliUnprivileged(const std::string& arguments) {
  if (geteuid() != 0) return test::RunCli(arguments);
  return test::RunCommand("setpriv --reuid=65534 --regid=65534 --clear-groups " + CliCopyForEveryone() + " " +
                          arguments);
}

// One library built by the CLI, shared by the tests (each works on its own copy when it changes it).
class ModeldbCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new test::TemporaryDirectory();
    LinkModels(directory_->path() / "meshes", {kModels[0], kModels[1]});
    library_ = directory_->File("lib.sqlite");
    build_ = new test::CommandResult(
        test::RunCli("modeldb build " + (directory_->path() / "meshes").string() + " --db " + library_ + QuickFlags()));
  }
  static void TearDownTestSuite() {
    delete build_;
    delete directory_;
  }
  // A copy of the shared library that a test may change.
  std::string CopyOfLibrary() {
    const std::string copy = scratch_.File("copy.sqlite");
    fs::copy_file(library_, copy);
    return copy;
  }
  static test::TemporaryDirectory* directory_;
  static std::string library_;
  static test::CommandResult* build_;
  test::TemporaryDirectory scratch_;
};
test::TemporaryDirectory* ModeldbCli::directory_ = nullptr;
std::string ModeldbCli::library_;
test::CommandResult* ModeldbCli::build_ = nullptr;

TEST_F(ModeldbCli, BuildsTwoModelsThatOtherProcessesReadBackBitForBit) {
  ASSERT_EQ(build_->exit_code, 0) << build_->output;
  EXPECT_THAT(build_->output,
              AllOf(HasSubstr("[1/2] 003_cracker_box: view 1/3:"), HasSubstr("[2/2] 006_mustard_bottle"),
                    HasSubstr("stored 3 views"), HasSubstr("built 2 of 2 models")));
  // This process reads what the CLI process wrote and compares it with its own build of the same meshes.
  const std::vector<StoredModel> stored = ModelDatabase(library_, OpenMode::kReadOnly).LoadModels();
  ASSERT_EQ(stored.size(), 2U);
  Renderer renderer;
  for (size_t i = 0; i < 2; ++i) {
    const std::string folder = test::DemoMeshDirectory() + "/" + kModels[i];
    ModelSource source;
    source.name = kModels[i];
    source.mesh_path = folder + "/" + kModels[i] + ".obj";
    source.object_from_mesh = ReadPoseFile(folder + "/object_from_mesh.json", "object_from_mesh");
    const ModelRecord expected = BuildModel(source, QuickOptions(), renderer).record;
    const ModelRecord& record = stored[i].record;
    EXPECT_EQ(record.name, kModels[i]);
    EXPECT_TRUE(record.object_from_mesh.isApprox(source.object_from_mesh, 1e-12)) << "pose file not picked up";
    EXPECT_EQ(test::CompareViews(expected.views, record.views), "") << kModels[i];

    // And a third process (the CLI again) reports the same counts and descriptor digest.
    const test::CommandResult info =
        test::RunCli("modeldb info " + std::string(kModels[i]) + " --json --db " + library_);
    ASSERT_EQ(info.exit_code, 0) << info.output;
    const nlohmann::json json = nlohmann::json::parse(info.output);
    EXPECT_EQ(json["views"], kViews);
    EXPECT_EQ(json["primitives"], expected.NumPrimitives());
    EXPECT_EQ(json["descriptors"], expected.NumDescriptors());
    EXPECT_EQ(json["descriptor_sha256"], expected.DescriptorSha256());
    EXPECT_EQ(json["mesh_sha256"], expected.mesh_sha256);
  }
  const test::CommandResult verify = test::RunCli("modeldb verify --db " + library_);
  EXPECT_EQ(verify.exit_code, 0) << verify.output;
  EXPECT_THAT(verify.output, AllOf(HasSubstr("2 models, 6 views"), HasSubstr("\nok")));
}

TEST_F(ModeldbCli, ListsAndExportsPrimitivesInTheObjectFrame) {
  const test::CommandResult list = test::RunCli("modeldb list --db " + library_);
  ASSERT_EQ(list.exit_code, 0) << list.output;
  EXPECT_THAT(list.output, AllOf(HasSubstr("2 models"), HasSubstr("003_cracker_box"), HasSubstr("006_mustard_bottle"),
                                 HasSubstr("stored_MB"), HasSubstr("stored values")));
  // Each model's stored bytes: its descriptors, primitives, mesh and point pair points; together most of the file.
  const nlohmann::json listed = nlohmann::json::parse(test::RunCli("modeldb list --json --db " + library_).output);
  long long stored = 0;
  for (const nlohmann::json& model : listed) {
    const long long points = model["point_pairs"].is_null() ? 0 : model["point_pairs"]["points"].get<long long>();
    EXPECT_EQ(model["stored_bytes"].get<long long>(), model["descriptors"].get<long long>() * 384 +
                                                          model["primitives"].get<long long>() * 104 +
                                                          model["stored_mesh_bytes"].get<long long>() + points * 24)
        << model["name"];
    stored += model["stored_bytes"].get<long long>();
  }
  const auto file_bytes = static_cast<long long>(fs::file_size(library_));
  EXPECT_LT(stored, file_bytes);
  EXPECT_GT(stored, file_bytes / 2) << "the values are most of the file";

  const std::string ply = scratch_.File("box.ply");
  const test::CommandResult exported =
      test::RunCli("modeldb export 003_cracker_box --db " + library_ + " --ply " + ply);
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  const std::vector<Primitive> written = ReadPrimitivesPly(ply);
  const ModelRecord record = ModelDatabase(library_, OpenMode::kReadOnly).LoadModels({"003_cracker_box"}).at(0).record;
  ASSERT_EQ(written.size(), static_cast<size_t>(record.NumPrimitives()));
  size_t i = 0;
  for (const ModelView& view : record.views) {
    for (const Primitive& p : view.primitives) {
      EXPECT_EQ(written[i].position, p.position);
      EXPECT_EQ(written[i].type, p.type);
      const float red = p.type == PrimitiveType::kSegment ? 1.0F : 0.1F;
      EXPECT_NEAR(written[i].color.x(), red, 0.01) << "coloured by type";
      ++i;
    }
  }
  const test::CommandResult one_view =
      test::RunCli("modeldb export 003_cracker_box --view 1 --db " + library_ + " --ply " + ply);
  ASSERT_EQ(one_view.exit_code, 0) << one_view.output;
  EXPECT_EQ(ReadPrimitivesPly(ply).size(), record.views[1].primitives.size());
}

TEST_F(ModeldbCli, RemovesAndReplacesModels) {
  const std::string library = CopyOfLibrary();
  const test::CommandResult removed = test::RunCli("modeldb remove 003_cracker_box --db " + library);
  ASSERT_EQ(removed.exit_code, 0) << removed.output;
  const test::CommandResult again = test::RunCli("modeldb remove 003_cracker_box --db " + library);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_THAT(again.output, HasSubstr("no model \"003_cracker_box\""));
  EXPECT_THAT(test::RunCli("modeldb list --db " + library).output,
              AllOf(HasSubstr("1 models"), Not(HasSubstr("003_cracker_box"))));

  const std::string mustard = test::DemoMeshDirectory() + "/006_mustard_bottle/006_mustard_bottle.obj";
  const test::CommandResult replaced = test::RunCli("modeldb build " + mustard + " --db " + library + QuickFlags(2));
  ASSERT_EQ(replaced.exit_code, 0) << replaced.output;
  EXPECT_THAT(replaced.output, HasSubstr("replaced the earlier model"));
  const ModelDatabase database(library, OpenMode::kReadOnly);
  ASSERT_EQ(database.ListModels().size(), 1U);
  EXPECT_EQ(database.FindModel("006_mustard_bottle")->num_views, 2);
  EXPECT_TRUE(database.Verify().ok());
}

TEST_F(ModeldbCli, ReportsABadMeshInADirectoryAndBuildsTheRest) {
  const fs::path meshes = scratch_.path() / "meshes";
  LinkModels(meshes, {kModels[1]});
  fs::create_directories(meshes / "no_mesh");
  fs::create_directories(meshes / "garbage");
  std::ofstream(meshes / "garbage" / "garbage.obj") << "this is not a mesh\n";
  const std::string library = scratch_.File("lib.sqlite");
  const test::CommandResult result =
      test::RunCli("modeldb build " + meshes.string() + " --db " + library + QuickFlags(1));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, AllOf(HasSubstr("no_mesh: expected a mesh file no_mesh.obj"), HasSubstr("garbage: FAILED"),
                                   HasSubstr("built 1 of 3 models")));
  const std::vector<ModelSummary> models = ModelDatabase(library, OpenMode::kReadOnly).ListModels();
  ASSERT_EQ(models.size(), 1U);
  EXPECT_EQ(models[0].name, "006_mustard_bottle");
}

// A texture whose PNG header claims 60000 x 60000 pixels (decoding it stopped the whole build with an OpenCV
// assertion that named no file) is reported by name before it is decoded, and the other meshes are built; exit 1.
TEST_F(ModeldbCli, ATextureOfAnImpossibleSizeIsReportedAndTheRestBuilt) {
  const fs::path meshes = scratch_.path() / "meshes";
  LinkModels(meshes, {kModels[1]});
  const fs::path folder = meshes / "000_huge_texture";  // first in name order: the build goes on after it
  fs::create_directories(folder);
  std::ofstream(folder / "000_huge_texture.obj") << "mtllib skin.mtl\nv 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nvt 0 0\nvt 1 0\n"
                                                    "vt 0 1\nusemtl skin\nf 1/1 2/2 3/3\n";
  std::ofstream(folder / "skin.mtl") << "newmtl skin\nmap_Kd skin.png\n";
  std::string png = std::string("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR", 16);
  for (int side = 0; side < 2; ++side) png += std::string("\0\0\xea\x60", 4);  // 60000, big-endian
  png += std::string("\x08\x02\0\0\0\0\0\0\0", 9);                             // 8-bit RGB; CRC, data left out
  std::ofstream(folder / "skin.png", std::ios::binary) << png;
  const std::string library = scratch_.File("lib.sqlite");
  const test::CommandResult result =
      test::RunCli("modeldb build " + meshes.string() + " --db " + library + QuickFlags(1));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, AllOf(HasSubstr("000_huge_texture: FAILED: " + (folder / "skin.png").string() +
                                             ": texture: expected a PNG of 1 to 8192 pixels a side, got 60000 x 60000"),
                                   HasSubstr("built 1 of 2 models"), Not(HasSubstr("OpenCV"))));
  const std::vector<ModelSummary> models = ModelDatabase(library, OpenMode::kReadOnly).ListModels();
  ASSERT_EQ(models.size(), 1U);
  EXPECT_EQ(models[0].name, "006_mustard_bottle");
}

// The malformed PLYs that crashed the mesh importer: each reported, naming the file, and the rest of the directory
// built.
TEST_F(ModeldbCli, MalformedPlysAreReportedAndTheRestBuilt) {
  const fs::path meshes = scratch_.path() / "meshes";
  LinkModels(meshes, {kModels[1]});
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  fs::create_directories(meshes / "index");
  std::ofstream(meshes / "index" / "index.ply")
      << header << "0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n3 0 1 2\n3 0 1 4000000\n";
  fs::create_directories(meshes / "short");
  std::ofstream(meshes / "short" / "short.ply") << header << "0 0 0\n0.1 0 0\n";
  const std::string library = scratch_.File("lib.sqlite");
  const test::CommandResult result =
      test::RunCli("modeldb build " + meshes.string() + " --db " + library + QuickFlags(1));
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, AllOf(HasSubstr("index.ply: face 1"), HasSubstr("short.ply: vertex 2"),
                                   HasSubstr("built 1 of 3 models")));
  EXPECT_EQ(ModelDatabase(library, OpenMode::kReadOnly).ListModels().size(), 1U);
}

// A mesh in the wrong unit (a box 2 m across written in millimetres and read as metres: 2 km) is refused before any
// view is rendered, naming --unit; so is one too small to see.
TEST_F(ModeldbCli, AMeshOfAnImplausibleSizeNamesTheUnit) {
  auto box = [&](const std::string& name, const std::string& side) {
    const std::string path = scratch_.File(name);
    std::ofstream(path) << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
                        << "0 0 0\n"
                        << side << " 0 0\n0 " << side << " 0\n0 0 " << side << "\n3 0 1 2\n3 0 2 3\n";
    return path;
  };
  const std::string library = scratch_.File("unit.sqlite");
  for (const std::string& mesh : {box("huge.ply", "2000"), box("tiny.ply", "0.0002")}) {
    const test::CommandResult result = test::RunCli("modeldb build " + mesh + " --db " + library + QuickFlags(1));
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_THAT(result.output, AllOf(HasSubstr(mesh), HasSubstr("--unit"), Not(HasSubstr("view 1/"))));
  }
}

// Meshes with no relief for point pairs (one triangle, a flat square) are stored without point pair points, each
// named in a warning, exit 0; `--no-ppf` stores none; `list` tells the three apart, and `recognize --hypotheses ppf`
// names the models it has no point pairs for.
TEST_F(ModeldbCli, MeshesWithoutReliefAreStoredWithoutPointPairsAndNamed) {
  const std::string triangle = scratch_.File("triangle.obj"), square = scratch_.File("square.obj");
  std::ofstream(triangle) << "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n";
  std::ofstream(square) << "v 0 0 0\nv 0.1 0 0\nv 0.1 0.1 0\nv 0 0.1 0\nf 1 2 3\nf 1 3 4\n";
  const std::string library = scratch_.File("flat.sqlite");
  const test::CommandResult build =
      test::RunCli("modeldb build " + triangle + " " + square + " --db " + library + QuickFlags(4));
  EXPECT_EQ(build.exit_code, 0) << build.output;
  for (const std::string& mesh : {triangle, square}) {
    EXPECT_THAT(build.output, HasSubstr("warning: " + mesh + ": no point pair points")) << build.output;
  }
  const std::string mustard = test::DemoMeshDirectory() + "/006_mustard_bottle";
  const test::CommandResult skipped =
      test::RunCli("modeldb build " + mustard + " --no-ppf --db " + library + QuickFlags(1));
  EXPECT_EQ(skipped.exit_code, 0) << skipped.output;

  std::map<std::string, int> points;
  for (const ModelSummary& model : ModelDatabase(library, OpenMode::kReadOnly).ListModels()) {
    points[model.name] = model.point_pair_points;
    if (model.point_pair_points == 0) {
      EXPECT_THAT(model.point_pair_refusal, HasSubstr("relief"));
    }
  }
  EXPECT_EQ(points, (std::map<std::string, int>{{"006_mustard_bottle", -1}, {"square", 0}, {"triangle", 0}}));
  const nlohmann::json listed = nlohmann::json::parse(test::RunCli("modeldb list --json --db " + library).output);
  ASSERT_EQ(listed.size(), 3U);
  EXPECT_TRUE(listed[0]["point_pairs"].is_null());
  EXPECT_EQ(listed[1]["point_pairs"]["points"], 0);

  const test::CommandResult recognized = test::RunCli("recognize --db " + library + " --hypotheses ppf --threads 2 " +
                                                      std::string(ECV_SOURCE_DIR) + "/models/frame/000001");
  EXPECT_EQ(recognized.exit_code, 0) << recognized.output;
  EXPECT_THAT(recognized.output, AllOf(HasSubstr("model 006_mustard_bottle: no point pair hypotheses"),
                                       HasSubstr("--no-ppf"), HasSubstr("model square: no point pair hypotheses")));
}

TEST_F(ModeldbCli, ReadsButDoesNotWriteInAReadOnlyLocation) {
  const fs::path read_only = scratch_.path() / "read_only";
  fs::create_directories(read_only);
  fs::copy_file(library_, read_only / "lib.sqlite");
  fs::permissions(read_only / "lib.sqlite", fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  fs::permissions(read_only, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                 fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const std::string library = (read_only / "lib.sqlite").string();
  const test::CommandResult list = RunCliUnprivileged("modeldb list --db " + library);
  EXPECT_EQ(list.exit_code, 0) << list.output;
  EXPECT_THAT(list.output, HasSubstr("2 models"));
  const test::CommandResult verify = RunCliUnprivileged("modeldb verify --db " + library);
  EXPECT_EQ(verify.exit_code, 0) << verify.output;

  // The mesh copied where every user can read it: the checkout may be in a private folder.
  const fs::path mustard_copy = scratch_.path() / "006_mustard_bottle";
  fs::copy(test::DemoMeshDirectory() + "/006_mustard_bottle", mustard_copy, fs::copy_options::recursive);
  const std::string mustard = mustard_copy.string();
  const test::CommandResult create =
      RunCliUnprivileged("modeldb build " + mustard + " --db " + (read_only / "new.sqlite").string() + QuickFlags(1));
  EXPECT_EQ(create.exit_code, 1) << create.output;
  EXPECT_THAT(create.output, AllOf(HasSubstr("new.sqlite"), HasSubstr("cannot write the model library here")));
  const test::CommandResult remove = RunCliUnprivileged("modeldb remove 003_cracker_box --db " + library);
  EXPECT_EQ(remove.exit_code, 1) << remove.output;
  EXPECT_THAT(remove.output, AllOf(HasSubstr(library), HasSubstr("cannot")));
  fs::permissions(read_only, fs::perms::owner_all);
  EXPECT_EQ(ModelDatabase(library, OpenMode::kReadOnly).ListModels().size(), 2U);  // unchanged
}

TEST_F(ModeldbCli, RefusesFilesThatAreNotLibrariesOfThisVersion) {
  const std::string text = scratch_.File("notes.sqlite");
  std::ofstream(text) << "some notes, not a database; long enough to fill an SQLite header of 100 bytes......\n";
  const test::CommandResult not_sqlite = test::RunCli("modeldb list --db " + text);
  EXPECT_EQ(not_sqlite.exit_code, 1);
  EXPECT_THAT(not_sqlite.output, AllOf(HasSubstr(text), HasSubstr("not an SQLite database")));

  const std::string newer = CopyOfLibrary();
  SqlConnection(newer, SqlOpenMode::kReadWrite, 1000).Execute("PRAGMA user_version = 9");
  const test::CommandResult refused = test::RunCli("modeldb list --db " + newer);
  EXPECT_EQ(refused.exit_code, 1);
  // The file asks for no later ecvpose than this one: a newer release, not this version, is what reads it.
  EXPECT_THAT(refused.output, AllOf(HasSubstr("schema version 9"), HasSubstr("reads versions up to"),
                                    HasSubstr("use ecvpose of a newer release")));
  SqlConnection(newer, SqlOpenMode::kReadWrite, 1000)
      .Execute("UPDATE meta SET value = '9.1.0' WHERE key = 'min_ecvpose_version'");
  EXPECT_THAT(test::RunCli("modeldb list --db " + newer).output, HasSubstr("use ecvpose 9.1.0 or newer"));
  const test::CommandResult folder = test::RunCli("modeldb list --db " + scratch_.path().string());
  EXPECT_EQ(folder.exit_code, 1);
  EXPECT_THAT(folder.output, HasSubstr("is a directory"));

  const std::string old = scratch_.File("old.sqlite");
  test::WritePrototypeLibrary(old, {test::SyntheticModel("a", 2, 20, 1)});
  const test::CommandResult needs_migration = test::RunCli("modeldb list --db " + old);
  EXPECT_EQ(needs_migration.exit_code, 1);
  EXPECT_THAT(needs_migration.output, HasSubstr("run `ecvpose modeldb migrate --db " + old + "`"));
  const test::CommandResult migrated = test::RunCli("modeldb migrate --db " + old);
  EXPECT_EQ(migrated.exit_code, 0) << migrated.output;
  EXPECT_THAT(migrated.output, HasSubstr("from schema version 0 to 3"));
  EXPECT_EQ(test::RunCli("modeldb list --db " + old).exit_code, 0);
}

TEST_F(ModeldbCli, RecognizeRefusesALibraryWithoutModels) {
  const std::string library = CopyOfLibrary();
  for (const char* name : {"003_cracker_box", "006_mustard_bottle"}) {
    EXPECT_EQ(test::RunCli("modeldb remove " + std::string(name) + " --db " + library).exit_code, 0);
  }
  const test::CommandResult empty =
      test::RunCli("recognize --db " + library + " " + std::string(ECV_SOURCE_DIR) + "/models/frame/000001");
  EXPECT_EQ(empty.exit_code, 1) << empty.output;
  EXPECT_THAT(empty.output, AllOf(HasSubstr(library), HasSubstr("at least one model")));
}

TEST_F(ModeldbCli, BadUsageExitsWithTwo) {
  EXPECT_EQ(test::RunCli("modeldb build --db " + scratch_.File("x.sqlite")).exit_code, 2);
  EXPECT_EQ(test::RunCli("modeldb list").exit_code, 2);
  const test::CommandResult name =
      test::RunCli("modeldb build " + test::DemoMeshDirectory() + " --name x --db " + scratch_.File("x.sqlite"));
  EXPECT_EQ(name.exit_code, 2);
  EXPECT_THAT(name.output, HasSubstr("--name needs a single mesh"));
  EXPECT_EQ(test::RunCli("modeldb merge " + scratch_.File("merged.sqlite")).exit_code, 2) << "no parts";
  for (const char* const shard : {"3/3", "1", "-1/2", "1/0", "0/2x"}) {  // a bad value, as of --size: exit 1
    const test::CommandResult bad = test::RunCli("modeldb build " + test::DemoMeshDirectory() + " --shard " + shard +
                                                 " --db " + scratch_.File("x.sqlite"));
    EXPECT_EQ(bad.exit_code, 1) << shard;
    EXPECT_THAT(bad.output, AllOf(HasSubstr("--shard"), HasSubstr("0 <= I < N"))) << shard;
  }
}

}  // namespace
}  // namespace ecv
