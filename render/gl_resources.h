#pragma once

// Internal to ecv_render: GL objects of the renderer (shader program, framebuffer, uploaded meshes).
// Every function here needs the owning gl::Context to be current.

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/mesh.h"
#include "render/gl_context.h"

namespace ecv::gl {

/// Fragment colour source, as the shader's `coloring` uniform.
enum ColoringMode : int { kColorFromTexture = 0, kColorFromVertices = 1, kColorUniform = 2 };

/// One mesh part in GL buffers.
struct Part {
  GLuint vertex_array = 0;
  std::vector<GLuint> buffers;  ///< attribute buffers and the index buffer
  GLsizei num_indices = 0;
  ColoringMode coloring = kColorUniform;
  GLuint texture = 0;                       ///< for kColorFromTexture
  Eigen::Vector3f color{0.8F, 0.8F, 0.8F};  ///< for kColorUniform, RGB 0..1
  bool has_normals = false;
};

/// One uploaded mesh.
struct Mesh {
  std::vector<Part> parts;
  std::vector<GLuint> textures;  ///< one per textured material
};

/// Uploads the parts of a validated mesh; textures wider or taller than `max_texture_size` are
/// downscaled; `mipmaps` builds mipmaps for trilinear filtering.
Mesh UploadMesh(const Context& context, const TriangleMesh& mesh, bool mipmaps, int max_texture_size);

/// Deletes the GL objects of `mesh` and empties it.
void ReleaseMesh(const Functions& gl, Mesh* mesh);

/// Uniform locations of the renderer's one shader program.
struct ProgramLocations {
  GLint camera_from_object = -1;
  GLint projection = -1;
  GLint coloring = -1;
  GLint albedo = -1;
  GLint uniform_color = -1;
  GLint has_normals = -1;
  GLint shading = -1;
  GLint ambient = -1;
  GLint label = -1;
};

/// The shader program: the vertex stage applies camera_from_object and the projection; the fragment
/// stage writes RGBA colour to attachment 0 and (camera z in metres, label) to attachment 1.
struct Program {
  GLuint id = 0;
  ProgramLocations locations;
};

/// Compiles and links the program; throws RenderError with the compiler log on failure.
Program CreateProgram(const Context& context);
void ReleaseProgram(const Functions& gl, Program* program);

/// An offscreen target of one size: RGBA8 colour, RG32F (camera z, label) and a 32-bit float depth buffer.
struct Framebuffer {
  GLuint id = 0;
  GLuint color = 0;
  GLuint depth_label = 0;
  GLuint depth_buffer = 0;
  int width = 0;
  int height = 0;
};

/// Makes `framebuffer` `width` x `height` pixels (recreating it when the size changes) and binds it.
void BindFramebuffer(const Context& context, int width, int height, Framebuffer* framebuffer);
void ReleaseFramebuffer(const Functions& gl, Framebuffer* framebuffer);

/// Reads the bound framebuffer: RGB colour (CV_8UC3), camera z (CV_32FC1) and labels (CV_16UC1).
/// GL row 0 is image row 0 because the projection puts image row v at window y = v + 0.5.
void ReadFramebuffer(const Context& context, const Framebuffer& framebuffer, cv::Mat* color, cv::Mat* depth,
                     cv::Mat* labels);

}  // namespace ecv::gl
