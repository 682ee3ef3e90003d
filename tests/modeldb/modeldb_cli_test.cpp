// `ecvpose modeldb` as a user runs it: a library of two demo meshes built by one process and read back by
// others bit for bit; list, info, remove, replace, verify, export; a bad mesh in a directory; a read-only
// location; files that are not libraries, or of another schema version.

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "io/ply_io.h"
#include "io/pose_io.h"
#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"
#include "modeldb/sql.h"
#include "modeldb_test_util.h"
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
test::CommandResult RunCliUnprivileged(const std::string& arguments) {
  return test::RunCli(arguments, geteuid() == 0 ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "");
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
  EXPECT_THAT(list.output, AllOf(HasSubstr("2 models"), HasSubstr("003_cracker_box"), HasSubstr("006_mustard_bottle")));

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

  const std::string mustard = test::DemoMeshDirectory() + "/006_mustard_bottle";
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
  EXPECT_THAT(refused.output, AllOf(HasSubstr("schema version 9"), HasSubstr("ecvpose 0.2.0 or newer")));

  const std::string old = scratch_.File("old.sqlite");
  test::WritePrototypeLibrary(old, {test::SyntheticModel("a", 2, 20, 1)});
  const test::CommandResult needs_migration = test::RunCli("modeldb list --db " + old);
  EXPECT_EQ(needs_migration.exit_code, 1);
  EXPECT_THAT(needs_migration.output, HasSubstr("run `ecvpose modeldb migrate --db " + old + "`"));
  const test::CommandResult migrated = test::RunCli("modeldb migrate --db " + old);
  EXPECT_EQ(migrated.exit_code, 0) << migrated.output;
  EXPECT_THAT(migrated.output, HasSubstr("from schema version 0 to 2"));
  EXPECT_EQ(test::RunCli("modeldb list --db " + old).exit_code, 0);
}

TEST_F(ModeldbCli, BadUsageExitsWithTwo) {
  EXPECT_EQ(test::RunCli("modeldb build --db " + scratch_.File("x.sqlite")).exit_code, 2);
  EXPECT_EQ(test::RunCli("modeldb list").exit_code, 2);
  const test::CommandResult name =
      test::RunCli("modeldb build " + test::DemoMeshDirectory() + " --name x --db " + scratch_.File("x.sqlite"));
  EXPECT_EQ(name.exit_code, 2);
  EXPECT_THAT(name.output, HasSubstr("--name needs a single mesh"));
}

}  // namespace
}  // namespace ecv
