// The Python module's ModelLibrary, build_models and render.

#include "library.h"

#include <algorithm>
#include <thread>

#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "arrays.h"
#include "bindings.h"
#include "core/error.h"
#include "core/parallel.h"
#include "io/pose_io.h"
#include "modeldb/library_build.h"
#include "modeldb/mesh_sources.h"
#include "modeldb/model_builder.h"

namespace ecv::python {

RenderResult Library::Render(const std::string& model, const Eigen::Isometry3d& camera_from_object,
                             const PinholeCamera& camera) {
  const LibraryModel* found = library_.Find(model);
  if (found == nullptr) ThrowInputError(path_, "model", "the name of one of its models", model);
  const std::lock_guard<std::mutex> lock(render_mutex_);
  if (!renderer_) renderer_ = std::make_unique<Renderer>();
  auto mesh = meshes_.find(model);
  if (mesh == meshes_.end()) mesh = meshes_.emplace(model, renderer_->AddMesh(ModelMesh(found->record))).first;
  RenderOptions options;
  options.shading = StoredViewShading(found->record.build_options_json);
  return renderer_->Render(mesh->second, camera, camera_from_object, options);
}

namespace {

// What Python sees of a library model.
struct ModelInfo {
  std::string name;
  double diameter_m = 0.0;
  bool symmetric = false;
  int views = 0;
};

std::shared_ptr<Library> OpenLibrary(const std::string& path, const std::vector<std::string>& models) {
  LibraryLoadOptions load;
  load.names = models;
  load.build_matchers = false;  // the recognizer indexes the scene and queries the views
  py::gil_scoped_release release;
  return std::make_shared<Library>(path, ModelLibrary::Load(path, load));
}

// build_models' keyword arguments, as `ecvpose modeldb build` takes them as flags.
struct BuildArguments {
  std::optional<std::string> name;
  std::string unit = "m";
  py::object object_from_mesh;  // None, a 4x4 array or the path of a pose JSON
  bool symmetric = false;
  bool allow_missing_textures = false;
  int views = ModelBuildOptions::DefaultSampling().num_views;
  double distance = ModelBuildOptions().distance_m;
  py::object camera;  // None (YCB-Video's) or a 3x3 K
  std::pair<int, int> size{640, 480};
  std::string shading = "auto";
  int threads = 0;  // 0: every core
  bool stored_mesh = true;
  bool point_pairs = true;
  int mesh_texture_size = MeshBlobOptions().max_texture_size;
  py::object feature_settings;      // None or a dict as `modeldb info` shows them
  std::pair<int, int> shard{0, 1};  // (part, parts): build only that part of the models (modeldb build --shard)
};

ModelBuildOptions BuildOptions(const BuildArguments& args) {
  ModelBuildOptions options;
  if (args.views < 1) ThrowInputError("views", "", "a whole number >= 1", std::to_string(args.views));
  options.sampling.num_views = args.views;
  options.distance_m = args.distance;
  if (args.threads < 0 || args.threads > kMaxThreads) {
    ThrowInputError("threads", "", "0 (every core) or 1 to " + std::to_string(kMaxThreads),
                    std::to_string(args.threads));
  }
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  options.threads = args.threads > 0 ? args.threads : std::min(cores, kMaxThreads);
  if (args.size.first < 1 || args.size.second < 1) {
    ThrowInputError("size", "", "(width, height) in pixels, each >= 1",
                    std::to_string(args.size.first) + "x" + std::to_string(args.size.second));
  }
  if (!args.camera.is_none()) {
    options.camera = CameraFromK(args.camera, args.size.first, args.size.second, "camera");
  } else {
    options.camera.width = args.size.first, options.camera.height = args.size.second;
  }
  if (args.shading != "auto" && args.shading != "unlit" && args.shading != "headlight") {
    ThrowInputError("shading", "", "auto, unlit or headlight", args.shading);
  }
  options.render.shading = args.shading == "headlight" ? Shading::kHeadlight : Shading::kUnlit;
  options.shade_untextured = args.shading == "auto";
  options.store_mesh = args.stored_mesh;
  options.point_pairs = args.point_pairs;
  options.mesh_blob.max_texture_size = args.mesh_texture_size;
  if (!args.feature_settings.is_none()) {
    const std::string text = py::module_::import("json").attr("dumps")(args.feature_settings).cast<std::string>();
    options.features = FeatureSettingsFromJson(text, "feature_settings");
    options.features.ecv.Check();
    options.features.descriptor.Check();
  }
  options.Check();
  return options;
}

ModelSource SourceDefaults(const BuildArguments& args) {
  ModelSource defaults;
  defaults.name = args.name.value_or("");
  defaults.unit = args.unit;
  defaults.allow_missing_textures = args.allow_missing_textures;
  defaults.symmetric = args.symmetric;
  if (py::isinstance<py::str>(args.object_from_mesh)) {
    const std::string path = args.object_from_mesh.cast<std::string>();
    defaults.object_from_mesh = ReadPoseFile(path, "object_from_mesh");
  } else if (!args.object_from_mesh.is_none()) {
    defaults.object_from_mesh = PoseFromArray(args.object_from_mesh, "object_from_mesh");
  }
  return defaults;
}

// Builds the models and returns their names; raises InputError naming each model that failed (the others stored).
std::vector<std::string> BuildModels(const std::string& db, const std::vector<std::string>& meshes,
                                     const BuildArguments& args, const py::object& progress) {
  if (meshes.empty()) ThrowInputError("meshes", "", "at least one mesh file or directory", "none");
  const ModelBuildOptions options = BuildOptions(args);
  const auto [part, parts] = args.shard;
  if (parts < 1 || part < 0 || part >= parts) {
    ThrowInputError("shard", "", "(part, parts) with 0 <= part < parts",
                    "(" + std::to_string(part) + ", " + std::to_string(parts) + ")");
  }
  MeshSourceScan scan = FindMeshSources(meshes, SourceDefaults(args), args.object_from_mesh.is_none());
  KeepShard(part, parts, &scan);
  if (args.name && scan.sources.size() != 1) {
    ThrowInputError("name", "", "one mesh to name", std::to_string(scan.sources.size()) + " meshes");
  }
  std::vector<std::string> failures = scan.problems;
  LibraryBuildReporter reporter;
  reporter.failed = [&](const ModelSource& source, const std::string& message) {
    failures.push_back(source.name + ": " + message);
  };
  if (!progress.is_none()) {
    reporter.progress = [&](const ModelSource& source, const BuildProgress& p) {
      const py::gil_scoped_acquire acquire;
      progress(source.name, p.view, p.num_views);
    };
  }
  LibraryBuildSummary summary;
  {
    py::gil_scoped_release release;
    summary = BuildLibrary(db, scan.sources, options, reporter);
  }
  if (!failures.empty()) {
    std::string message = std::to_string(failures.size()) + " of " +
                          std::to_string(scan.sources.size() + scan.problems.size()) + " models failed (" +
                          std::to_string(summary.built.size()) + " built into " + db + ")";
    for (const std::string& failure : failures) message += "\n  " + failure;
    throw InputError(message);
  }
  return summary.built;
}

}  // namespace

void BindLibrary(py::module_& m) {
  py::class_<ModelInfo>(m, "Model", "One model of a library.")
      .def_readonly("name", &ModelInfo::name)
      .def_readonly("diameter_m", &ModelInfo::diameter_m, "largest distance between two vertices, metres")
      .def_readonly("symmetric", &ModelInfo::symmetric, "evaluated with ADD-S")
      .def_readonly("views", &ModelInfo::views, "rendered views stored")
      .def("__repr__", [](const ModelInfo& model) {
        return "<ecvpose.Model " + model.name + ", " + std::to_string(model.views) + " views>";
      });

  py::class_<Library, std::shared_ptr<Library>>(m, "ModelLibrary", "A model library (SQLite), loaded once.")
      .def_static("open", &OpenLibrary, py::arg("path"), py::arg("models") = std::vector<std::string>{},
                  "Loads the library at `path` (only `models`, when given).")
      .def_property_readonly("path", &Library::path)
      .def_property_readonly(
          "models",
          [](const Library& library) {
            std::vector<ModelInfo> models;
            for (const LibraryModel& model : library.library().models()) {
              const ModelRecord& r = model.record;
              models.push_back({r.name, r.diameter_m, r.symmetric, static_cast<int>(r.views.size())});
            }
            return models;
          })
      .def("__repr__", [](const Library& library) {
        return "<ecvpose.ModelLibrary " + library.path() + ", " + std::to_string(library.library().models().size()) +
               " models>";
      });

  m.def(
      "build_models",
      [](const std::string& db, const py::object& meshes, std::optional<std::string> name, std::string unit,
         py::object object_from_mesh, bool symmetric, bool allow_missing_textures, int views, double distance,
         py::object camera, std::pair<int, int> size, std::string shading, int threads, bool stored_mesh,
         bool point_pairs, int mesh_texture_size, py::object feature_settings, std::pair<int, int> shard,
         py::object progress) {
        const std::vector<std::string> paths = py::isinstance<py::str>(meshes)
                                                   ? std::vector<std::string>{meshes.cast<std::string>()}
                                                   : meshes.cast<std::vector<std::string>>();
        BuildArguments args;
        args.name = std::move(name);
        args.unit = std::move(unit);
        args.object_from_mesh = std::move(object_from_mesh);
        args.symmetric = symmetric;
        args.allow_missing_textures = allow_missing_textures;
        args.views = views;
        args.distance = distance;
        args.camera = std::move(camera);
        args.size = size;
        args.shading = std::move(shading);
        args.threads = threads;
        args.stored_mesh = stored_mesh;
        args.point_pairs = point_pairs;
        args.mesh_texture_size = mesh_texture_size;
        args.feature_settings = std::move(feature_settings);
        args.shard = shard;
        return BuildModels(db, paths, args, progress);
      },
      py::arg("db"), py::arg("meshes"), py::kw_only(), py::arg("name") = py::none(), py::arg("unit") = "m",
      py::arg("object_from_mesh") = py::none(), py::arg("symmetric") = false, py::arg("allow_missing_textures") = false,
      py::arg("views") = ModelBuildOptions::DefaultSampling().num_views,
      py::arg("distance") = ModelBuildOptions().distance_m, py::arg("camera") = py::none(),
      py::arg("size") = std::pair<int, int>{640, 480}, py::arg("shading") = "auto", py::arg("threads") = 0,
      py::arg("stored_mesh") = true, py::arg("point_pairs") = true,
      py::arg("mesh_texture_size") = MeshBlobOptions().max_texture_size, py::arg("feature_settings") = py::none(),
      py::arg("shard") = std::pair<int, int>{0, 1}, py::arg("progress") = py::none(), kBuildModelsDoc);

  m.def(
      "merge_libraries",
      [](const std::string& out, const std::vector<std::string>& libraries, const py::object& progress) {
        LibraryMergeReporter reporter;
        if (!progress.is_none()) {
          reporter.copied = [&](const std::string& model, const std::string& shard, int number, int count) {
            const py::gil_scoped_acquire acquire;
            progress(model, shard, number, count);
          };
        }
        const py::gil_scoped_release release;
        return MergeLibraries(out, libraries, reporter);
      },
      py::arg("out"), py::arg("libraries"), py::kw_only(), py::arg("progress") = py::none(),
      "Copies every model of `libraries` (the parts of a build with `shard`) into the library `out` (created if "
      "missing), as `ecvpose modeldb merge` does: in name order, each model in one transaction with its colour matrix. "
      "Raises InputError, before writing anything, for libraries of other feature settings or schema versions and a "
      "model in two of them. progress(model, library, number, count) is called after each model. Returns the number "
      "of models copied.");

  m.def(
      "render",
      [](Library& library, const std::string& model, const py::object& camera_from_object, const py::object& k,
         int width, int height) {
        const PinholeCamera camera = CameraFromK(k, width, height, "K");
        const Eigen::Isometry3d pose = PoseFromArray(camera_from_object, "camera_from_object");
        RenderResult rendered;
        {
          py::gil_scoped_release release;
          rendered = library.Render(model, pose, camera);
        }
        return py::make_tuple(ImageArray(rendered.color), ImageArray(rendered.depth));
      },
      py::arg("library"), py::arg("model"), py::arg("camera_from_object"), py::arg("K"), py::arg("width"),
      py::arg("height"),
      "`model` of `library` rendered at `camera_from_object` (4x4, metres) by a camera with intrinsics `K` (3x3) and "
      "an image of `width` x `height`: (colour HxWx3 uint8 RGB, depth HxW float32 metres, 0 where the model is not "
      "seen).");
}

}  // namespace ecv::python
