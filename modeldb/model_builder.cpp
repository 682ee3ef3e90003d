// Building a library model from a mesh (the offline data flow): render N views, extract ECV primitives
// (paper Sect. II-A) in each, move them into the object frame, and compute the context descriptors per view
// (Sect. II-B; invariant to the rigid move, so computing them in the object frame changes nothing but lets a
// reloaded model reproduce them bit for bit).

#include "modeldb/model_builder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/parallel.h"
#include "core/timing.h"
#include "io/mesh_io.h"
#include "modeldb/content_hash.h"

namespace ecv {
namespace {

constexpr double kMinDiameterM = 0.001, kMaxDiameterM = 10.0;  // what an RGB-D camera can recognise

// Removes an uploaded mesh from the renderer however the build ends.
class UploadedMesh {
 public:
  UploadedMesh(Renderer& renderer, const TriangleMesh& mesh) : renderer_(renderer), id_(renderer.AddMesh(mesh)) {}
  ~UploadedMesh() { renderer_.RemoveMesh(id_); }
  UploadedMesh(const UploadedMesh&) = delete;
  UploadedMesh& operator=(const UploadedMesh&) = delete;
  MeshId id() const { return id_; }

 private:
  Renderer& renderer_;
  MeshId id_;
};

// Camera frame -> object frame: positions by the whole transform, orientations by its rotation.
void MoveIntoObjectFrame(const Eigen::Isometry3d& object_from_camera, std::vector<Primitive>* primitives) {
  const Eigen::Matrix3f rotation = object_from_camera.linear().cast<float>();
  const Eigen::Vector3f translation = object_from_camera.translation().cast<float>();
  for (Primitive& primitive : *primitives) {
    primitive.position = rotation * primitive.position + translation;
    primitive.orientation = rotation * primitive.orientation;
  }
}

}  // namespace

PinholeCamera YcbVideoCamera() {
  return {1066.778, 1067.487, 312.9869, 241.3109, 640, 480};
}

ViewSamplingOptions ModelBuildOptions::DefaultSampling() {
  ViewSamplingOptions sampling;
  sampling.num_views = 40;
  return sampling;
}

void ModelBuildOptions::Check() const {
  sampling.Check();
  if (sampling.distance_m != 0.0) {
    ThrowInputError("model build options", "sampling.distance_m", "0 (the distance is distance_m)",
                    std::to_string(sampling.distance_m));
  }
  if (!(distance_m >= 0.0) || !std::isfinite(distance_m)) {
    ThrowInputError("model build options", "distance_m", "a distance >= 0 m", std::to_string(distance_m));
  }
  camera.Check("model build options: camera");
  render.Check();
  features.ecv.Check();
  features.descriptor.Check();
  mesh_blob.Check();
  point_pair_sampling.Check();
  CheckThreadCount("model build options", threads);
}

double ViewDistance(const BoundingSphere& sphere, const ModelBuildOptions& options) {
  return std::max(options.distance_m, FitViewDistance(sphere.radius_m, options.camera, options.sampling.margin));
}

ModelView BuildModelView(Renderer& renderer, MeshId mesh, const Eigen::Isometry3d& camera_from_object,
                         const ModelBuildOptions& options, BuildTimings* timings) {
  BuildTimings unused;
  BuildTimings& time = timings != nullptr ? *timings : unused;
  ModelView view;
  view.camera = options.camera;
  view.camera_from_object = camera_from_object;
  auto start = Clock::now();
  const RenderResult rendered = renderer.Render(mesh, options.camera, camera_from_object, options.render);
  time.render_ms += MillisecondsSince(start);
  start = Clock::now();
  const RgbdFrame frame{rendered.color, rendered.depth, options.camera, "rendered view"};
  view.primitives = ExtractPrimitives(frame, options.features.ecv, rendered.mask).primitives;
  MoveIntoObjectFrame(camera_from_object.inverse(), &view.primitives);
  time.extract_ms += MillisecondsSince(start);
  start = Clock::now();
  // The surface context's support (if any), in the object frame as the primitives are.
  const SurfaceSamples surface = MovedSurface(DescriptorSurface(frame, options.features.descriptor, rendered.mask),
                                              camera_from_object.inverse().cast<float>());
  view.descriptors = ComputeDescriptors(view.primitives, options.features.descriptor, options.threads, 1, &surface);
  time.describe_ms += MillisecondsSince(start);
  return view;
}

std::vector<ModelView> BuildModelViews(const TriangleMesh& mesh, const ModelBuildOptions& options, Renderer& renderer,
                                       const BuildProgressCallback& progress, BuildTimings* timings) {
  options.Check();
  BuildTimings unused;
  BuildTimings& time = timings != nullptr ? *timings : unused;
  const auto start = Clock::now();
  const UploadedMesh uploaded(renderer, mesh);
  time.upload_ms += MillisecondsSince(start);
  const BoundingSphere sphere = ComputeBoundingSphere(mesh);
  ViewSamplingOptions sampling = options.sampling;
  sampling.distance_m = ViewDistance(sphere, options);
  const std::vector<Eigen::Isometry3d> poses = SampleViews(sphere, options.camera, sampling);
  std::vector<ModelView> views;
  for (size_t i = 0; i < poses.size(); ++i) {
    views.push_back(BuildModelView(renderer, uploaded.id(), poses[i], options, &time));
    views.back().index = static_cast<int>(i);
    if (progress) {
      progress({static_cast<int>(i + 1), static_cast<int>(poses.size()),
                static_cast<int>(views.back().primitives.size()), views.back().descriptors.values.rows});
    }
  }
  return views;
}

BuildResult BuildModel(const ModelSource& source, const ModelBuildOptions& options, Renderer& renderer,
                       const BuildProgressCallback& progress) {
  options.Check();
  BuildResult result;
  auto start = Clock::now();
  MeshLoadOptions load;
  load.metres_per_unit = MetresPerUnit(source.unit);
  load.object_from_mesh = source.object_from_mesh;
  load.allow_missing_textures = source.allow_missing_textures;
  const TriangleMesh mesh = LoadMesh(source.mesh_path, load, &result.warnings);
  ModelRecord& record = result.record;
  record.mesh_sha256 = Sha256OfFiles(MeshContentFiles(source.mesh_path, mesh));
  if (options.store_mesh) record.mesh_blob = EncodeMeshBlob(mesh, options.mesh_blob);
  result.timings.load_ms = MillisecondsSince(start);
  record.name = source.name.empty() ? std::filesystem::path(source.mesh_path).stem().string() : source.name;
  record.mesh_path = std::filesystem::absolute(source.mesh_path).lexically_normal().string();
  record.unit = source.unit;
  record.object_from_mesh = source.object_from_mesh;
  record.diameter_m = mesh.Diameter();
  if (!(record.diameter_m >= kMinDiameterM && record.diameter_m <= kMaxDiameterM)) {
    ThrowInputError(source.mesh_path, "size",
                    "an object between 1 mm and 10 m across (is --unit, here '" + source.unit + "', right?)",
                    std::to_string(record.diameter_m) + " m across");
  }
  record.symmetric = source.symmetric;
  ModelBuildOptions shaded = options;
  shaded.render.shading = ViewShading(mesh, options);
  record.build_options_json = BuildOptionsToJson(shaded);
  record.features = options.features;
  record.views = BuildModelViews(mesh, shaded, renderer, progress, &result.timings);
  if (record.NumPrimitives() == 0) {
    ThrowInputError(source.mesh_path, "views", "ECV primitives in its rendered views",
                    "none in any of " + std::to_string(record.views.size()) + " views (the mesh is " +
                        std::to_string(record.diameter_m) + " m across; is --unit right?)");
  }
  if (options.point_pairs) {
    start = Clock::now();
    record.point_pairs = MakePointPairRecord(mesh, options.point_pair_sampling);
    result.timings.point_pairs_ms = MillisecondsSince(start);
    if (!record.point_pairs->refusal.empty()) {
      result.warnings.push_back(source.mesh_path + ": no point pair points, so no shape-driven pose hypotheses (" +
                                record.point_pairs->refusal + ")");
    }
  }
  return result;
}

Shading ViewShading(const TriangleMesh& mesh, const ModelBuildOptions& options) {
  const bool textured = std::any_of(mesh.parts.begin(), mesh.parts.end(), [&](const MeshPart& part) {
    return mesh.Coloring(part) == MeshColoring::kTexture;
  });
  return options.shade_untextured && !textured ? Shading::kHeadlight : options.render.shading;
}

std::string BuildOptionsToJson(const ModelBuildOptions& options) {
  const ViewSamplingOptions& s = options.sampling;
  const PinholeCamera& c = options.camera;
  nlohmann::ordered_json json;
  json["views"] = s.num_views;
  json["camera"] = {c.fx, c.fy, c.cx, c.cy};
  json["size"] = {c.width, c.height};
  json["distance_m"] = options.distance_m;  // or farther where the object would not fit
  json["margin"] = s.margin;
  json["elevation_rad"] = {s.min_elevation_rad, s.max_elevation_rad};
  json["up_object"] = {s.up_object.x(), s.up_object.y(), s.up_object.z()};
  json["shading"] = options.render.shading == Shading::kUnlit ? "unlit" : "headlight";
  return json.dump();
}

Shading StoredViewShading(const std::string& build_options_json) {
  const nlohmann::json json = nlohmann::json::parse(build_options_json, nullptr, false);
  const bool headlight = json.is_object() && json.contains("shading") && json["shading"] == "headlight";
  return headlight ? Shading::kHeadlight : Shading::kUnlit;
}

std::vector<std::string> MeshContentFiles(const std::string& mesh_path, const TriangleMesh& mesh) {
  std::vector<std::string> files = {mesh_path};
  for (const MeshMaterial& material : mesh.materials) {
    const std::string& texture = material.texture_path;
    // none, embedded in the mesh file, or missing (and tolerated by the loader)
    if (texture.empty() || texture[0] == '*' || !std::filesystem::is_regular_file(texture)) continue;
    if (std::find(files.begin(), files.end(), texture) == files.end()) files.push_back(texture);
  }
  return files;
}

}  // namespace ecv
