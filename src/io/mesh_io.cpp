// Meshes through assimp: OBJ+MTL with texture images, PLY with vertex colours, glTF/GLB, ...

#include "io/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/pose.h"
#include "io/frame_io.h"

namespace ecv {
namespace fs = std::filesystem;
namespace {

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::string Trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  const size_t last = text.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

// An embedded texture ("*N" or a name matching one of the scene's textures) as RGB.
cv::Mat DecodeEmbedded(const aiTexture& texture) {
  cv::Mat bgr;
  if (texture.mHeight == 0) {  // compressed bytes (PNG, JPG) of length mWidth
    const cv::Mat bytes(1, static_cast<int>(texture.mWidth), CV_8UC1, texture.pcData);
    bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
  } else {  // raw aiTexel (b, g, r, a) rows
    const cv::Mat bgra(static_cast<int>(texture.mHeight), static_cast<int>(texture.mWidth), CV_8UC4, texture.pcData);
    cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
  }
  cv::Mat rgb;
  if (!bgr.empty()) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

void LoadTexture(const aiScene& scene, const fs::path& mesh_dir, const std::string& mesh_path,
                 const MeshLoadOptions& options, MeshMaterial* material, std::vector<std::string>* warnings) {
  const std::string name = material->texture_path;
  if (name.empty()) return;
  if (const aiTexture* embedded = scene.GetEmbeddedTexture(name.c_str())) {
    material->texture = DecodeEmbedded(*embedded);
    if (material->texture.empty()) ThrowInputError(mesh_path, "embedded texture " + name, "a decodable image");
    return;
  }
  std::string relative = name;
  std::replace(relative.begin(), relative.end(), '\\', '/');
  const fs::path file = mesh_dir / relative;
  material->texture_path = file.string();
  if (!fs::exists(file)) {
    const std::string message =
        mesh_path + ": material '" + material->name + "': texture '" + name + "' not found at " + file.string();
    if (!options.allow_missing_textures) {
      throw InputError(message + " (give --allow-missing-textures to use vertex or material colours instead)");
    }
    if (warnings != nullptr) warnings->push_back(message + "; using vertex or material colours instead");
    material->texture_path.clear();
    return;
  }
  material->texture = ReadColorImage(file.string());
}

MeshMaterial ConvertMaterial(const aiMaterial& source) {
  MeshMaterial material;
  aiString name;
  if (source.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) material.name = name.C_Str();
  aiColor4D color;
  if (source.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS ||
      source.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS) {
    material.diffuse_color = {color.r, color.g, color.b};
  }
  aiString texture;
  for (aiTextureType type : {aiTextureType_DIFFUSE, aiTextureType_BASE_COLOR}) {
    if (source.GetTextureCount(type) > 0 && source.GetTexture(type, 0, &texture) == AI_SUCCESS) {
      material.texture_path = Trim(texture.C_Str());  // MTL lines often end in a space
      break;
    }
  }
  return material;
}

MeshPart ConvertPart(const aiMesh& source) {
  MeshPart part;
  part.material = static_cast<int>(source.mMaterialIndex);
  const size_t n = source.mNumVertices;
  part.positions.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const aiVector3D& p = source.mVertices[i];
    part.positions.emplace_back(p.x, p.y, p.z);
    if (source.HasNormals()) {
      const aiVector3D& normal = source.mNormals[i];
      part.normals.emplace_back(Eigen::Vector3f(normal.x, normal.y, normal.z).normalized());
    }
    if (source.HasTextureCoords(0))
      part.texcoords.emplace_back(source.mTextureCoords[0][i].x, source.mTextureCoords[0][i].y);
    if (source.HasVertexColors(0)) {
      const aiColor4D& c = source.mColors[0][i];
      part.colors.emplace_back(c.r, c.g, c.b);
    }
  }
  for (unsigned f = 0; f < source.mNumFaces; ++f) {
    const aiFace& face = source.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left by the importer
    part.triangles.emplace_back(face.mIndices[0], face.mIndices[1], face.mIndices[2]);
  }
  return part;
}

}  // namespace

void MeshLoadOptions::Check() const {
  if (!std::isfinite(metres_per_unit) || metres_per_unit <= 0.0) {
    ThrowInputError("mesh options", "metres_per_unit", "a finite positive scale", std::to_string(metres_per_unit));
  }
  if (!object_from_mesh.matrix().allFinite()) ThrowInputError("mesh options", "object_from_mesh", "a finite transform");
}

double MetresPerUnit(const std::string& unit) {
  if (unit == "m") return 1.0;
  if (unit == "cm") return 0.01;
  if (unit == "mm") return 0.001;
  ThrowInputError("--unit", "unit", "m, cm or mm", "'" + unit + "'");
}

std::map<std::string, Eigen::Isometry3d> ReadTransformTable(const std::string& path) {
  std::ifstream stream(path);
  if (!stream) ThrowInputError(path, "transform table", "a readable file");
  std::map<std::string, Eigen::Isometry3d> table;
  std::string line;
  for (int number = 1; std::getline(stream, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string name;
    Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
    fields >> name;
    for (int r = 0; r < 3; ++r) fields >> matrix(r, 0) >> matrix(r, 1) >> matrix(r, 2);
    fields >> matrix(0, 3) >> matrix(1, 3) >> matrix(2, 3);
    const std::string where = "line " + std::to_string(number);
    if (!fields) ThrowInputError(path, where, "a name and 12 numbers (R row-major, then t)", "'" + line + "'");
    table[name] = RigidFromMatrix(matrix, path, where);
  }
  return table;
}

bool LooksLikeMesh(const std::string& path) {
  static const char* const kExtensions[] = {".obj", ".ply", ".gltf", ".glb", ".stl", ".off", ".fbx", ".dae", ".3ds"};
  const std::string extension = Lowercase(fs::path(path).extension().string());
  return std::find(std::begin(kExtensions), std::end(kExtensions), extension) != std::end(kExtensions);
}

TriangleMesh LoadMesh(const std::string& path, const MeshLoadOptions& options, std::vector<std::string>* warnings) {
  options.Check();
  if (!fs::exists(path)) ThrowInputError(path, "mesh", "an existing file", "no such file");
  if (fs::is_directory(path)) ThrowInputError(path, "mesh", "a mesh file", "a directory");

  Assimp::Importer importer;
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_GenSmoothNormals;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    ThrowInputError(path, "mesh", "a mesh file assimp can read", importer.GetErrorString());
  }

  TriangleMesh mesh;
  mesh.name = fs::path(path).stem().string();
  const fs::path mesh_dir = fs::path(path).parent_path();
  for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
    mesh.materials.push_back(ConvertMaterial(*scene->mMaterials[i]));
    LoadTexture(*scene, mesh_dir, path, options, &mesh.materials.back(), warnings);
  }
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    MeshPart part = ConvertPart(*scene->mMeshes[i]);
    if (!part.triangles.empty()) mesh.parts.push_back(std::move(part));
  }
  if (mesh.NumTriangles() == 0) ThrowInputError(path, "faces", "a mesh with triangles", "no triangles");

  mesh.Scale(options.metres_per_unit);
  mesh.Transform(options.object_from_mesh);
  return mesh;
}

}  // namespace ecv
