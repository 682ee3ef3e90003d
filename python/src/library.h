#pragma once

// The Python module's model library: the loaded models, and a renderer of their meshes made when first asked for.

#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "modeldb/model_library.h"
#include "render/renderer.h"

namespace ecv::python {

class Library {
 public:
  Library(std::string path, ModelLibrary library) : path_(std::move(path)), library_(std::move(library)) {}

  const std::string& path() const { return path_; }
  const ModelLibrary& library() const { return library_; }

  /// `model` rendered at `camera_from_object` as its views were shaded; throws InputError naming an unknown model.
  RenderResult Render(const std::string& model, const Eigen::Isometry3d& camera_from_object,
                      const PinholeCamera& camera);

 private:
  std::string path_;
  ModelLibrary library_;
  std::mutex render_mutex_;             // one render at a time: the renderer is not shared between threads
  std::unique_ptr<Renderer> renderer_;  // made by the first Render
  std::map<std::string, MeshId> meshes_;
};

}  // namespace ecv::python
