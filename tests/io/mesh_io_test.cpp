// Real meshes: YCB textured OBJs (texture images), LM-O PLYs (vertex colours, millimetres).

#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/pose.h"
#include "io/mesh_io.h"
#include "io/points_io.h"
#include "io/pose_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

const char* const kTexturedYcb[] = {"003_cracker_box",    "004_sugar_box",   "005_tomato_soup_can",
                                    "006_mustard_bottle", "009_gelatin_box", "010_potted_meat_can"};

std::string TexturedObj(const std::string& name) {
  return test::DataPath("ycbv_subset/ycb_google16k_textured/" + name + "_textured.obj");
}

TEST(MeshIo, YcbTexturedObjsLoadWithTheirTextures) {
  for (const char* name : kTexturedYcb) {
    const TriangleMesh mesh = LoadMesh(TexturedObj(name));
    ASSERT_EQ(mesh.parts.size(), 1U) << name;
    const MeshPart& part = mesh.parts[0];
    EXPECT_EQ(mesh.Coloring(part), MeshColoring::kTexture) << name;
    EXPECT_EQ(part.texcoords.size(), part.positions.size()) << name;
    const cv::Mat& texture = mesh.materials.at(static_cast<size_t>(part.material)).texture;
    EXPECT_EQ(texture.size(), cv::Size(4096, 4096)) << name;
    EXPECT_EQ(texture.type(), CV_8UC3) << name;
    EXPECT_GT(mesh.NumTriangles(), 10000U) << name;
    // Everyday objects in metres: between 5 and 30 cm across.
    EXPECT_GT(mesh.Diameter(), 0.05) << name;
    EXPECT_LT(mesh.Diameter(), 0.30) << name;
    for (const Eigen::Vector2f& uv : part.texcoords) {
      ASSERT_TRUE(uv.x() >= -1e-3F && uv.x() <= 1.001F && uv.y() >= -1e-3F && uv.y() <= 1.001F) << name;
    }
  }
}

// Mapped by object_from_mesh (derived/google16k_to_ycbv.txt), the google_16k mesh lands on the YCB-Video
// model frame: its box agrees with that of the YCB-Video evaluation points within 5 mm.
TEST(MeshIo, ObjectFromMeshMapsGoogle16kIntoTheYcbvFrame) {
  const auto table = ReadTransformTable(test::DataPath("ycbv_subset/derived/google16k_to_ycbv.txt"));
  ASSERT_EQ(table.size(), 6U);
  for (const auto& [name, object_from_mesh] : table) {
    MeshLoadOptions options;
    options.object_from_mesh = object_from_mesh;
    const Eigen::AlignedBox3d mesh_box = LoadMesh(TexturedObj(name), options).BoundingBox();
    Eigen::AlignedBox3d points_box;
    for (const Eigen::Vector3d& p : ReadXyzFile(test::DataPath("ycbv_subset/models/" + name + "/points.xyz"))) {
      points_box.extend(p);
    }
    EXPECT_LT((mesh_box.min() - points_box.min()).cwiseAbs().maxCoeff(), 0.005) << name;
    EXPECT_LT((mesh_box.max() - points_box.max()).cwiseAbs().maxCoeff(), 0.005) << name;
  }
}

TEST(MeshIo, LmoPlysLoadWithVertexColoursInMetresAndBopDiameters) {
  const nlohmann::json info = ReadJsonFile(test::DataPath("lmo_subset/data/bop/lmo/models/models_info.json"));
  MeshLoadOptions millimetres;
  millimetres.metres_per_unit = MetresPerUnit("mm");
  int checked = 0;
  for (const auto& [id, entry] : info.items()) {
    char name[32];
    std::snprintf(name, sizeof(name), "obj_%06d.ply", std::stoi(id));
    const TriangleMesh mesh =
        LoadMesh(test::DataPath(std::string("lmo_subset/data/bop/lmo/models/") + name), millimetres);
    ASSERT_EQ(mesh.parts.size(), 1U) << name;
    EXPECT_EQ(mesh.Coloring(mesh.parts[0]), MeshColoring::kVertexColor) << name;
    EXPECT_EQ(mesh.parts[0].colors.size(), mesh.parts[0].positions.size()) << name;
    Eigen::Vector3f mean_color = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& c : mesh.parts[0].colors) mean_color += c;
    mean_color /= static_cast<float>(mesh.parts[0].colors.size());
    EXPECT_GT(mean_color.maxCoeff(), 0.05F) << name << ": colours in [0, 1], not all black";
    EXPECT_LE(mean_color.maxCoeff(), 1.0F) << name;
    const double diameter_m = entry["diameter"].get<double>() / 1000.0;
    EXPECT_NEAR(mesh.Diameter(), diameter_m, 0.01 * diameter_m) << name;
    EXPECT_NEAR(mesh.BoundingBox().min().x(), entry["min_x"].get<double>() / 1000.0, 1e-4) << name;
    ++checked;
  }
  EXPECT_EQ(checked, 8);
}

// Which real meshes close outwards (verification renders skip their back faces): every textured YCB mesh and the
// YCB-Video banana; 6 of the 8 LM-O scans, the can (obj_000005) and the eggbox (obj_000010) having open edges.
TEST(MeshIo, RealMeshesCloseOutwardsButTwoLmoScans) {
  for (const char* name : kTexturedYcb) EXPECT_TRUE(LoadMesh(TexturedObj(name)).IsClosedOutward()) << name;
  EXPECT_TRUE(LoadMesh(test::DataPath("ycbv_subset/models/011_banana/textured_simple.obj")).IsClosedOutward());
  for (const int id : {1, 5, 6, 8, 9, 10, 11, 12}) {
    char name[32];
    std::snprintf(name, sizeof(name), "obj_%06d.ply", id);
    const TriangleMesh mesh = LoadMesh(test::DataPath(std::string("lmo_subset/data/bop/lmo/models/") + name));
    EXPECT_EQ(mesh.IsClosedOutward(), id != 5 && id != 10) << name;
  }
}

TEST(MeshIo, MissingTextureIsAllowedOnRequestWithAWarning) {
  const std::string path = test::DataPath("ycbv_subset/models/003_cracker_box/textured_simple.obj");
  MeshLoadOptions options;
  options.allow_missing_textures = true;
  std::vector<std::string> warnings;
  const TriangleMesh mesh = LoadMesh(path, options, &warnings);
  ASSERT_EQ(warnings.size(), 1U);
  EXPECT_NE(warnings[0].find("texture_map.png"), std::string::npos) << warnings[0];
  // Without its texture the mesh falls back to the grey vertex colours of its OBJ "v x y z r g b" lines.
  const MeshPart& part = mesh.parts.at(0);
  EXPECT_EQ(mesh.Coloring(part), MeshColoring::kVertexColor);
  EXPECT_TRUE(mesh.materials.at(static_cast<size_t>(part.material)).texture.empty());
  EXPECT_NEAR(part.colors.at(0).x(), 0.752941F, 1e-5F);
  EXPECT_NEAR(mesh.materials.at(static_cast<size_t>(part.material)).diffuse_color.x(), 0.639216F, 1e-5F);  // MTL Kd
}

TEST(MeshIo, RecognisesMeshExtensions) {
  EXPECT_TRUE(LooksLikeMesh("a/b.OBJ"));
  EXPECT_TRUE(LooksLikeMesh("model.ply"));
  EXPECT_TRUE(LooksLikeMesh("scene.glb"));
  EXPECT_FALSE(LooksLikeMesh("cloud.pcd"));
  EXPECT_FALSE(LooksLikeMesh("Example-Scenes/0001/000001"));
}

}  // namespace
}  // namespace ecv
