#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/camera.h"
#include "core/mesh.h"
#include "io/mesh_blob.h"
#include "modeldb/model_record.h"
#include "render/renderer.h"
#include "render/view_sampling.h"

namespace ecv {

/// The camera of YCB-Video (Asus Xtion, 640x480): the default for rendering a library.
PinholeCamera YcbVideoCamera();

/// How a library model is made from a mesh: N rendered views, ECV primitives moved into the object frame,
/// context descriptors per view.
struct ModelBuildOptions {
  /// Viewpoints on the sphere (Fibonacci lattice) and margin; `sampling.num_views` views. Its distance_m must
  /// stay 0: the distance is `distance_m` below.
  ViewSamplingOptions sampling = DefaultSampling();
  /// Camera distance from the object centre, metres; farther when the object would not fit the image with the
  /// margin; 0 = as close as it fits. 0.9 m is about where YCB-Video sees its objects: primitives then have the
  /// scene's density and image scale (as close as fits, small objects give dense views that take many times
  /// longer to describe and store, and matched real frames worse: bench/RESULTS.md, modeldb_bench, and
  /// bench/EXPERIMENTS.md, 2026-11-21). Every benchmark figure is measured with this and DefaultSampling's 40 views.
  double distance_m = 0.9;
  PinholeCamera camera = YcbVideoCamera();  ///< intrinsics and image size of every view (stored per view)
  RenderOptions render;                     ///< shading etc. (unlit: the texture's colours as stored)
  /// Beyond the paper: BuildModel renders a mesh without any texture (vertex or material colours only) with
  /// headlight shading even when `render.shading` is unlit. A camera sees such an object's form through its
  /// shading; flat colours show little but the silhouette (it finds more of the LM-O frame's scanned models:
  /// bench/EXPERIMENTS.md, 2026-11-23). Textured meshes keep their texture as stored.
  /// The recognizer renders each model in verification as its views were (StoredViewShading).
  bool shade_untextured = true;
  FeatureSettings features;  ///< extraction and descriptor settings
  /// Store the mesh in the record (ModelRecord::mesh_blob), so that recognition verifies poses without the mesh
  /// file and without decoding its full-size textures (bench/RESULTS.md, setup_bench). Textures are kept up to
  /// mesh_blob.max_texture_size (the recognizer's own cap).
  bool store_mesh = true;
  MeshBlobOptions mesh_blob;
  /// Draw the model's point pair points (ModelRecord::point_pairs) for shape-driven pose hypotheses. A mesh too
  /// small, flat or coarse for them is stored without, with a warning.
  bool point_pairs = true;
  PpfModelSampling point_pair_sampling;
  int threads = 1;  ///< worker threads describing each view (1 to kMaxThreads); the model does not depend on it

  /// Throws InputError naming the field for nonsense values (via the parts' Check()).
  void Check() const;

  /// The default sampling: 40 views over the whole sphere.
  static ViewSamplingOptions DefaultSampling();
};

/// Where a model comes from.
struct ModelSource {
  std::string name;        ///< model name; empty = the mesh file's stem
  std::string mesh_path;   ///< OBJ/PLY/glTF ... (io/mesh_io.h)
  std::string unit = "m";  ///< unit of the mesh coordinates: "m", "cm" or "mm"
  /// Applied after the unit change: x_object = R x_mesh + t (metres).
  Eigen::Isometry3d object_from_mesh = Eigen::Isometry3d::Identity();
  bool allow_missing_textures = false;  ///< use vertex or material colours where a texture file is missing
  bool symmetric = false;               ///< stored flag for ADD-S evaluation
};

/// Progress after each view.
struct BuildProgress {
  int view = 0;  ///< views done
  int num_views = 0;
  int primitives = 0;   ///< of this view
  int descriptors = 0;  ///< of this view
};
using BuildProgressCallback = std::function<void(const BuildProgress&)>;

/// Time per step of a build, milliseconds (summed over the views).
struct BuildTimings {
  double load_ms = 0.0;         ///< reading the mesh and its textures, hashing them, packing it (store_mesh)
  double upload_ms = 0.0;       ///< uploading the mesh to the renderer
  double render_ms = 0.0;       ///< rendering the views
  double extract_ms = 0.0;      ///< ECV primitives and the move into the object frame
  double describe_ms = 0.0;     ///< context descriptors
  double point_pairs_ms = 0.0;  ///< point pair points, and their table counted
};

struct BuildResult {
  ModelRecord record;
  BuildTimings timings;
  std::vector<std::string> warnings;  ///< what the mesh loader tolerated
};

/// Loads the mesh of `source`, hashes its file and textures, and builds its record with `renderer` (one
/// Renderer per thread; it may be reused for the next model), its views shaded as ViewShading says. Throws
/// InputError for a bad mesh or options.
BuildResult BuildModel(const ModelSource& source, const ModelBuildOptions& options, Renderer& renderer,
                       const BuildProgressCallback& progress = {});

/// The views of an already loaded mesh (object frame, metres): render, extract, move the primitives into the
/// object frame (object_from_camera = camera_from_object^-1), describe. Adds to `timings` if given.
std::vector<ModelView> BuildModelViews(const TriangleMesh& mesh, const ModelBuildOptions& options, Renderer& renderer,
                                       const BuildProgressCallback& progress = {}, BuildTimings* timings = nullptr);

/// The camera distance of a build for an object with bounding sphere `sphere`: the larger of
/// `options.distance_m` and the distance at which the sphere fits the image with the margin (metres).
double ViewDistance(const BoundingSphere& sphere, const ModelBuildOptions& options);

/// One view of a mesh uploaded to `renderer`, rendered at `camera_from_object` (metres) with the options'
/// camera: primitives in the object frame and their descriptors. Adds to `timings` if given.
ModelView BuildModelView(Renderer& renderer, MeshId mesh, const Eigen::Isometry3d& camera_from_object,
                         const ModelBuildOptions& options, BuildTimings* timings = nullptr);

/// The shading of `mesh`'s views: headlight for a mesh without a texture when options.shade_untextured, else
/// options.render.shading.
Shading ViewShading(const TriangleMesh& mesh, const ModelBuildOptions& options);

/// The shading a record's views were rendered with, from its build options (`build_options_json`); unlit when
/// they do not say (libraries built before the choice was recorded).
Shading StoredViewShading(const std::string& build_options_json);

/// How the views were made, as JSON text (views, camera, distance asked for, margin, elevation band, shading).
std::string BuildOptionsToJson(const ModelBuildOptions& options);

/// The mesh file and the texture files it uses (what the mesh hash covers), in material order.
std::vector<std::string> MeshContentFiles(const std::string& mesh_path, const TriangleMesh& mesh);

}  // namespace ecv
