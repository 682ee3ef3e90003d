// Meshes through assimp: OBJ+MTL with texture images, PLY with vertex colours, glTF/GLB, ...

#include "io/mesh_io.h"

#include <dlfcn.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/pose.h"
#include "io/files.h"
#include "io/frame_io.h"
#include "io/glb_check.h"
#include "io/image_bytes.h"
#include "io/mesh_blob.h"
#include "io/ply_check.h"

namespace ecv {
namespace fs = std::filesystem;
namespace {

constexpr char kMeshImporterName[] = "ecvpose-mesh-import";

std::string Lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::string Trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  const size_t last = text.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

// An embedded texture ("*N" or a name matching one of the scene's textures) as RGB; compressed ones are checked as
// image files are (DecodeImage: their header's size first), named `source`.
cv::Mat DecodeEmbedded(const aiTexture& texture, const std::string& source) {
  cv::Mat bgr;
  if (texture.mHeight == 0) {  // compressed bytes (PNG, JPG) of length mWidth
    const std::string bytes(reinterpret_cast<const char*>(texture.pcData), texture.mWidth);
    bgr = DecodeImage(bytes, source, "embedded texture", cv::IMREAD_COLOR);
  } else {  // raw aiTexel (b, g, r, a) rows
    const cv::Mat bgra(static_cast<int>(texture.mHeight), static_cast<int>(texture.mWidth), CV_8UC4, texture.pcData);
    cv::cvtColor(bgra, bgr, cv::COLOR_BGRA2BGR);
  }
  cv::Mat rgb;
  if (!bgr.empty()) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

// Reads a material's texture file, named relative to the mesh's folder; a missing file is an error unless allowed.
void LoadTexture(const fs::path& mesh_dir, const std::string& mesh_path, const MeshLoadOptions& options,
                 MeshMaterial* material, std::vector<std::string>* warnings) {
  const std::string name = material->texture_path;
  if (name.empty() || !material->texture.empty()) return;  // none, or embedded (decoded already)
  std::string relative = name;
  std::replace(relative.begin(), relative.end(), '\\', '/');
  const fs::path file = mesh_dir / relative;
  material->texture_path = file.string();
  if (!PathExists(file)) {
    const std::string message =
        mesh_path + ": material '" + material->name + "': texture '" + name + "' not found at " + file.string();
    if (!options.allow_missing_textures) {
      throw InputError(message + " (give --allow-missing-textures to use vertex or material colours instead)");
    }
    if (warnings != nullptr) warnings->push_back(message + "; using vertex or material colours instead");
    material->texture_path.clear();
    return;
  }
  material->texture = ColorImageAsRgb(ReadImageFile(file.string(), "texture"), file.string());
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

// The mesh as assimp reads it, before units and transforms: geometry, materials, embedded textures decoded; texture
// files only named (MeshMaterial::texture_path as the file gives it).
TriangleMesh ImportMesh(const std::string& path) {
  Assimp::Importer importer;
  const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_FindInvalidData | aiProcess_Triangulate |
                         aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices | aiProcess_SortByPType |
                         aiProcess_GenSmoothNormals;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    ThrowInputError(path, "mesh", "a mesh file assimp can read", importer.GetErrorString());
  }
  TriangleMesh mesh;
  mesh.name = fs::path(path).stem().string();
  for (unsigned i = 0; i < scene->mNumMaterials; ++i) {
    MeshMaterial& material = mesh.materials.emplace_back(ConvertMaterial(*scene->mMaterials[i]));
    if (material.texture_path.empty()) continue;
    if (const aiTexture* embedded = scene->GetEmbeddedTexture(material.texture_path.c_str())) {
      material.texture = DecodeEmbedded(*embedded, path + ": " + material.texture_path);
      if (material.texture.empty()) {
        ThrowInputError(path, "embedded texture " + material.texture_path, "a decodable image");
      }
    }
  }
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    MeshPart part = ConvertPart(*scene->mMeshes[i]);
    if (!part.triangles.empty()) mesh.parts.push_back(std::move(part));
  }
  return mesh;
}

// Where the mesh importer program is: $ECVPOSE_MESH_IMPORTER, else in the folder "ecvpose" beside the library (or
// program) that holds this code, else where it was installed, else where it was built. Empty when none is there.
std::string FindMeshImporter(std::vector<std::string>* tried) {
  std::vector<std::string> candidates;
  if (const char* chosen = std::getenv("ECVPOSE_MESH_IMPORTER"); chosen != nullptr && *chosen != '\0') {
    candidates.emplace_back(chosen);
  } else {
    Dl_info self{};
    if (dladdr(reinterpret_cast<void*>(&FindMeshImporter), &self) != 0 && self.dli_fname != nullptr) {
      const fs::path beside = fs::path(self.dli_fname).parent_path() / "ecvpose" / kMeshImporterName;
      candidates.push_back(beside.string());
    }
    candidates.emplace_back(ECV_MESH_IMPORTER_INSTALLED);
    candidates.emplace_back(ECV_MESH_IMPORTER_BUILT);
  }
  for (const std::string& candidate : candidates) {
    if (access(candidate.c_str(), X_OK) == 0 && !IsDirectory(candidate)) return candidate;
  }
  *tried = candidates;
  return {};
}

std::string MeshImporter() {
  std::vector<std::string> tried;
  std::string path = FindMeshImporter(&tried);
  if (path.empty()) {
    std::string list;
    for (const std::string& candidate : tried) list += (list.empty() ? "" : ", ") + candidate;
    throw std::runtime_error(std::string("the mesh importer program ") + kMeshImporterName +
                             " is not where ecvpose looks for it (" + list +
                             "): reinstall ecvpose, or set ECVPOSE_MESH_IMPORTER to its path");
  }
  return path;
}

// Starts the importer program on `path`, its standard output into `output` (the pipe's write end). posix_spawn, not
// fork: a fork of a process whose other threads hold locks (the allocator's, under sanitizers) can hang the child.
pid_t SpawnImporter(const std::string& path, int output) {
  const std::string program = MeshImporter();
  const std::string parent = std::to_string(getpid());
  std::vector<char*> argv = {const_cast<char*>(program.c_str()), const_cast<char*>(path.c_str()),
                             const_cast<char*>(parent.c_str()), nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, output, STDOUT_FILENO);
  pid_t child = -1;
  const int failed = posix_spawn(&child, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (failed != 0) {
    ThrowInputError(path, "mesh", "a process to read it in", program + ": " + std::strerror(failed));
  }
  return child;
}

}  // namespace

int RunMeshImporter(const std::string& path, int fd) {
  char status = 'M';
  std::string payload;
  try {
    MeshBlobOptions raw;
    raw.max_texture_size = 0;  // embedded textures as they are
    raw.lz4_level = 1;
    const std::vector<unsigned char> blob = EncodeMeshBlob(ImportMesh(path), raw);
    payload.assign(blob.begin(), blob.end());
  } catch (const InputError& error) {
    status = 'E';
    payload = error.what();
  } catch (const std::exception& error) {  // the importer's own, e.g. a failed assertion: named with the file
    status = 'E';
    payload = path + ": mesh: expected a file the mesh importer reads, got " + error.what();
  }
  const uint64_t size = payload.size();
  const bool sent =
      WriteAll(fd, &status, 1) && WriteAll(fd, &size, sizeof(size)) && WriteAll(fd, payload.data(), payload.size());
  return sent ? 0 : 3;
}

namespace {

// ImportMesh in the importer program: assimp trusts what files say, and a malformed one can crash it or make it loop;
// a crash or a hang there becomes an InputError naming the file.
TriangleMesh ImportMeshIsolated(const std::string& path, double timeout_s) {
  int fds[2];
  // Close-on-exec: an importer started by another thread meanwhile must not hold this pipe open.
  if (pipe2(fds, O_CLOEXEC) != 0) ThrowInputError(path, "mesh", "a pipe to read it through", std::strerror(errno));
  pid_t child = -1;
  try {
    child = SpawnImporter(path, fds[1]);
  } catch (...) {
    close(fds[0]);
    close(fds[1]);
    throw;
  }
  close(fds[1]);
  std::string received;
  char buffer[1 << 16];
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  bool timed_out = false;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    pollfd ready{fds[0], POLLIN, 0};
    const int polled = left.count() > 0 ? poll(&ready, 1, static_cast<int>(left.count())) : 0;
    if (polled < 0 && errno == EINTR) continue;
    if (polled == 0) {  // the importer hangs on the file: it is ended
      timed_out = true;
      kill(child, SIGKILL);
      break;
    }
    const ssize_t got = read(fds[0], buffer, sizeof(buffer));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    received.append(buffer, static_cast<size_t>(got));
  }
  close(fds[0]);
  int wait_status = 0;
  while (waitpid(child, &wait_status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) {
    ThrowInputError(path, "mesh", "a file the mesh importer reads within " + std::to_string(timeout_s) + " s",
                    "it took longer and was stopped");
  }
  if (WIFSIGNALED(wait_status)) {
    ThrowInputError(path, "mesh", "a file the mesh importer reads without crashing",
                    std::string("the importer crashed on it (") + strsignal(WTERMSIG(wait_status)) + ")");
  }
  uint64_t size = 0;
  if (!WIFEXITED(wait_status) || WEXITSTATUS(wait_status) != 0 || received.size() < 1 + sizeof(size)) {
    ThrowInputError(path, "mesh", "a file the mesh importer reads", "the importer stopped without a result");
  }
  std::memcpy(&size, received.data() + 1, sizeof(size));
  if (received.size() != 1 + sizeof(size) + size) {
    ThrowInputError(path, "mesh", "a file the mesh importer reads", "the importer's result was cut short");
  }
  const char* payload = received.data() + 1 + sizeof(size);
  if (received[0] == 'E') throw InputError(std::string(payload, size));
  return DecodeMeshBlob(reinterpret_cast<const unsigned char*>(payload), size, path);
}

// The OBJ's material libraries (mtllib lines) must exist: assimp would build the mesh grey without a word.
void CheckObjMaterials(const std::string& path, const MeshLoadOptions& options, std::vector<std::string>* warnings) {
  std::ifstream stream(path);
  std::string line;
  while (std::getline(stream, line)) {
    std::istringstream words(line);
    std::string keyword, library;
    words >> keyword;
    if (keyword != "mtllib") continue;
    std::getline(words >> std::ws, library);
    library = Trim(library);
    const fs::path file = fs::path(path).parent_path() / library;
    if (library.empty()) continue;
    if (PathExists(file)) {
      RequireRegularFile(file.string(), "material library");  // the importer would wait on a FIFO
      continue;
    }
    const std::string message = path + ": material library '" + library + "' not found at " + file.string();
    if (!options.allow_missing_textures) {
      throw InputError(message + " (give --allow-missing-textures to build it with default colours)");
    }
    if (warnings != nullptr) warnings->push_back(message + "; using default colours");
  }
}

// Every vertex position finite: NaN or infinite coordinates would make every measure of the mesh meaningless.
void CheckFinite(const std::string& path, const TriangleMesh& mesh) {
  for (size_t p = 0; p < mesh.parts.size(); ++p) {
    const std::vector<Eigen::Vector3f>& positions = mesh.parts[p].positions;
    for (size_t i = 0; i < positions.size(); ++i) {
      if (!positions[i].allFinite()) {
        ThrowInputError(path,
                        "vertex " + std::to_string(i) + (mesh.parts.size() > 1 ? " of part " + std::to_string(p) : ""),
                        "finite coordinates", "NaN or infinite");
      }
    }
  }
}

}  // namespace

void MeshLoadOptions::Check() const {
  if (!std::isfinite(metres_per_unit) || metres_per_unit <= 0.0) {
    ThrowInputError("mesh options", "metres_per_unit", "a finite positive scale", std::to_string(metres_per_unit));
  }
  if (!object_from_mesh.matrix().allFinite()) ThrowInputError("mesh options", "object_from_mesh", "a finite transform");
  if (!(import_timeout_s > 0.0)) {
    ThrowInputError("mesh options", "import_timeout_s", "> 0 s", std::to_string(import_timeout_s));
  }
}

double MetresPerUnit(const std::string& unit) {
  if (unit == "m") return 1.0;
  if (unit == "cm") return 0.01;
  if (unit == "mm") return 0.001;
  ThrowInputError("--unit", "unit", "m, cm or mm", "'" + unit + "'");
}

std::map<std::string, Eigen::Isometry3d> ReadTransformTable(const std::string& path) {
  RequireRegularFile(path, "transform table");
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
  RequireRegularFile(path, "mesh");  // a FIFO would hang the reader, a link to /dev/zero feed it without end
  const std::string extension = Lowercase(fs::path(path).extension().string());
  CheckGlbFile(path);
  if (extension == ".ply") CheckPlyFile(path);
  if (extension == ".obj") CheckObjMaterials(path, options, warnings);

  TriangleMesh mesh = ImportMeshIsolated(path, options.import_timeout_s);
  const fs::path mesh_dir = fs::path(path).parent_path();
  for (MeshMaterial& material : mesh.materials) LoadTexture(mesh_dir, path, options, &material, warnings);
  if (mesh.NumTriangles() == 0) ThrowInputError(path, "faces", "a mesh with triangles", "no triangles");
  CheckFinite(path, mesh);
  mesh.Scale(options.metres_per_unit);
  mesh.Transform(options.object_from_mesh);
  return mesh;
}

}  // namespace ecv
