#pragma once

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/mesh.h"

namespace ecv {

/// How to read a mesh file into the object frame.
struct MeshLoadOptions {
  double metres_per_unit = 1.0;  ///< scale of the file's coordinates: 1 for metres, 0.001 for millimetres
  /// Applied after the unit change: x_object = R x_mesh + t (t in metres).
  Eigen::Isometry3d object_from_mesh = Eigen::Isometry3d::Identity();
  /// When a referenced texture file is missing, use vertex or material colours (with a warning) instead of
  /// failing.
  bool allow_missing_textures = false;
  /// The importer reads the file in its own process (the program ecvpose-mesh-import); one that takes longer than
  /// this (seconds) is ended and the file refused (a malformed file can make it loop).
  double import_timeout_s = 120.0;

  void Check() const;
};

/// Scale for a unit name: "m" -> 1, "mm" -> 0.001, "cm" -> 0.01; throws InputError otherwise.
double MetresPerUnit(const std::string& unit);

/// Loads OBJ (+MTL and texture images), PLY (vertex colours), glTF/GLB and the other formats assimp
/// reads. The file must be a regular one; PLY and GLB files are checked first (CheckPlyFile, CheckGlbFile), texture
/// images by their header's size (ReadImageFile), and assimp reads the file in a process of its own (the program
/// ecvpose-mesh-import, found beside the ecvpose libraries or at $ECVPOSE_MESH_IMPORTER), so that a crash, an
/// exception or a hang of it becomes an error naming the file. Safe to call from several threads at once. Throws
/// InputError for a missing, malformed or unreadable file, a mesh without triangles or with non-finite vertices, or a
/// missing texture or material library (unless allowed); `warnings` (may be null) receives what was tolerated.
TriangleMesh LoadMesh(const std::string& path, const MeshLoadOptions& options = {},
                      std::vector<std::string>* warnings = nullptr);

/// The work of the program ecvpose-mesh-import: reads `path` with assimp and writes to `fd` the mesh, or the error's
/// message, in the form LoadMesh reads back. Returns the program's exit code (0, or 3 when `fd` closed early).
int RunMeshImporter(const std::string& path, int fd);

/// Rigid transforms by name from a text table with lines "name r11 r12 r13 r21 r22 r23 r31 r32 r33 tx ty tz
/// [anything]" ('#' starts a comment), such as YCB's derived/google16k_to_ycbv.txt (p_to = R p_from + t,
/// metres). Throws InputError naming the file and line on a malformed row or a non-rigid matrix.
std::map<std::string, Eigen::Isometry3d> ReadTransformTable(const std::string& path);

/// True for file extensions LoadMesh is meant for (.obj .ply .gltf .glb .stl .off .fbx .dae .3ds).
bool LooksLikeMesh(const std::string& path);

}  // namespace ecv
