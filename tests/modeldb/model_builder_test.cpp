// Building library models from the demo meshes (models/meshes, 1024^2 textures) with few, small views:
// primitives land in the object frame, builds repeat bit for bit, stored descriptors are those of the stored
// primitives; the directory scan finds meshes, names and pose files.

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"
#include "modeldb/content_hash.h"
#include "modeldb/mesh_sources.h"
#include "modeldb/model_builder.h"
#include "modeldb/model_database.h"
#include "modeldb_test_util.h"
#include "support/test_data.h"

namespace ecv {
namespace {

using ::testing::HasSubstr;

ModelSource CrackerBox() {
  const std::string folder = test::DemoMeshDirectory() + "/003_cracker_box";
  ModelSource source;
  source.name = "003_cracker_box";
  source.mesh_path = folder + "/003_cracker_box.obj";
  source.object_from_mesh = ReadPoseFile(folder + "/object_from_mesh.json", "object_from_mesh");
  return source;
}

ModelBuildOptions FewSmallViews(int views) {
  ModelBuildOptions options;
  options.sampling.num_views = views;
  options.camera = test::SmallCamera();
  return options;
}

// One build shared by the tests below (rendering and describing take a few seconds).
class BuiltModel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    renderer_ = new Renderer();
    built_ = new BuildResult(BuildModel(CrackerBox(), FewSmallViews(4), *renderer_,
                                        [](const BuildProgress& p) { progress_.push_back(p.view); }));
  }
  static void TearDownTestSuite() {
    delete built_;
    delete renderer_;
  }
  static Renderer* renderer_;
  static BuildResult* built_;
  static std::vector<int> progress_;
};
Renderer* BuiltModel::renderer_ = nullptr;
BuildResult* BuiltModel::built_ = nullptr;
std::vector<int> BuiltModel::progress_;

TEST_F(BuiltModel, RecordsTheMeshTheViewsAndTheSettings) {
  const ModelRecord& record = built_->record;
  EXPECT_EQ(record.name, "003_cracker_box");
  ASSERT_EQ(record.views.size(), 4U);
  EXPECT_EQ(progress_, std::vector<int>({1, 2, 3, 4}));
  const TriangleMesh mesh = LoadMesh(CrackerBox().mesh_path, {1.0, CrackerBox().object_from_mesh, false});
  EXPECT_NEAR(record.diameter_m, mesh.Diameter(), 1e-12);
  EXPECT_EQ(record.mesh_sha256, Sha256OfFiles(MeshContentFiles(CrackerBox().mesh_path, mesh)));
  EXPECT_EQ(MeshContentFiles(CrackerBox().mesh_path, mesh).size(), 2U);  // the OBJ and its JPEG texture
  EXPECT_TRUE(record.object_from_mesh.isApprox(CrackerBox().object_from_mesh, 0.0));
  // The mesh is stored as loaded, in the object frame (its 1024 px texture under the 2048 px cap: as it is).
  const TriangleMesh stored = ModelMesh(record);
  ASSERT_EQ(stored.parts.size(), mesh.parts.size());
  EXPECT_EQ(stored.parts[0].positions, mesh.parts[0].positions);
  EXPECT_EQ(stored.parts[0].texcoords, mesh.parts[0].texcoords);
  EXPECT_EQ(stored.parts[0].triangles, mesh.parts[0].triangles);
  ASSERT_EQ(stored.materials.size(), mesh.materials.size());
  const size_t m = static_cast<size_t>(mesh.parts[0].material);
  EXPECT_EQ(cv::norm(stored.materials.at(m).texture, mesh.materials.at(m).texture, cv::NORM_INF), 0.0);
  for (const ModelView& view : record.views) {
    EXPECT_EQ(view.camera.width, 320);
    EXPECT_GT(view.primitives.size(), 100U) << "view " << view.index;
    EXPECT_GT(view.descriptors.values.rows, 0);
  }
  const BuildTimings& t = built_->timings;
  EXPECT_GT(t.render_ms, 0.0);
  EXPECT_GT(t.extract_ms, 0.0);
  EXPECT_GT(t.describe_ms, 0.0);
}

// The depth the extraction gives a keypoint (src/ecv/surface.cpp): the median of the rendered depths in the
// 5x5 window around it that lie within the 1 cm depth gap behind the nearest one; 0 when it sees no object.
float FrontSurfaceDepth(const cv::Mat& depth, const Eigen::Vector2f& pixel, float gap) {
  std::vector<float> values;
  const int u = static_cast<int>(pixel.x()), v = static_cast<int>(pixel.y());
  for (int y = std::max(0, v - 2); y <= std::min(depth.rows - 1, v + 2); ++y) {
    for (int x = std::max(0, u - 2); x <= std::min(depth.cols - 1, u + 2); ++x) {
      if (depth.at<float>(y, x) > 0.0F) values.push_back(depth.at<float>(y, x));
    }
  }
  if (values.empty()) return 0.0F;
  const float limit = *std::min_element(values.begin(), values.end()) + gap;
  values.erase(std::remove_if(values.begin(), values.end(), [limit](float z) { return z > limit; }), values.end());
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Each primitive, moved back by the stored camera_from_object, projects to its own keypoint with the stored
// camera at the depth the extraction reads from the rendered view there (to 0.01 mm); texlet normals face
// the camera.
TEST_F(BuiltModel, PrimitivesAreInTheObjectFrame) {
  MeshLoadOptions load;
  load.object_from_mesh = CrackerBox().object_from_mesh;
  const MeshId mesh = renderer_->AddMesh(LoadMesh(CrackerBox().mesh_path, load));
  const float gap = static_cast<float>(built_->record.features.ecv.depth_gap_m);
  for (const ModelView& view : built_->record.views) {
    const RenderResult rendered = renderer_->Render(mesh, view.camera, view.camera_from_object);
    int facing_away = 0;
    double worst_depth_error = 0.0;
    for (const Primitive& p : view.primitives) {
      const Eigen::Vector3d camera_point = view.camera_from_object * p.position.cast<double>();
      const Eigen::Vector2d pixel = view.camera.Project(camera_point);
      ASSERT_LT((pixel - p.pixel.cast<double>()).norm(), 0.01) << "view " << view.index;
      const double expected_z = FrontSurfaceDepth(rendered.depth, p.pixel, gap);
      worst_depth_error = std::max(worst_depth_error, std::abs(camera_point.z() - expected_z));
      const Eigen::Vector3d normal = view.camera_from_object.linear() * p.orientation.cast<double>();
      if (p.type == PrimitiveType::kTexlet && normal.dot(camera_point) >= 0.0) ++facing_away;
    }
    EXPECT_LT(worst_depth_error, 1e-5) << "view " << view.index;
    EXPECT_EQ(facing_away, 0) << "view " << view.index;
  }
  renderer_->RemoveMesh(mesh);
}

TEST_F(BuiltModel, RepeatsBitForBitAndSurvivesStorage) {
  ModelBuildOptions threaded = FewSmallViews(4);
  threaded.threads = 3;  // the views' descriptors do not depend on the worker threads
  const BuildResult again = BuildModel(CrackerBox(), threaded, *renderer_);
  EXPECT_EQ(test::CompareViews(built_->record.views, again.record.views), "");

  ModelDatabase database(":memory:", OpenMode::kCreate);
  database.AddModel(built_->record);
  const ModelRecord loaded = database.LoadModels().at(0).record;
  EXPECT_EQ(test::CompareViews(built_->record.views, loaded.views), "");
  // The stored descriptors are exactly those of the stored (object-frame) primitives.
  for (const ModelView& view : loaded.views) {
    const Descriptors recomputed = ComputeDescriptors(view.primitives, loaded.features.descriptor);
    ASSERT_EQ(recomputed.primitive, view.descriptors.primitive);
    EXPECT_EQ(cv::norm(recomputed.values, view.descriptors.values, cv::NORM_INF), 0.0) << "view " << view.index;
  }
}

// Mean brightness of a record's primitive colours (RGB in [0, 1]).
double MeanBrightness(const ModelRecord& record) {
  double sum = 0.0;
  size_t count = 0;
  for (const ModelView& view : record.views) {
    for (const Primitive& primitive : view.primitives) sum += primitive.color.mean();
    count += view.primitives.size();
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

// A vertex-coloured scan (LM-O's watering can) gets headlight-shaded views, a textured mesh its texture as stored;
// the choice is recorded with the build, and shade_untextured = false or --shading unlit turns it off.
TEST(ModelBuilder, ShadesMeshesWithoutATextureAndKeepsTexturesAsStored) {
  ModelSource can;
  can.mesh_path = test::DataPath("lmo_subset/data/bop/lmo/models/obj_000005.ply");
  can.unit = "mm";
  ModelBuildOptions options = FewSmallViews(2);
  const TriangleMesh can_mesh = LoadMesh(can.mesh_path, {0.001, Eigen::Isometry3d::Identity(), false});
  const TriangleMesh box_mesh = LoadMesh(CrackerBox().mesh_path, {1.0, CrackerBox().object_from_mesh, false});
  EXPECT_EQ(ViewShading(can_mesh, options), Shading::kHeadlight);
  EXPECT_EQ(ViewShading(box_mesh, options), Shading::kUnlit);
  options.render.shading = Shading::kHeadlight;
  EXPECT_EQ(ViewShading(box_mesh, options), Shading::kHeadlight);

  Renderer renderer;
  const BuildResult shaded = BuildModel(can, FewSmallViews(2), renderer);
  ModelBuildOptions flat = FewSmallViews(2);
  flat.shade_untextured = false;
  EXPECT_EQ(ViewShading(can_mesh, flat), Shading::kUnlit);
  const BuildResult unlit = BuildModel(can, flat, renderer);
  EXPECT_THAT(shaded.record.build_options_json, HasSubstr("\"shading\":\"headlight\""));
  EXPECT_THAT(unlit.record.build_options_json, HasSubstr("\"shading\":\"unlit\""));
  // What the recognizer reads back to render the model in verification as its views were rendered.
  EXPECT_EQ(StoredViewShading(shaded.record.build_options_json), Shading::kHeadlight);
  EXPECT_EQ(StoredViewShading(unlit.record.build_options_json), Shading::kUnlit);
  EXPECT_EQ(StoredViewShading("{\"views\": 40}"), Shading::kUnlit);  // built before the choice was recorded
  EXPECT_EQ(StoredViewShading("{\"shading\": 1}"), Shading::kUnlit);
  EXPECT_EQ(StoredViewShading("not json"), Shading::kUnlit);
  // Headlight scales each colour by 0.35 + 0.65 |cos(incidence)| <= 1: a curved can comes out darker.
  EXPECT_LT(MeanBrightness(shaded.record), 0.95 * MeanBrightness(unlit.record));
  EXPECT_GT(MeanBrightness(shaded.record), 0.5 * MeanBrightness(unlit.record));
}

TEST(ModelBuilder, RejectsBadOptionsAndMeshes) {
  Renderer renderer;
  ModelBuildOptions options = FewSmallViews(0);
  try {
    BuildModel(CrackerBox(), options, renderer);
    ADD_FAILURE() << "no error for 0 views";
  } catch (const InputError& error) {
    EXPECT_THAT(error.what(), HasSubstr("num_views"));
  }
  options = FewSmallViews(1);
  options.threads = 0;
  EXPECT_THROW(BuildModel(CrackerBox(), options, renderer), InputError);
  test::TemporaryDirectory directory;
  std::ofstream(directory.File("broken.obj")) << "v 0 0 0\nthis is not an OBJ line\n";
  ModelSource broken;
  broken.mesh_path = directory.File("broken.obj");
  EXPECT_THROW(BuildModel(broken, FewSmallViews(1), renderer), InputError);
  broken.mesh_path = directory.File("missing.obj");
  EXPECT_THROW(BuildModel(broken, FewSmallViews(1), renderer), InputError);
}

TEST(MeshSources, FindsModelFoldersMeshFilesAndPoseFiles) {
  test::TemporaryDirectory directory;
  namespace fs = std::filesystem;
  const fs::path root = directory.path() / "meshes";
  fs::create_directories(root / "box");
  fs::create_directories(root / "can");
  fs::create_directories(root / "empty");
  fs::create_directories(root / "bad_pose");
  std::ofstream(root / "box" / "box.obj") << "";
  std::ofstream(root / "box" / "box_low.obj") << "";  // <name>/<name>.obj wins over others
  std::ofstream(root / "box" / kObjectFromMeshFile)
      << R"({"object_from_mesh": [[1,0,0,0.5],[0,1,0,0],[0,0,1,0],[0,0,0,1]]})";
  std::ofstream(root / "can" / "textured.ply") << "";  // the only mesh of the folder
  std::ofstream(root / "bad_pose" / "bad_pose.obj") << "";
  std::ofstream(root / "bad_pose" / kObjectFromMeshFile) << R"({"object_from_mesh": 3})";
  std::ofstream(root / "loose.stl") << "";
  std::ofstream(root / "README.md") << "";

  ModelSource defaults;
  defaults.unit = "mm";
  const MeshSourceScan scan = FindMeshSources({root.string(), (directory.path() / "gone.obj").string()}, defaults);
  ASSERT_EQ(scan.sources.size(), 3U);
  EXPECT_EQ(scan.sources[0].name, "box");
  EXPECT_EQ(fs::path(scan.sources[0].mesh_path).filename(), "box.obj");
  EXPECT_DOUBLE_EQ(scan.sources[0].object_from_mesh.translation().x(), 0.5);
  EXPECT_EQ(scan.sources[0].unit, "mm");
  EXPECT_EQ(scan.sources[1].name, "can");
  EXPECT_TRUE(scan.sources[1].object_from_mesh.isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_EQ(scan.sources[2].name, "loose");
  ASSERT_EQ(scan.problems.size(), 3U);
  EXPECT_THAT(scan.problems[0], HasSubstr("bad_pose"));
  EXPECT_THAT(scan.problems[1], HasSubstr("empty: expected a mesh file empty.obj"));
  EXPECT_THAT(scan.problems[2], HasSubstr("gone.obj: expected a mesh file"));

  // Without pose files (an explicit --object-from-mesh), and a single mesh takes the given name.
  defaults.name = "renamed";
  const MeshSourceScan single = FindMeshSources({(root / "box" / "box.obj").string()}, defaults, false);
  ASSERT_EQ(single.sources.size(), 1U);
  EXPECT_EQ(single.sources[0].name, "renamed");
  EXPECT_TRUE(single.sources[0].object_from_mesh.isApprox(Eigen::Isometry3d::Identity()));
}

}  // namespace
}  // namespace ecv
