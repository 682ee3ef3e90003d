// A mesh packed into bytes (io/mesh_blob.h) and back: real YCB and LM-O meshes round-trip exactly, textures are
// capped as the renderer caps them, and broken bytes are reported, never read past.

#include <cstring>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/mesh_blob.h"
#include "io/mesh_io.h"
#include "support/test_data.h"

namespace ecv {
namespace {

template <typename Vector>
bool SameArrays(const std::vector<Vector>& a, const std::vector<Vector>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Vector)) == 0);
}

bool SameImages(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && (a.empty() || cv::norm(a, b, cv::NORM_INF) == 0.0);
}

// Every array bit for bit, every material; textures compared by the caller.
void ExpectSameGeometry(const TriangleMesh& a, const TriangleMesh& b) {
  EXPECT_EQ(a.name, b.name);
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (size_t p = 0; p < a.parts.size(); ++p) {
    EXPECT_EQ(a.parts[p].material, b.parts[p].material) << "part " << p;
    EXPECT_TRUE(SameArrays(a.parts[p].positions, b.parts[p].positions)) << "part " << p;
    EXPECT_TRUE(SameArrays(a.parts[p].normals, b.parts[p].normals)) << "part " << p;
    EXPECT_TRUE(SameArrays(a.parts[p].texcoords, b.parts[p].texcoords)) << "part " << p;
    EXPECT_TRUE(SameArrays(a.parts[p].colors, b.parts[p].colors)) << "part " << p;
    EXPECT_TRUE(SameArrays(a.parts[p].triangles, b.parts[p].triangles)) << "part " << p;
  }
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t m = 0; m < a.materials.size(); ++m) {
    EXPECT_EQ(a.materials[m].name, b.materials[m].name);
    EXPECT_EQ(a.materials[m].texture_path, b.materials[m].texture_path);
    EXPECT_EQ(a.materials[m].diffuse_color, b.materials[m].diffuse_color);
  }
}

TriangleMesh RoundTrip(const TriangleMesh& mesh, const MeshBlobOptions& options = {}) {
  const std::vector<unsigned char> blob = EncodeMeshBlob(mesh, options);
  return DecodeMeshBlob(blob.data(), blob.size(), "test blob");
}

TEST(MeshBlob, ATexturedYcbMeshRoundTripsWithItsTextureCappedAsTheRendererCapsIt) {
  MeshLoadOptions load;
  load.object_from_mesh.translate(Eigen::Vector3d(0.01, -0.02, 0.03));
  const TriangleMesh mesh =
      LoadMesh(test::DataPath("ycbv_subset/ycb_google16k_textured/006_mustard_bottle_textured.obj"), load);
  const size_t m = static_cast<size_t>(mesh.parts.at(0).material);  // the textured part's material
  ASSERT_EQ(mesh.materials.at(m).texture.size(), cv::Size(4096, 4096));

  MeshBlobOptions options;
  options.max_texture_size = 1024;
  const TriangleMesh decoded = RoundTrip(mesh, options);
  ExpectSameGeometry(mesh, decoded);
  cv::Mat expected;  // what render/gl_resources.cpp uploads for a cap of 1024
  cv::resize(mesh.materials[m].texture, expected, cv::Size(), 0.25, 0.25, cv::INTER_AREA);
  EXPECT_TRUE(SameImages(decoded.materials[m].texture, expected));
  EXPECT_EQ(decoded.IsClosedOutward(), mesh.IsClosedOutward());
  EXPECT_EQ(decoded.Diameter(), mesh.Diameter());

  options.max_texture_size = 0;  // as it is
  const std::vector<unsigned char> full = EncodeMeshBlob(mesh, options);
  EXPECT_TRUE(SameImages(DecodeMeshBlob(full.data(), full.size(), "test blob").materials[m].texture,
                         mesh.materials[m].texture));
  const TriangleMesh geometry = DecodeMeshBlob(full.data(), full.size(), "test blob", /*with_textures=*/false);
  ExpectSameGeometry(mesh, geometry);
  EXPECT_TRUE(geometry.materials[m].texture.empty());
}

TEST(MeshBlob, AVertexColouredLmoScanRoundTripsExactly) {
  MeshLoadOptions load;
  load.metres_per_unit = 0.001;
  const TriangleMesh mesh = LoadMesh(test::DataPath("lmo_subset/data/bop/lmo/models/obj_000005.ply"), load);
  ASSERT_FALSE(mesh.parts.at(0).colors.empty());
  const TriangleMesh decoded = RoundTrip(mesh);
  ExpectSameGeometry(mesh, decoded);
  EXPECT_EQ(decoded.Coloring(decoded.parts[0]), MeshColoring::kVertexColor);
}

TEST(MeshBlob, BrokenBytesAreReportedByField) {
  TriangleMesh mesh;
  mesh.name = "square";
  MeshPart& part = mesh.parts.emplace_back();
  part.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  part.triangles = {{0, 1, 2}, {0, 2, 3}};
  part.texcoords = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  part.material = 0;
  MeshMaterial& material = mesh.materials.emplace_back();
  material.texture = cv::Mat(6, 8, CV_8UC3);
  cv::randu(material.texture, 0, 256);
  const std::vector<unsigned char> blob = EncodeMeshBlob(mesh);
  const TriangleMesh decoded = RoundTrip(mesh);
  EXPECT_EQ(decoded.parts.at(0).triangles, part.triangles);
  EXPECT_TRUE(SameImages(decoded.materials.at(0).texture, material.texture));

  auto error_of = [](std::vector<unsigned char> bytes) -> std::string {
    try {
      DecodeMeshBlob(bytes.data(), bytes.size(), "lib.sqlite: model square: stored mesh");
    } catch (const InputError& error) {
      return error.what();
    }
    return "";
  };
  for (size_t size = 0; size < blob.size(); ++size) {  // cut anywhere
    const std::string error = error_of({blob.begin(), blob.begin() + static_cast<std::ptrdiff_t>(size)});
    ASSERT_NE(error.find("lib.sqlite: model square: stored mesh"), std::string::npos) << size << ": " << error;
  }
  std::vector<unsigned char> other = blob;
  other[7] = '2';
  EXPECT_NE(error_of(other).find("header: expected a mesh of format ECVMESH1"), std::string::npos);
  std::vector<unsigned char> index = blob;
  index[index.size() - 4] = 9;  // the last triangle's last index: 3 -> 9
  EXPECT_NE(error_of(index).find("triangles: expected vertex indices below 4"), std::string::npos) << error_of(index);
  std::vector<unsigned char> wide = blob;  // the texture's width, after the name, material count, name, colour, path
  const size_t width_at = 8 + 4 + mesh.name.size() + 4 + 4 + 12 + 4;
  ASSERT_EQ(wide[width_at], 8);
  wide[width_at] = 9;  // 9 x 6 pixels where the data holds 8 x 6
  EXPECT_NE(error_of(wide).find("texture: expected LZ4 data of 9 x 6 RGB pixels"), std::string::npos) << error_of(wide);
  std::vector<unsigned char> longer = blob;
  longer.push_back(0);
  EXPECT_NE(error_of(longer).find("end"), std::string::npos);

  MeshBlobOptions bad;
  bad.lz4_level = 13;
  EXPECT_THROW(EncodeMeshBlob(mesh, bad), InputError);
  bad = {};
  bad.max_texture_size = -1;
  EXPECT_THROW(bad.Check(), InputError);
}

}  // namespace
}  // namespace ecv
