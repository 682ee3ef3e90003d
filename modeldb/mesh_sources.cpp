#include "modeldb/mesh_sources.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>

#include "core/error.h"
#include "io/mesh_io.h"
#include "io/pose_io.h"

namespace fs = std::filesystem;

namespace ecv {
namespace {

std::vector<fs::path> SortedEntries(const fs::path& directory) {
  std::vector<fs::path> entries;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory)) {
    if (entry.path().filename().string().rfind('.', 0) != 0) entries.push_back(entry.path());  // not hidden
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

bool IsMeshFile(const fs::path& path) {
  return fs::is_regular_file(path) && LooksLikeMesh(path.string());
}

// Adds the model of `mesh` named `name`, with the pose file beside it if there is one.
void AddSource(const fs::path& mesh, const std::string& name, const ModelSource& defaults, bool use_pose_files,
               MeshSourceScan* scan) {
  ModelSource source = defaults;
  source.mesh_path = mesh.string();
  source.name = name;
  const fs::path pose_file = mesh.parent_path() / kObjectFromMeshFile;
  if (use_pose_files && fs::is_regular_file(pose_file)) {
    try {
      source.object_from_mesh = ReadPoseFile(pose_file.string(), "object_from_mesh");
    } catch (const InputError& error) {
      scan->problems.push_back(name + ": " + error.what());
      return;
    }
  }
  scan->sources.push_back(source);
}

// The mesh of a model subfolder: <sub>/<sub>.<ext>, else its only mesh file.
void ScanSubfolder(const fs::path& folder, const ModelSource& defaults, bool use_pose_files, MeshSourceScan* scan) {
  const std::string name = folder.filename().string();
  std::vector<fs::path> meshes;
  for (const fs::path& entry : SortedEntries(folder)) {
    if (IsMeshFile(entry)) meshes.push_back(entry);
  }
  const auto named = std::find_if(meshes.begin(), meshes.end(), [&](const fs::path& p) { return p.stem() == name; });
  if (named != meshes.end()) {
    AddSource(*named, name, defaults, use_pose_files, scan);
  } else if (meshes.size() == 1) {
    AddSource(meshes.front(), name, defaults, use_pose_files, scan);
  } else {
    scan->problems.push_back(folder.string() + ": expected a mesh file " + name + ".obj (or .ply, .gltf, ...), found " +
                             (meshes.empty() ? std::string("none") : std::to_string(meshes.size()) + " other ones"));
  }
}

}  // namespace

MeshSourceScan FindMeshSources(const std::vector<std::string>& paths, const ModelSource& defaults,
                               bool use_pose_files) {
  MeshSourceScan scan;
  const bool single = paths.size() == 1 && IsMeshFile(paths.front());
  for (const std::string& text : paths) {
    const fs::path path(text);
    if (fs::is_directory(path)) {
      for (const fs::path& entry : SortedEntries(path)) {
        if (fs::is_directory(entry)) ScanSubfolder(entry, defaults, use_pose_files, &scan);
        if (IsMeshFile(entry)) AddSource(entry, entry.stem().string(), defaults, use_pose_files, &scan);
      }
    } else if (IsMeshFile(path)) {
      const std::string name = single && !defaults.name.empty() ? defaults.name : path.stem().string();
      AddSource(path, name, defaults, use_pose_files, &scan);
    } else {
      scan.problems.push_back(text + ": expected a mesh file (.obj .ply .gltf .glb .stl .off ...) or a directory" +
                              (fs::exists(path) ? std::string(", got another file") : ", got no such path"));
    }
  }
  return scan;
}

int ShardOfName(const std::string& name, int parts) {
  if (parts <= 1) return 0;
  uint64_t hash = 14695981039346656037ULL;  // FNV-1a, 64 bits
  for (const char c : name) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ULL;
  }
  return static_cast<int>(hash % static_cast<uint64_t>(parts));
}

void KeepShard(int part, int parts, MeshSourceScan* scan) {
  const auto other = [&](const std::string& key) { return ShardOfName(key, parts) != part; };
  std::vector<ModelSource>& sources = scan->sources;
  sources.erase(std::remove_if(sources.begin(), sources.end(), [&](const ModelSource& s) { return other(s.name); }),
                sources.end());
  std::vector<std::string>& problems = scan->problems;
  problems.erase(std::remove_if(problems.begin(), problems.end(),
                                [&](const std::string& p) { return other(p.substr(0, p.find(':'))); }),
                 problems.end());
}

}  // namespace ecv
