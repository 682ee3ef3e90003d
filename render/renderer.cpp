#include "render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <string>

#include "core/error.h"
#include "render/gl_context.h"
#include "render/gl_resources.h"

namespace ecv {
namespace {

bool IsColor(const Eigen::Vector3f& color) {
  return color.allFinite() && color.minCoeff() >= 0.0F && color.maxCoeff() <= 1.0F;
}

std::string MeshSource(const TriangleMesh& mesh) {
  return "mesh '" + mesh.name + "'";
}

// Throws InputError unless `count` (an optional attribute array's length) is 0 or `expected`.
void CheckAttribute(const TriangleMesh& mesh, size_t part, const char* field, size_t count, size_t expected) {
  if (count == 0 || count == expected) return;
  ThrowInputError(MeshSource(mesh), "part " + std::to_string(part) + " " + field,
                  "none or one per vertex (" + std::to_string(expected) + ")", std::to_string(count));
}

void ValidateMesh(const TriangleMesh& mesh) {
  if (mesh.NumTriangles() == 0) {
    ThrowInputError(MeshSource(mesh), "triangles", "at least one triangle to render",
                    "0 triangles (" + std::to_string(mesh.NumVertices()) + " vertices)");
  }
  for (size_t p = 0; p < mesh.parts.size(); ++p) {
    const MeshPart& part = mesh.parts[p];
    const size_t n = part.positions.size();
    CheckAttribute(mesh, p, "normals", part.normals.size(), n);
    CheckAttribute(mesh, p, "texcoords", part.texcoords.size(), n);
    CheckAttribute(mesh, p, "colors", part.colors.size(), n);
    if (part.material >= static_cast<int>(mesh.materials.size())) {
      ThrowInputError(MeshSource(mesh), "part " + std::to_string(p) + " material",
                      "an index below " + std::to_string(mesh.materials.size()), std::to_string(part.material));
    }
    for (const Eigen::Vector3f& position : part.positions) {
      if (!position.allFinite()) ThrowInputError(MeshSource(mesh), "positions", "finite coordinates", "NaN or inf");
    }
    for (const Eigen::Vector3i& triangle : part.triangles) {
      if (triangle.minCoeff() < 0 || triangle.maxCoeff() >= static_cast<int>(n)) {
        ThrowInputError(MeshSource(mesh), "part " + std::to_string(p) + " triangles",
                        "vertex indices in [0, " + std::to_string(n) + ")",
                        std::to_string(triangle.minCoeff()) + ".." + std::to_string(triangle.maxCoeff()));
      }
    }
  }
}

}  // namespace

void RendererOptions::Check() const {
  if (max_texture_size < 1) {
    ThrowInputError("renderer options", "max_texture_size", "at least 1 pixel", std::to_string(max_texture_size));
  }
}

void RenderOptions::Check() const {
  if (!std::isfinite(near_m) || !std::isfinite(far_m) || near_m <= 0.0 || far_m <= near_m) {
    ThrowInputError("render options", "near_m/far_m", "0 < near_m < far_m, metres",
                    std::to_string(near_m) + "/" + std::to_string(far_m));
  }
  if (!(ambient >= 0.0 && ambient <= 1.0)) {
    ThrowInputError("render options", "ambient", "a value in [0, 1]", std::to_string(ambient));
  }
  if (!IsColor(uniform_color)) ThrowInputError("render options", "uniform_color", "RGB in [0, 1]");
  if (!IsColor(background)) ThrowInputError("render options", "background", "RGB in [0, 1]");
}

Eigen::Matrix4d ProjectionFromCamera(const PinholeCamera& camera, double near_m, double far_m) {
  // Window x = (x_ndc + 1) W / 2 must equal u + 0.5 = fx x / z + cx + 0.5 (likewise y), with w_clip = z.
  const double width = camera.width;
  const double height = camera.height;
  Eigen::Matrix4d projection = Eigen::Matrix4d::Zero();
  projection(0, 0) = 2.0 * camera.fx / width;
  projection(0, 2) = 2.0 * (camera.cx + 0.5) / width - 1.0;
  projection(1, 1) = 2.0 * camera.fy / height;
  projection(1, 2) = 2.0 * (camera.cy + 0.5) / height - 1.0;
  projection(2, 2) = (far_m + near_m) / (far_m - near_m);
  projection(2, 3) = -2.0 * far_m * near_m / (far_m - near_m);
  projection(3, 2) = 1.0;
  return projection;
}

class Renderer::Impl {
 public:
  explicit Impl(const RendererOptions& options) : options_(options), program_(gl::CreateProgram(context_)) {}

  ~Impl() {
    try {
      context_.MakeCurrent();
    } catch (const RenderError&) {
      return;  // destroying the context frees its objects anyway
    }
    const gl::Functions& gl = context_.functions();
    for (auto& [index, mesh] : meshes_) gl::ReleaseMesh(gl, &mesh);
    gl::ReleaseFramebuffer(gl, &framebuffer_);
    gl::ReleaseProgram(gl, &program_);
  }

  MeshId AddMesh(const TriangleMesh& mesh) {
    ValidateMesh(mesh);
    context_.MakeCurrent();
    const int index = next_index_++;
    meshes_[index] = gl::UploadMesh(context_, mesh, options_.mipmaps, options_.max_texture_size);
    return MeshId{index};
  }

  void RemoveMesh(MeshId id) {
    auto found = meshes_.find(id.index);
    if (found == meshes_.end()) return;
    context_.MakeCurrent();
    gl::ReleaseMesh(context_.functions(), &found->second);
    meshes_.erase(found);
  }

  RenderResult RenderScene(const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                           const RenderOptions& options);

  std::string Description() const { return context_.version() + ", " + context_.renderer(); }

 private:
  const gl::Mesh& Find(MeshId id) const {
    auto found = meshes_.find(id.index);
    if (found == meshes_.end()) {
      ThrowInputError("renderer", "mesh id", "an id returned by AddMesh and not removed", std::to_string(id.index));
    }
    return found->second;
  }

  void Clear(const RenderOptions& options);
  void SetFrameUniforms(const PinholeCamera& camera, const RenderOptions& options);
  void Draw(const gl::Mesh& mesh, const Eigen::Isometry3d& camera_from_object, int label, const RenderOptions& options);

  RendererOptions options_;
  gl::Context context_;
  gl::Program program_;
  gl::Framebuffer framebuffer_;
  std::map<int, gl::Mesh> meshes_;
  int next_index_ = 0;
};

void Renderer::Impl::Clear(const RenderOptions& options) {
  const gl::Functions& gl = context_.functions();
  const GLfloat background[4] = {options.background.x(), options.background.y(), options.background.z(), 0.0F};
  const GLfloat no_depth[4] = {0.0F, 0.0F, 0.0F, 0.0F};
  const GLfloat far_depth = 1.0F;
  gl.ClearBufferfv(GL_COLOR, 0, background);
  gl.ClearBufferfv(GL_COLOR, 1, no_depth);
  gl.ClearBufferfv(GL_DEPTH, 0, &far_depth);
}

void Renderer::Impl::SetFrameUniforms(const PinholeCamera& camera, const RenderOptions& options) {
  const gl::Functions& gl = context_.functions();
  const gl::ProgramLocations& at = program_.locations;
  const Eigen::Matrix4f projection = ProjectionFromCamera(camera, options.near_m, options.far_m).cast<float>();
  gl.UseProgram(program_.id);
  gl.UniformMatrix4fv(at.projection, 1, GL_FALSE, projection.data());  // Eigen is column-major, as GL
  gl.Uniform1i(at.albedo, 0);
  gl.Uniform1i(at.shading, options.shading == Shading::kHeadlight ? 1 : 0);
  gl.Uniform1f(at.ambient, static_cast<float>(options.ambient));
  gl.ActiveTexture(GL_TEXTURE0);
}

void Renderer::Impl::Draw(const gl::Mesh& mesh, const Eigen::Isometry3d& camera_from_object, int label,
                          const RenderOptions& options) {
  const gl::Functions& gl = context_.functions();
  const gl::ProgramLocations& at = program_.locations;
  const Eigen::Matrix4f matrix = camera_from_object.matrix().cast<float>();
  gl.UniformMatrix4fv(at.camera_from_object, 1, GL_FALSE, matrix.data());
  gl.Uniform1f(at.label, static_cast<float>(label));
  for (const gl::Part& part : mesh.parts) {
    const bool uniform = options.use_uniform_color;
    gl.Uniform1i(at.coloring, uniform ? gl::kColorUniform : part.coloring);
    const Eigen::Vector3f color = uniform ? options.uniform_color : part.color;
    gl.Uniform3f(at.uniform_color, color.x(), color.y(), color.z());
    gl.Uniform1i(at.has_normals, part.has_normals ? 1 : 0);
    gl.BindTexture(GL_TEXTURE_2D, part.texture);
    gl.BindVertexArray(part.vertex_array);
    gl.DrawElements(GL_TRIANGLES, part.num_indices, GL_UNSIGNED_INT, nullptr);
  }
  gl.BindVertexArray(0);
}

RenderResult Renderer::Impl::RenderScene(const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                                         const RenderOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  camera.Check("render camera");
  options.Check();
  for (const SceneObject& object : objects) {
    Find(object.mesh);
    if (!object.camera_from_object.matrix().allFinite()) {
      ThrowInputError("render scene", "camera_from_object", "a finite rigid transform");
    }
  }
  context_.MakeCurrent();
  const gl::Functions& gl = context_.functions();
  GLint max_size = 0;
  gl.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  max_size = std::min<GLint>(max_size, kMaxRenderSide);
  if (camera.width > max_size || camera.height > max_size) {
    ThrowInputError("render camera", "width/height", "at most " + std::to_string(max_size) + " pixels",
                    std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  gl::BindFramebuffer(context_, camera.width, camera.height, &framebuffer_);
  gl.Viewport(0, 0, camera.width, camera.height);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_LESS);
  if (options.cull_back_faces) {
    gl.Enable(GL_CULL_FACE);
    gl.FrontFace(GL_CW);  // counter-clockwise seen from outside, but the projection mirrors y (image rows down)
    gl.CullFace(GL_BACK);
  } else {
    gl.Disable(GL_CULL_FACE);
  }
  Clear(options);
  SetFrameUniforms(camera, options);
  for (size_t i = 0; i < objects.size(); ++i) {
    Draw(Find(objects[i].mesh), objects[i].camera_from_object, static_cast<int>(i + 1), options);
  }
  context_.CheckErrors("rendering " + std::to_string(objects.size()) + " object(s)");

  RenderResult result;
  gl::ReadFramebuffer(context_, framebuffer_, &result.color, &result.depth, &result.labels);
  result.mask = result.labels > 0;
  result.visible_pixels.assign(objects.size(), 0);
  for (int v = 0; v < result.labels.rows; ++v) {  // row pointers: a cv::MatIterator per pixel took most of a render
    const uint16_t* row = result.labels.ptr<uint16_t>(v);
    for (int u = 0; u < result.labels.cols; ++u) {
      if (row[u] > 0 && row[u] <= objects.size()) ++result.visible_pixels[row[u] - 1];
    }
  }
  result.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return result;
}

Renderer::Renderer(const RendererOptions& options) {
  options.Check();
  impl_ = std::make_unique<Impl>(options);
}

Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

MeshId Renderer::AddMesh(const TriangleMesh& mesh) {
  return impl_->AddMesh(mesh);
}

void Renderer::RemoveMesh(MeshId mesh) {
  impl_->RemoveMesh(mesh);
}

RenderResult Renderer::Render(MeshId mesh, const PinholeCamera& camera, const Eigen::Isometry3d& camera_from_object,
                              const RenderOptions& options) {
  return impl_->RenderScene({SceneObject{mesh, camera_from_object}}, camera, options);
}

RenderResult Renderer::RenderScene(const std::vector<SceneObject>& objects, const PinholeCamera& camera,
                                   const RenderOptions& options) {
  return impl_->RenderScene(objects, camera, options);
}

std::string Renderer::Description() const {
  return impl_->Description();
}

}  // namespace ecv
