#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "core/camera.h"
#include "core/mesh.h"

namespace ecv {

/// The offscreen OpenGL context could not be created or used: a broken installation (OSMesa missing,
/// too old, or GL calls going to another libGL), not a broken input.
class RenderError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The largest image side a Renderer renders, pixels (less where the GL implementation's renderbuffers are smaller).
/// 8192 x 8192 takes about 3 GB while rendering; OSMesa crashes on 16384 x 16384.
constexpr int kMaxRenderSide = 8192;

/// Settings fixed for the life of a Renderer.
struct RendererOptions {
  bool mipmaps = true;          ///< trilinear texture filtering; mipmaps are built once, in AddMesh
  int max_texture_size = 8192;  ///< textures larger than this (pixels per side) are downscaled in AddMesh

  /// Throws InputError when max_texture_size is below 1.
  void Check() const;
};

/// How surfaces are lit.
enum class Shading {
  kUnlit,      ///< the surface colour as stored (texture, vertex colour or material colour)
  kHeadlight,  ///< Lambertian, light at the camera: colour * (ambient + (1 - ambient) |cos(incidence)|)
};

/// Settings of one render call.
struct RenderOptions {
  double near_m = 0.01;               ///< near clipping distance along the optical axis, metres
  double far_m = 20.0;                ///< far clipping distance along the optical axis, metres
  Shading shading = Shading::kUnlit;  ///< lighting
  double ambient = 0.35;              ///< kHeadlight: brightness of a surface seen edge-on, 0..1
  bool use_uniform_color = false;     ///< paint every surface in `uniform_color` instead of its own colour
  Eigen::Vector3f uniform_color{1.0F, 0.0F, 0.0F};  ///< RGB in [0, 1], used when use_uniform_color
  Eigen::Vector3f background{0.0F, 0.0F, 0.0F};     ///< RGB in [0, 1] of pixels where no object is seen
  /// Skip the faces turned away from the camera (counter-clockwise seen from outside is the front). For meshes
  /// with TriangleMesh::IsClosedOutward() the image is the same (up to a silhouette pixel where a front and a back
  /// face meet) and the render takes about a third less time; other meshes would show holes.
  bool cull_back_faces = false;

  /// Throws InputError unless 0 < near_m < far_m (finite), 0 <= ambient <= 1 and colours lie in [0, 1].
  void Check() const;
};

/// Handle of a mesh uploaded to one Renderer.
struct MeshId {
  int index = -1;
};

/// One uploaded mesh placed in the camera frame.
struct SceneObject {
  MeshId mesh;
  Eigen::Isometry3d camera_from_object = Eigen::Isometry3d::Identity();  ///< metres
};

/// Images of one render call: the camera's size, top row first, pixel (u, v) = the ray through
/// PinholeCamera pixel centre (u, v), so depth(v, u) back-projects with PinholeCamera::BackProject.
struct RenderResult {
  cv::Mat color;   ///< CV_8UC3 RGB
  cv::Mat depth;   ///< CV_32FC1 camera-frame z of the nearest surface, metres; 0 where no object is seen
  cv::Mat mask;    ///< CV_8UC1: 255 where an object is seen, 0 elsewhere
  cv::Mat labels;  ///< CV_16UC1: 1 + index (into the scene objects) of the object seen, 0 elsewhere
  std::vector<int> visible_pixels;  ///< per scene object: number of pixels where it is seen
  double render_ms = 0.0;           ///< wall time of the call, milliseconds
};

/// Renders triangle meshes offscreen with OSMesa (software OpenGL 3.3 core). The GL context is
/// created once, by the constructor, and reused by every call; meshes are uploaded once with AddMesh.
/// The projection is the pinhole model of the camera (no distortion), rasterised at pixel centres.
/// Faces are drawn from both sides. One Renderer must not be used by two threads at the same time;
/// several Renderers may live in one process.
class Renderer {
 public:
  /// Creates the OpenGL context; throws RenderError when it cannot (naming the reason) and InputError
  /// for bad options.
  explicit Renderer(const RendererOptions& options = {});
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Uploads the geometry and textures of `mesh` (object frame, metres). Throws InputError naming the
  /// mesh when it has no triangles, an index out of range, a non-finite position or an attribute
  /// array whose length differs from the positions'.
  MeshId AddMesh(const TriangleMesh& mesh);

  /// Frees what AddMesh uploaded; `mesh` becomes invalid.
  void RemoveMesh(MeshId mesh);

  /// Renders one mesh at `camera_from_object` (metres) for `camera`. Throws InputError, before allocating, for an
  /// image side beyond kMaxRenderSide.
  RenderResult Render(MeshId mesh, const PinholeCamera& camera, const Eigen::Isometry3d& camera_from_object,
                      const RenderOptions& options = {});

  /// Renders several meshes in one image with occlusion; labels number them 1.. in `objects` order.
  RenderResult RenderScene(const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                           const RenderOptions& options = {});

  /// OpenGL version and driver, e.g. "4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)".
  std::string Description() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

/// The 4x4 OpenGL projection used for `camera` (camera frame: x right, y down, z forward) that puts
/// image pixel centre (u, v) at window coordinates (u + 0.5, v + 0.5), so GL row 0 is image row 0,
/// and maps z in [near_m, far_m] to normalised depth [-1, 1].
Eigen::Matrix4d ProjectionFromCamera(const PinholeCamera& camera, double near_m, double far_m);

}  // namespace ecv
