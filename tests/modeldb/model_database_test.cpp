// The model database on synthetic models (no rendering): storing and loading bit for bit, atomic replacement,
// removal, colour matrices, feature settings, verification, bad files, schema versions and migration.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "modeldb/content_hash.h"
#include "modeldb/library_build.h"
#include "modeldb/mesh_sources.h"
#include "modeldb/model_database.h"
#include "modeldb/schema.h"
#include "modeldb/sql.h"
#include "modeldb_test_util.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::AllOf;
using ::testing::Contains;
using ::testing::HasSubstr;

// The message of the InputError thrown by `action`, or "" when none is thrown.
template <typename Action>
std::string InputErrorOf(Action action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(ContentHash, MatchesTheStandardTestVectors) {
  EXPECT_EQ(Sha256Hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  const std::string two_blocks = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
  EXPECT_EQ(Sha256Hex(two_blocks.data(), two_blocks.size()),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  Sha256 pieces;  // the same bytes in uneven pieces
  pieces.Update(two_blocks.data(), 5);
  pieces.Update(two_blocks.data() + 5, two_blocks.size() - 5);
  EXPECT_EQ(pieces.HexDigest(), Sha256Hex(two_blocks.data(), two_blocks.size()));
}

TEST(ModelDatabase, StoresAndLoadsModelsBitForBit) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  const ModelRecord a = test::SyntheticModel("a", 3, 200, 1);
  const ModelRecord b = test::SyntheticModel("b", 2, 150, 2);
  database.AddModel(a);
  database.AddModel(b);
  const std::vector<StoredModel> loaded = database.LoadModels();
  ASSERT_EQ(loaded.size(), 2U);
  for (const auto& [expected, stored] : {std::pair(&a, &loaded[0]), std::pair(&b, &loaded[1])}) {
    EXPECT_EQ(stored->record.name, expected->name);
    EXPECT_EQ(test::CompareViews(expected->views, stored->record.views), "") << expected->name;
    EXPECT_EQ(stored->record.DescriptorSha256(), expected->DescriptorSha256());
    EXPECT_TRUE(stored->record.object_from_mesh.isApprox(expected->object_from_mesh, 0.0));
    EXPECT_EQ(stored->record.diameter_m, expected->diameter_m);
  }
  const ModelSummary summary = database.FindModel("a").value();
  EXPECT_EQ(summary.num_views, 3);
  EXPECT_EQ(summary.num_primitives, 600);
  EXPECT_EQ(summary.num_descriptors, a.NumDescriptors());
  EXPECT_EQ(summary.descriptor_sha256, a.DescriptorSha256());
  EXPECT_FALSE(summary.symmetric);
  EXPECT_FALSE(database.FindModel("c").has_value());
}

TEST(ModelDatabase, ReplacesAModelOfTheSameNameWhole) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  database.AddModel(test::SyntheticModel("a", 3, 100, 1));
  database.AddModel(test::SyntheticModel("b", 2, 100, 2));
  const ModelRecord replacement = test::SyntheticModel("a", 5, 80, 3);
  const AddModelResult result = database.AddModel(replacement);
  EXPECT_TRUE(result.replaced);
  ASSERT_EQ(database.ListModels().size(), 2U);
  const std::vector<StoredModel> loaded = database.LoadModels({"a"});
  EXPECT_EQ(test::CompareViews(replacement.views, loaded.at(0).record.views), "");
  const VerifyReport report = database.Verify();
  EXPECT_TRUE(report.ok()) << report.problems.front();
  EXPECT_EQ(report.views, 5 + 2);  // nothing of the old "a" is left
  EXPECT_EQ(report.primitives, 5 * 80 + 2 * 100);
}

// A model's number in the library is its BOP obj_id unless its name gives one: it stays when the model is built
// again, and the loaded record carries it.
TEST(ModelDatabase, AModelKeepsItsNumberWhenBuiltAgain) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  database.AddModel(test::SyntheticModel("a", 2, 50, 1));
  database.AddModel(test::SyntheticModel("b", 2, 50, 2));
  const int64_t a = database.FindModel("a")->id, b = database.FindModel("b")->id;
  EXPECT_NE(a, b);
  EXPECT_GT(a, 0);
  database.AddModel(test::SyntheticModel("a", 3, 40, 3));
  database.AddModel(test::SyntheticModel("c", 2, 50, 4));
  EXPECT_EQ(database.FindModel("a")->id, a);
  EXPECT_NE(database.FindModel("c")->id, a);
  EXPECT_NE(database.FindModel("c")->id, b);
  EXPECT_EQ(database.LoadModels({"a"}).at(0).record.id, a);
}

TEST(BopObjectId, FromABopOrYcbVideoNameElseTheLibraryNumber) {
  EXPECT_EQ(BopObjectId("obj_000005", 9), 5);
  EXPECT_EQ(BopObjectId("003_cracker_box", 9), 2);
  EXPECT_EQ(BopObjectId("021_bleach_cleanser", 9), 12);
  EXPECT_EQ(BopObjectId("mug", 9), 9);
  EXPECT_EQ(BopObjectId("obj_12x", 9), 9);
  EXPECT_EQ(BopObjectId("obj_", 9), 9);
}

// A library of YCB-Video objects and other models (e.g. scaled variants) numbered 1..n: no two models share an id.
TEST(BopObjectId, EveryModelOfALibraryHasItsOwnIdAndDatasetNamesKeepTheirs) {
  // 040_large_marker is YCB-Video's 18, which is also the variant's library number; obj_000002 asks for the
  // cracker box's 2 and comes after it in the library.
  const std::map<std::string, int> ids = BopObjectIds({{"variant_b", 18},
                                                       {"040_large_marker", 30},
                                                       {"mug", 4},
                                                       {"003_cracker_box", 1},
                                                       {"obj_000002", 2},
                                                       {"variant_a", 2}});
  const std::map<std::string, int> expected = {{"040_large_marker", 18}, {"003_cracker_box", 2}, {"mug", 4},
                                               {"obj_000002", 19},       {"variant_a", 20},      {"variant_b", 21}};
  EXPECT_EQ(ids, expected);
  EXPECT_TRUE(BopObjectIds({}).empty());
}

TEST(ModelDatabase, RemovesAModelWithItsRows) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  database.AddModel(test::SyntheticModel("a", 3, 100, 1));
  database.AddModel(test::SyntheticModel("b", 2, 100, 2));
  database.SetColorMatrix("a", {Eigen::Matrix3d::Identity() * 0.9, 0.01, "test", ""});
  EXPECT_TRUE(database.RemoveModel("a"));
  EXPECT_FALSE(database.RemoveModel("a"));
  ASSERT_EQ(database.ListModels().size(), 1U);
  EXPECT_EQ(database.ListModels()[0].name, "b");
  const VerifyReport report = database.Verify();
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.views, 2);
  EXPECT_EQ(report.primitives, 200);
  EXPECT_EQ(report.descriptors, 2 * 80);
}

TEST(ModelDatabase, KeepsAColourMatrixAcrossARebuildOfTheSameMeshOnly) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  ModelRecord model = test::SyntheticModel("a", 2, 50, 1);
  database.AddModel(model);
  EXPECT_FALSE(database.GetColorMatrix("a").has_value());
  ColorMatrixRecord matrix;
  matrix.model_to_scene << 0.9, 0.1, 0.0, 0.05, 1.1, -0.02, 0.0, 0.0, 0.8;
  matrix.rms = 0.012;
  matrix.source = "pairs:pairs.csv";
  database.SetColorMatrix("a", matrix);
  const ColorMatrixRecord stored = database.GetColorMatrix("a").value();
  EXPECT_EQ(stored.model_to_scene, matrix.model_to_scene);
  EXPECT_EQ(stored.rms, 0.012);
  EXPECT_EQ(stored.source, "pairs:pairs.csv");
  EXPECT_FALSE(stored.created.empty());
  EXPECT_TRUE(database.FindModel("a")->has_color_matrix);

  EXPECT_TRUE(database.AddModel(model).color_matrix_kept);  // same mesh content
  EXPECT_EQ(database.GetColorMatrix("a")->model_to_scene, matrix.model_to_scene);
  model.mesh_sha256 = std::string(64, 'f');
  EXPECT_TRUE(database.AddModel(model).color_matrix_dropped);  // another mesh: the fit no longer holds
  EXPECT_FALSE(database.GetColorMatrix("a").has_value());

  database.SetColorMatrix("a", matrix);
  EXPECT_TRUE(database.ClearColorMatrix("a"));
  EXPECT_FALSE(database.ClearColorMatrix("a"));
  matrix.model_to_scene(1, 1) = std::nan("");
  EXPECT_THAT(InputErrorOf([&] { database.SetColorMatrix("a", matrix); }), HasSubstr("finite"));
  EXPECT_THAT(InputErrorOf([&] { database.GetColorMatrix("nope"); }), AllOf(HasSubstr("nope"), HasSubstr("(a)")));
}

TEST(ModelDatabase, SetsTheSymmetryFlag) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  database.AddModel(test::SyntheticModel("a", 1, 10, 1));
  database.SetSymmetric("a", true);
  EXPECT_TRUE(database.FindModel("a")->symmetric);
  EXPECT_TRUE(database.LoadModels({"a"}).at(0).record.symmetric);
  EXPECT_THAT(InputErrorOf([&] { database.SetSymmetric("b", true); }), HasSubstr("\"b\""));
}

TEST(ModelDatabase, KeepsOneSetOfFeatureSettingsPerLibrary) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  EXPECT_FALSE(database.feature_settings().has_value());
  ModelRecord a = test::SyntheticModel("a", 1, 10, 1);
  a.features.descriptor.soft_binning = false;
  database.AddModel(a);
  EXPECT_FALSE(database.feature_settings()->descriptor.soft_binning);
  ModelRecord b = test::SyntheticModel("b", 1, 10, 2);  // default settings: soft binning
  EXPECT_THAT(InputErrorOf([&] { database.AddModel(b); }), AllOf(HasSubstr("feature settings"), HasSubstr("\"b\"")));
  EXPECT_EQ(database.ListModels().size(), 1U);
  database.AddModel(test::SyntheticModel("a", 1, 10, 3));  // replacing the only model may change them
  EXPECT_TRUE(database.feature_settings()->descriptor.soft_binning);
  EXPECT_TRUE(database.LoadModels().at(0).record.features.descriptor.soft_binning);
}

// Libraries written before the descriptor's `pairs` and `shells` fields existed were built with all pairs in one
// shell, and read so; a user's partial settings (`modeldb build --feature-settings`) take today's defaults.
TEST(ModelDatabase, ReadsSettingsStoredWithoutTheNewerDescriptorFieldsAsTheyWereBuilt) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("old.sqlite");
  {
    ModelDatabase database(path, OpenMode::kCreate);
    ModelRecord a = test::SyntheticModel("a", 1, 10, 1);
    a.features = StoredFeatureDefaults();
    database.AddModel(a);
  }
  {
    nlohmann::json stored = nlohmann::json::parse(FeatureSettingsToJson(StoredFeatureDefaults()));
    stored["descriptor"].erase("pairs");
    stored["descriptor"].erase("shells");
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);
    raw.Prepare("UPDATE meta SET value = ? WHERE key = 'features'").Bind(1, stored.dump()).Run();
  }
  const FeatureSettings old = *ModelDatabase(path, OpenMode::kReadOnly).feature_settings();
  EXPECT_EQ(old.descriptor.pairs, DescriptorPairs::kAll);
  EXPECT_EQ(old.descriptor.shells, 1);
  EXPECT_EQ(old.descriptor.radius_m, 0.025);

  const FeatureSettings partial = FeatureSettingsFromJson(R"({"descriptor": {"soft_binning": false}})", "test");
  EXPECT_FALSE(partial.descriptor.soft_binning);
  EXPECT_EQ(partial.descriptor.pairs, DescriptorPairs::kSource);
  EXPECT_EQ(partial.descriptor.shells, 4);
  EXPECT_EQ(partial.descriptor.radius_m, 0.045);
  EXPECT_EQ(partial.descriptor.shape, DescriptorShape::kPrimitives);

  // The surface context's settings, read and written back.
  const FeatureSettings surface =
      FeatureSettingsFromJson(R"({"descriptor": {"shape": 1, "surface_weight": 3.5}})", "test");
  EXPECT_EQ(surface.descriptor.shape, DescriptorShape::kSurface);
  EXPECT_EQ(surface.descriptor.surface_weight, 3.5);
  const FeatureSettings again = FeatureSettingsFromJson(FeatureSettingsToJson(surface), "test");
  EXPECT_EQ(again.descriptor.shape, DescriptorShape::kSurface);
  EXPECT_EQ(again.descriptor.surface_weight, 3.5);
}

TEST(ModelDatabase, RefusesIncompleteRecords) {
  ModelDatabase database(":memory:", OpenMode::kCreate);
  EXPECT_THAT(InputErrorOf([&] { database.AddModel(test::SyntheticModel("", 1, 10, 1)); }), HasSubstr("name"));
  EXPECT_THAT(InputErrorOf([&] { database.AddModel(test::SyntheticModel("a", 0, 10, 1)); }), HasSubstr("view"));
  ModelRecord broken = test::SyntheticModel("a", 1, 10, 1);
  broken.views[0].descriptors.primitive[0] = 99;
  EXPECT_THAT(InputErrorOf([&] { database.AddModel(broken); }), HasSubstr("refer to its primitives"));
  EXPECT_TRUE(database.ListModels().empty());
}

TEST(ModelDatabase, VerifyFindsChangedDescriptorsAndOrphans) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  {
    ModelDatabase database(path, OpenMode::kCreate);
    database.AddModel(test::SyntheticModel("a", 2, 50, 1));
    EXPECT_TRUE(database.Verify().ok());
  }
  {
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);
    raw.Execute(
        "UPDATE descriptors SET value = zeroblob(384) WHERE primitive_id = (SELECT min(primitive_id) "
        "FROM descriptors)");
  }
  VerifyReport report = ModelDatabase(path, OpenMode::kReadOnly).Verify();
  EXPECT_THAT(report.problems, Contains(HasSubstr("descriptor values differ")));
  EXPECT_TRUE(ModelDatabase(path, OpenMode::kReadOnly).Verify(false).ok());  // the quick check cannot see it
  {
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);  // foreign keys are off in a raw connection
    raw.Execute("DELETE FROM views WHERE view_index = 1");
  }
  report = ModelDatabase(path, OpenMode::kReadOnly).Verify();
  EXPECT_THAT(report.problems, Contains(HasSubstr("foreign key: primitives")));
  EXPECT_THAT(report.problems, Contains(HasSubstr("2 views stored, 1 present")));
}

// Stored values a load needs are checked one by one: a view pose that is not a rigid transform, a diameter that is
// not finite, a view camera without a size, each named by model, view and field.
TEST(ModelDatabase, VerifyFindsStoredValuesThatAreNotPosesOrSizes) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  {
    ModelDatabase database(path, OpenMode::kCreate);
    database.AddModel(test::SyntheticModel("a", 3, 20, 1));
    EXPECT_TRUE(database.Verify().ok());
  }
  {
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);
    raw.Execute("UPDATE views SET camera_from_object = 'garbage' WHERE view_index = 0");
    raw.Execute(
        "UPDATE views SET camera_from_object = '[[2,0,0,0],[0,1,0,0],[0,0,1,0.5],[0,0,0,1]]' WHERE view_index = 1");
    raw.Execute("UPDATE views SET width = 0 WHERE view_index = 2");
    raw.Execute("UPDATE models SET diameter_m = 1e999");  // SQLite's infinity
  }
  const VerifyReport report = ModelDatabase(path, OpenMode::kReadOnly).Verify(false);
  EXPECT_THAT(report.problems,
              Contains(AllOf(HasSubstr("model a view 0: camera_from_object"), HasSubstr("got garbage"))));
  EXPECT_THAT(report.problems,
              Contains(AllOf(HasSubstr("model a view 1: camera_from_object"), HasSubstr("a rotation"))));
  EXPECT_THAT(report.problems, Contains(HasSubstr("model a view 2: camera: width/height")));
  EXPECT_THAT(report.problems, Contains("model a: diameter_m: expected a finite size > 0 m, got inf"));
  EXPECT_EQ(report.problems.size(), 4U) << ::testing::PrintToString(report.problems);
}

// The mesh bytes go in and out as they are, with the model's transaction: replaced with it, removed with it, and
// checked against their digest by verify.
TEST(ModelDatabase, StoresAModelsMeshWithItAndVerifiesItsDigest) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  ModelRecord a = test::SyntheticModel("a", 2, 30, 1);
  for (int i = 0; i < 5000; ++i) a.mesh_blob.push_back(static_cast<unsigned char>(i * 7));
  {
    ModelDatabase database(path, OpenMode::kCreate);
    database.AddModel(a);
    database.AddModel(test::SyntheticModel("b", 1, 30, 2));  // without a stored mesh
    const std::vector<StoredModel> loaded = database.LoadModels();
    ASSERT_EQ(loaded.size(), 2U);
    EXPECT_EQ(loaded[0].record.mesh_blob, a.mesh_blob);
    EXPECT_TRUE(loaded[1].record.mesh_blob.empty());
    EXPECT_EQ(database.FindModel("a")->mesh_blob_bytes, 5000);
    EXPECT_EQ(database.FindModel("b")->mesh_blob_bytes, 0);
    EXPECT_TRUE(database.Verify().ok());
  }
  SqlConnection(path, SqlOpenMode::kReadWrite, 1000).Execute("UPDATE meshes SET data = zeroblob(5000)");
  EXPECT_THAT(ModelDatabase(path, OpenMode::kReadOnly).Verify().problems,
              Contains(HasSubstr("model a: stored mesh differs")));

  ModelDatabase database(path, OpenMode::kReadWrite);
  a.mesh_blob.resize(100);
  database.AddModel(a);  // replaced whole, its mesh too
  EXPECT_EQ(database.FindModel("a")->mesh_blob_bytes, 100);
  EXPECT_TRUE(database.Verify().ok());
  database.RemoveModel("a");
  SqlConnection raw(path, SqlOpenMode::kReadOnly, 1000);
  SqlStatement rows = raw.Prepare("SELECT count(*) FROM meshes");
  ASSERT_TRUE(rows.Step());
  EXPECT_EQ(rows.Int(0), 0);
}

TEST(ModelDatabase, NamesWhatIsWrongWithABadFile) {
  test::TemporaryDirectory directory;
  const std::string text = directory.File("notes.sqlite");
  std::ofstream(text) << "not a database, just text that is long enough to have a header\n";
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(text, OpenMode::kReadOnly); }),
              AllOf(HasSubstr(text), HasSubstr("not an SQLite database")));
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(text, OpenMode::kCreate); }), HasSubstr("not an SQLite database"));

  const std::string missing = directory.File("missing.sqlite");
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(missing, OpenMode::kReadOnly); }),
              AllOf(HasSubstr("no such model library"), HasSubstr("ecvpose modeldb build")));
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(directory.File("no/such/dir/lib.sqlite"), OpenMode::kCreate); }),
              HasSubstr("existing directory"));

  const std::string foreign = directory.File("foreign.sqlite");
  SqlConnection(foreign, SqlOpenMode::kCreate, 1000).Execute("CREATE TABLE photos (id INTEGER)");
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(foreign, OpenMode::kCreate); }),
              AllOf(HasSubstr("not an ecvpose model library"), HasSubstr("photos")));

  const std::string empty = directory.File("empty.sqlite");
  std::ofstream{empty};
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(empty, OpenMode::kReadOnly); }), HasSubstr("empty database"));
  EXPECT_EQ(InputErrorOf([&] { ModelDatabase(empty, OpenMode::kCreate).AddModel(test::SyntheticModel("a", 1, 5, 1)); }),
            "");
}

// Point pair points round-trip bit for bit, with their sampling, pairs and a refusal; a model built without them
// has none; stored points that are not oriented points are refused naming the model.
TEST(ModelDatabase, StoresPointPairPointsBitForBit) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  ModelRecord with = test::SyntheticModel("with", 1, 10, 1), refused = test::SyntheticModel("refused", 1, 10, 2);
  PointPairRecord points;
  points.sampling.samples = 1234;
  points.sampling.keep_normal_deg = 25.0;
  for (int i = 0; i < 50; ++i) {
    const float t = 0.37F * static_cast<float>(i);
    points.points.push_back({{std::sin(t) / 7.0F, std::cos(t) / 3.0F, t / 1000.0F},
                             Eigen::Vector3f(std::cos(t), 0.3F, std::sin(t)).normalized()});
  }
  points.pairs = 2450;
  with.point_pairs = points;
  refused.point_pairs = PointPairRecord{};
  refused.point_pairs->refusal = "too flat";
  ModelDatabase database(path, OpenMode::kCreate);
  database.AddModel(with);
  database.AddModel(refused);
  database.AddModel(test::SyntheticModel("without", 1, 10, 3));

  const std::vector<StoredModel> loaded = database.LoadModels();
  ASSERT_EQ(loaded.size(), 3U);
  const std::optional<PointPairRecord>& read = loaded[1].record.point_pairs;  // by name: refused, with, without
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->sampling, points.sampling);
  EXPECT_EQ(read->pairs, 2450);
  ASSERT_EQ(read->points.size(), points.points.size());
  EXPECT_EQ(EncodeOrientedPoints(read->points), EncodeOrientedPoints(points.points));
  ASSERT_TRUE(loaded[0].record.point_pairs.has_value());
  EXPECT_TRUE(loaded[0].record.point_pairs->points.empty());
  EXPECT_EQ(loaded[0].record.point_pairs->refusal, "too flat");
  EXPECT_FALSE(loaded[2].record.point_pairs.has_value());
  const std::vector<ModelSummary> summaries = database.ListModels();
  EXPECT_EQ(summaries[0].point_pair_points, 0);
  EXPECT_EQ(summaries[1].point_pair_points, 50);
  EXPECT_EQ(summaries[1].point_pairs, 2450);
  EXPECT_EQ(summaries[2].point_pair_points, -1);

  SqlConnection(path, SqlOpenMode::kReadWrite, 1000)
      .Execute(
          "UPDATE point_pairs SET points = zeroblob(24), num_points = 1 WHERE model_id = "
          "(SELECT id FROM models WHERE name = 'with')");
  EXPECT_THAT(InputErrorOf([&] { database.LoadModels({"with"}); }),
              AllOf(HasSubstr("model with"), HasSubstr("point_pairs.points"), HasSubstr("unit normal")));
}

TEST(ModelDatabase, RefusesANewerSchemaNamingTheVersionNeeded) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  ModelDatabase(path, OpenMode::kCreate).AddModel(test::SyntheticModel("a", 1, 10, 1));
  {
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);
    raw.Execute("PRAGMA user_version = 7; UPDATE meta SET value = '0.9.0' WHERE key = 'min_ecvpose_version'");
  }
  for (const OpenMode mode : {OpenMode::kReadOnly, OpenMode::kReadWrite, OpenMode::kCreate}) {
    EXPECT_THAT(
        InputErrorOf([&] { ModelDatabase(path, mode); }),
        AllOf(HasSubstr(path), HasSubstr("schema version 7"),
              HasSubstr("up to " + std::to_string(kModelDbSchemaVersion)), HasSubstr("ecvpose 0.9.0 or newer")));
  }
  EXPECT_THAT(InputErrorOf([&] { MigrateModelDatabase(path); }), HasSubstr("schema version 7"));
}

TEST(ModelDatabase, MigratesThePrototypeLayoutInOneTransaction) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("old.sqlite");
  const ModelRecord a = test::SyntheticModel("a", 2, 60, 1);
  const ModelRecord b = test::SyntheticModel("b", 3, 40, 2);
  test::WritePrototypeLibrary(path, {a, b});
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(path, OpenMode::kReadOnly); }),
              AllOf(HasSubstr("schema version 0"), HasSubstr("ecvpose modeldb migrate --db " + path)));
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(path, OpenMode::kCreate); }), HasSubstr("modeldb migrate"));

  const ModelDbMigration migration = MigrateModelDatabase(path);
  EXPECT_EQ(migration.from_version, 0);
  EXPECT_EQ(migration.to_version, kModelDbSchemaVersion);
  EXPECT_EQ(migration.steps.size(), 3U);  // 0 -> 1 -> 2 -> 3
  // Without stored meshes the models get no point pair points, and the migration says so, naming them.
  ASSERT_EQ(migration.notes.size(), 2U);
  EXPECT_THAT(migration.notes[0], AllOf(HasSubstr("model a"), HasSubstr("no stored mesh"), HasSubstr("build")));
  EXPECT_THAT(migration.notes[1], HasSubstr("model b"));
  EXPECT_TRUE(MigrateModelDatabase(path).steps.empty());  // nothing left to do

  ModelDatabase database(path, OpenMode::kReadWrite);
  const VerifyReport report = database.Verify();
  EXPECT_TRUE(report.ok()) << (report.ok() ? "" : report.problems.front());
  const std::vector<StoredModel> loaded = database.LoadModels();
  ASSERT_EQ(loaded.size(), 2U);
  EXPECT_EQ(test::CompareViews(a.views, loaded[0].record.views), "");
  EXPECT_EQ(test::CompareViews(b.views, loaded[1].record.views), "");
  const ModelSummary summary = database.FindModel("b").value();
  EXPECT_EQ(summary.num_views, 3);
  EXPECT_EQ(summary.num_descriptors, b.NumDescriptors());
  EXPECT_EQ(summary.descriptor_sha256, b.DescriptorSha256());
  EXPECT_FALSE(summary.symmetric);
  database.SetColorMatrix("a", {});  // the tables of version 1 are there
  database.AddModel(test::SyntheticModel("c", 1, 10, 3));
  EXPECT_EQ(database.ListModels().size(), 3U);
}

// A library written before meshes were stored (version 1): refused until migrated; its models then read their mesh
// files (no stored mesh), and new models store theirs.
TEST(ModelDatabase, MigratesAVersionOneLibraryByAddingTheMeshesTable) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("v1.sqlite");
  const ModelRecord a = test::SyntheticModel("a", 2, 40, 1);
  ModelDatabase(path, OpenMode::kCreate).AddModel(a);
  SqlConnection(path, SqlOpenMode::kReadWrite, 1000)
      .Execute(
          "DROP TABLE meshes; DROP TABLE point_pairs; PRAGMA user_version = 1; UPDATE meta SET value = '0.1.0' "
          "WHERE key = "
          "'min_ecvpose_version'");
  EXPECT_THAT(InputErrorOf([&] { ModelDatabase(path, OpenMode::kReadOnly); }),
              AllOf(HasSubstr("schema version 1"), HasSubstr("ecvpose modeldb migrate --db " + path)));

  const ModelDbMigration migration = MigrateModelDatabase(path);
  EXPECT_EQ(migration.from_version, 1);
  EXPECT_EQ(migration.to_version, 3);
  ASSERT_EQ(migration.steps.size(), 2U);
  EXPECT_THAT(migration.steps[0], HasSubstr("meshes"));
  EXPECT_THAT(migration.steps[1], HasSubstr("point pair"));
  ModelDatabase database(path, OpenMode::kReadWrite);
  EXPECT_TRUE(database.Verify().ok());
  const std::vector<StoredModel> loaded = database.LoadModels();
  ASSERT_EQ(loaded.size(), 1U);
  EXPECT_EQ(test::CompareViews(a.views, loaded[0].record.views), "");
  EXPECT_TRUE(loaded[0].record.mesh_blob.empty());
  ModelRecord b = test::SyntheticModel("b", 1, 20, 2);
  b.mesh_blob = {1, 2, 3};
  database.AddModel(b);
  EXPECT_EQ(database.FindModel("b")->mesh_blob_bytes, 3);
}

TEST(ModelDatabase, AFailedMigrationLeavesTheOldFileAsItWas) {
  test::TemporaryDirectory directory;
  const std::string path = directory.File("old.sqlite");
  test::WritePrototypeLibrary(path, {test::SyntheticModel("a", 2, 30, 1)});
  {
    SqlConnection raw(path, SqlOpenMode::kReadWrite, 1000);  // a view whose model is gone: the check fails
    raw.Execute("INSERT INTO views VALUES (NULL, 99, 0, 1, 1, 1, 1, 1, 1, '[]')");
  }
  EXPECT_THAT(InputErrorOf([&] { MigrateModelDatabase(path); }), HasSubstr("foreign keys"));
  SqlConnection raw(path, SqlOpenMode::kReadOnly, 1000);
  const SchemaState state = InspectSchema(raw);
  EXPECT_EQ(state.kind, SchemaState::Kind::kOlder);
  EXPECT_EQ(state.version, 0);
  SqlStatement settings = raw.Prepare("SELECT count(*) FROM settings");
  ASSERT_TRUE(settings.Step());
  EXPECT_EQ(settings.Int(0), 1);  // the prototype's tables are still there
}

}  // namespace
}  // namespace ecv

namespace ecv {
namespace {

// A writer queued behind another process's lock says, once, what it waits for; a writer that cannot take the lock
// fails when it opens the library, not after the work it would store.
TEST(SqlConnection, AWriterWaitingForTheLockSaysSoAndFailsAtOpen) {
  const test::TemporaryDirectory directory;
  const std::string path = directory.File("locked.sqlite");
  SqlConnection holder(path, SqlOpenMode::kCreate, 1000);
  holder.Execute("PRAGMA journal_mode = WAL; CREATE TABLE t (x INTEGER); BEGIN IMMEDIATE; INSERT INTO t VALUES (1)");
  ::testing::internal::CaptureStderr();
  try {
    SqlConnection waiting(path, SqlOpenMode::kReadWrite, 1500);
    ADD_FAILURE() << "opened for writing while another connection holds the write lock";
  } catch (const SqlError& error) {
    EXPECT_THAT(error.what(), ::testing::AllOf(::testing::HasSubstr(path), ::testing::HasSubstr("cannot write")));
  }
  const std::string said = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(said, ::testing::HasSubstr("waiting for the library's lock"));
  holder.Execute("ROLLBACK");
  EXPECT_NO_THROW(SqlConnection(path, SqlOpenMode::kReadWrite, 1500));
  EXPECT_NO_THROW(SqlConnection(path, SqlOpenMode::kReadOnly, 1500));
}

std::string JournalMode(const std::string& path) {
  SqlConnection connection(path, SqlOpenMode::kReadOnly, 1000);
  SqlStatement mode = connection.Prepare("PRAGMA journal_mode");
  mode.Step();
  return mode.Text(0);
}

bool HasLogFiles(const std::string& path) {
  return std::filesystem::exists(path + "-wal") || std::filesystem::exists(path + "-shm");
}

// Many recognizers read one finished library: they must not need to write beside it.
TEST(ModelDatabase, AWriterLeavesAFinishedLibraryWithoutALogForItsReaders) {
  const test::TemporaryDirectory directory;
  const std::string path = directory.File("lib.sqlite");
  ModelDatabase(path, OpenMode::kCreate).AddModel(test::SyntheticModel("a", 1, 20, 1));
  EXPECT_EQ(JournalMode(path), "delete");
  EXPECT_FALSE(HasLogFiles(path));
  {
    const ModelDatabase reader(path, OpenMode::kReadOnly);
    EXPECT_EQ(reader.LoadModels().size(), 1U);
    EXPECT_FALSE(HasLogFiles(path));
    // A writer beside a reader of the finished library logs while it writes and switches back when it closes.
    std::optional<ModelDatabase> writer(std::in_place, path, OpenMode::kReadWrite);
    writer->AddModel(test::SyntheticModel("b", 1, 20, 2));
    EXPECT_TRUE(std::filesystem::exists(path + "-wal"));
    {
      const ModelDatabase during(path, OpenMode::kReadOnly);  // opened while logged: holds the log open
      EXPECT_EQ(during.ListModels().size(), 2U);
      writer.reset();  // does not wait for it, and leaves the file logged
      EXPECT_EQ(JournalMode(path), "wal");
    }
    EXPECT_EQ(reader.ListModels().size(), 2U);
  }
  ModelDatabase(path, OpenMode::kReadWrite).RemoveModel("b");  // the next writer to close switches it
  EXPECT_EQ(JournalMode(path), "delete");
  EXPECT_FALSE(HasLogFiles(path));
}

TEST(MeshSources, ShardsHoldEachModelAndProblemOnceAlikeOnEveryMachine) {
  // FNV-1a of the name: these values are part of the file layout a cluster's parts were built with.
  EXPECT_EQ(ShardOfName("003_cracker_box", 3), 1);
  EXPECT_EQ(ShardOfName("011_banana", 4), 3);
  EXPECT_EQ(ShardOfName("anything", 1), 0);
  MeshSourceScan scan;
  for (int i = 0; i < 60; ++i) scan.sources.push_back(ModelSource{"model_" + std::to_string(i), "m.obj"});
  for (int i = 0; i < 6; ++i) scan.problems.push_back("folder_" + std::to_string(i) + ": no mesh");
  std::map<std::string, int> sources, problems;
  for (int part = 0; part < 3; ++part) {
    MeshSourceScan kept = scan;
    KeepShard(part, 3, &kept);
    EXPECT_GE(kept.sources.size(), 10U) << "part " << part << " of an even split of 60";
    for (const ModelSource& source : kept.sources) ++sources[source.name];
    for (const std::string& problem : kept.problems) ++problems[problem];
  }
  EXPECT_EQ(sources.size(), 60U);
  EXPECT_EQ(problems.size(), 6U);
  for (const auto& [name, count] : sources) EXPECT_EQ(count, 1) << name;
  for (const auto& [problem, count] : problems) EXPECT_EQ(count, 1) << problem;
}

TEST(LibraryMerge, CopiesEveryModelInNameOrderWithItsColourMatrixAsOneBuildWould) {
  const test::TemporaryDirectory directory;
  const std::string first = directory.File("part0.sqlite"), second = directory.File("part1.sqlite");
  const std::vector<ModelRecord> models = {test::SyntheticModel("a", 2, 40, 1), test::SyntheticModel("b", 1, 30, 2),
                                           test::SyntheticModel("c", 3, 20, 3), test::SyntheticModel("d", 1, 50, 4)};
  ColorMatrixRecord matrix;
  matrix.model_to_scene << 0.9, 0.1, 0.0, 0.05, 1.1, -0.02, 0.0, 0.0, 0.8;
  matrix.rms = 0.02;
  matrix.source = "fit";
  {
    ModelDatabase part(first, OpenMode::kCreate);
    part.AddModel(models[3]);
    part.AddModel(models[1]);
    ModelDatabase other(second, OpenMode::kCreate);
    other.AddModel(models[2]);
    other.AddModel(models[0]);
    other.SetColorMatrix("c", matrix);
  }
  std::vector<std::string> said;
  LibraryMergeReporter reporter;
  reporter.copied = [&](const std::string& model, const std::string& shard, int number, int count) {
    said.push_back(model + " " + std::filesystem::path(shard).filename().string() + " " + std::to_string(number) + "/" +
                   std::to_string(count));
  };
  const std::string merged = directory.File("merged.sqlite");
  EXPECT_EQ(MergeLibraries(merged, {first, second}, reporter), 4);
  EXPECT_THAT(said, ::testing::ElementsAre("a part1.sqlite 1/4", "b part0.sqlite 2/4", "c part1.sqlite 3/4",
                                           "d part0.sqlite 4/4"));
  const ModelDatabase library(merged, OpenMode::kReadOnly);
  const std::vector<ModelSummary> listed = library.ListModels();
  ASSERT_EQ(listed.size(), 4U);
  const std::vector<StoredModel> loaded = library.LoadModels();
  for (size_t i = 0; i < models.size(); ++i) {
    EXPECT_EQ(listed[i].id, static_cast<int64_t>(i) + 1) << "numbered in name order, as one build of a folder";
    EXPECT_EQ(listed[i].descriptor_sha256, models[i].DescriptorSha256());
    EXPECT_EQ(listed[i].mesh_sha256, models[i].mesh_sha256);
    EXPECT_EQ(test::CompareViews(models[i].views, loaded[i].record.views), "") << models[i].name;
  }
  const ColorMatrixRecord copied = library.GetColorMatrix("c").value();
  EXPECT_EQ(copied.model_to_scene, matrix.model_to_scene);
  EXPECT_EQ(copied.created, ModelDatabase(second, OpenMode::kReadOnly).GetColorMatrix("c")->created);
  EXPECT_FALSE(library.GetColorMatrix("a").has_value());
  EXPECT_TRUE(library.Verify().ok());
  EXPECT_EQ(JournalMode(merged), "delete");
}

TEST(LibraryMerge, RefusesMixedSettingsAModelInTwoPartsAndItselfBeforeWritingAnything) {
  const test::TemporaryDirectory directory;
  const std::string first = directory.File("part0.sqlite"), second = directory.File("part1.sqlite");
  const std::string other_settings = directory.File("other.sqlite");
  ModelDatabase(first, OpenMode::kCreate).AddModel(test::SyntheticModel("a", 1, 20, 1));
  ModelDatabase(second, OpenMode::kCreate).AddModel(test::SyntheticModel("a", 1, 20, 2));
  ModelRecord unbinned = test::SyntheticModel("b", 1, 20, 3);
  unbinned.features.descriptor.soft_binning = false;
  ModelDatabase(other_settings, OpenMode::kCreate).AddModel(unbinned);
  const std::string merged = directory.File("merged.sqlite");
  EXPECT_THAT(InputErrorOf([&] {
                MergeLibraries(merged, {first, other_settings});
              }),
              AllOf(HasSubstr(other_settings), HasSubstr("feature settings"), HasSubstr(first)));
  EXPECT_THAT(InputErrorOf([&] {
                MergeLibraries(merged, {first, second});
              }),
              AllOf(HasSubstr(second), HasSubstr("\"a\""), HasSubstr("also in " + first)));
  EXPECT_THAT(InputErrorOf([&] { MergeLibraries(first, {first, second}); }), HasSubstr("other than the merged one"));
  EXPECT_THAT(InputErrorOf([&] { MergeLibraries(merged, {directory.File("gone.sqlite")}); }),
              HasSubstr("no such model library"));
  EXPECT_FALSE(std::filesystem::exists(merged));
  EXPECT_EQ(ModelDatabase(first, OpenMode::kReadOnly).ListModels().size(), 1U);
}

}  // namespace
}  // namespace ecv
