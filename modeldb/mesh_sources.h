#pragma once

#include <string>
#include <vector>

#include "modeldb/model_builder.h"

namespace ecv {

/// Models to build, found from the paths given to `modeldb build`, and what could not be used.
struct MeshSourceScan {
  std::vector<ModelSource> sources;
  std::vector<std::string> problems;  ///< one line each, naming the path and what was expected
};

/// Turns mesh files and directories into model sources, each a copy of `defaults` with its mesh and name:
/// - a mesh file: one model named after the file's stem;
/// - a directory: each subfolder's mesh, `<sub>/<sub>.<ext>` (or the only mesh file in it), named after the
///   subfolder, and each mesh file directly in the directory, named after its stem.
/// An `object_from_mesh.json` beside a mesh (key "object_from_mesh") is used unless `use_pose_files` is false.
/// A missing path, a subfolder without a mesh or with several, and a malformed pose file are problems, not
/// exceptions, so that the other models can still be built. `defaults.name` is used only for a single mesh.
MeshSourceScan FindMeshSources(const std::vector<std::string>& paths, const ModelSource& defaults,
                               bool use_pose_files = true);

/// The part, 0..parts-1, that a model of this name belongs to when a build is split into `parts` (modeldb build
/// --shard): FNV-1a of the name's bytes, so the same on every machine and unchanged when models are added.
int ShardOfName(const std::string& name, int parts);

/// Keeps the sources of part `part` (0..parts-1) and the problems whose name or path (the text before their first
/// ':') falls into it, so that the parts of a scan hold each of its models and problems once.
void KeepShard(int part, int parts, MeshSourceScan* scan);

/// Name of the pose file looked for beside each mesh.
inline constexpr const char* kObjectFromMeshFile = "object_from_mesh.json";

}  // namespace ecv
