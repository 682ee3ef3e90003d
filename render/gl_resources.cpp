#include "render/gl_resources.h"

#include <algorithm>
#include <string>

#include <opencv2/imgproc.hpp>

#include "render/renderer.h"

namespace ecv::gl {
namespace {

// Attribute locations shared by UploadMesh and the vertex shader.
enum Attribute : GLuint { kPosition = 0, kNormal = 1, kTexcoord = 2, kVertexColor = 3 };

const char* const kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 texcoord;
layout(location = 3) in vec3 vertex_color;
uniform mat4 camera_from_object;
uniform mat4 projection;
out vec3 position_camera;
out vec3 normal_camera;
out vec2 texture_st;
out vec3 color;
void main() {
  vec4 p = camera_from_object * vec4(position, 1.0);
  position_camera = p.xyz;
  normal_camera = mat3(camera_from_object) * normal;
  texture_st = vec2(texcoord.x, 1.0 - texcoord.y);  // OBJ: texture row = (1 - v) * height; row 0 uploaded first
  color = vertex_color;
  gl_Position = projection * p;
}
)";

const char* const kFragmentShader = R"(#version 330 core
in vec3 position_camera;
in vec3 normal_camera;
in vec2 texture_st;
in vec3 color;
uniform int coloring;  // 0 texture, 1 vertex colours, 2 uniform colour
uniform sampler2D albedo;
uniform vec3 uniform_color;
uniform int has_normals;
uniform int shading;  // 0 unlit, 1 headlight
uniform float ambient;
uniform float label;
layout(location = 0) out vec4 out_color;
layout(location = 1) out vec2 out_depth_label;
void main() {
  vec3 c = coloring == 0 ? texture(albedo, texture_st).rgb : (coloring == 1 ? color : uniform_color);
  if (shading == 1) {
    vec3 n = has_normals == 1 ? normal_camera : cross(dFdx(position_camera), dFdy(position_camera));
    float lambert = abs(dot(normalize(n), normalize(position_camera)));
    c *= ambient + (1.0 - ambient) * lambert;
  }
  out_color = vec4(c, 1.0);
  out_depth_label = vec2(position_camera.z, label);  // exact camera z, interpolated perspective-correctly
}
)";

GLuint CompileShader(const Context& context, GLenum stage, const char* source) {
  const Functions& gl = context.functions();
  const GLuint shader = gl.CreateShader(stage);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = GL_FALSE;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[2048] = {0};
    gl.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
    gl.DeleteShader(shader);
    throw RenderError(std::string("OpenGL: the renderer's shader does not compile: ") + log);
  }
  return shader;
}

// Uploads one attribute array of `count` vectors of `size` floats to a new buffer at `location`.
GLuint UploadAttribute(const Functions& gl, GLuint location, int size, const float* data, size_t count) {
  GLuint buffer = 0;
  gl.GenBuffers(1, &buffer);
  gl.BindBuffer(GL_ARRAY_BUFFER, buffer);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(count * size * sizeof(float)), data, GL_STATIC_DRAW);
  gl.VertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, 0, nullptr);
  gl.EnableVertexAttribArray(location);
  return buffer;
}

GLuint UploadTexture(const Context& context, const cv::Mat& texture, bool mipmaps, int max_texture_size) {
  const Functions& gl = context.functions();
  cv::Mat image = CapTextureSize(texture, max_texture_size);
  if (!image.isContinuous()) image = image.clone();
  GLuint id = 0;
  gl.GenTextures(1, &id);
  gl.BindTexture(GL_TEXTURE_2D, id);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, image.cols, image.rows, 0, GL_RGB, GL_UNSIGNED_BYTE, image.data);
  if (mipmaps) gl.GenerateMipmap(GL_TEXTURE_2D);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  context.CheckErrors("uploading a " + std::to_string(image.cols) + "x" + std::to_string(image.rows) + " texture");
  return id;
}

Part UploadPart(const Context& context, const TriangleMesh& mesh, const MeshPart& part,
                const std::vector<GLuint>& material_textures) {
  const Functions& gl = context.functions();
  Part uploaded;
  gl.GenVertexArrays(1, &uploaded.vertex_array);
  gl.BindVertexArray(uploaded.vertex_array);
  const size_t n = part.positions.size();
  uploaded.buffers.push_back(UploadAttribute(gl, kPosition, 3, part.positions.front().data(), n));
  uploaded.has_normals = !part.normals.empty();
  if (uploaded.has_normals) uploaded.buffers.push_back(UploadAttribute(gl, kNormal, 3, part.normals[0].data(), n));
  const MeshColoring coloring = mesh.Coloring(part);
  if (coloring == MeshColoring::kTexture) {
    uploaded.buffers.push_back(UploadAttribute(gl, kTexcoord, 2, part.texcoords[0].data(), n));
    uploaded.coloring = kColorFromTexture;
    uploaded.texture = material_textures[static_cast<size_t>(part.material)];
  } else if (coloring == MeshColoring::kVertexColor) {
    uploaded.buffers.push_back(UploadAttribute(gl, kVertexColor, 3, part.colors[0].data(), n));
    uploaded.coloring = kColorFromVertices;
  } else {
    uploaded.coloring = kColorUniform;
    if (part.material >= 0) uploaded.color = mesh.materials[static_cast<size_t>(part.material)].diffuse_color;
  }
  GLuint indices = 0;
  gl.GenBuffers(1, &indices);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices);  // recorded in the vertex array
  static_assert(sizeof(Eigen::Vector3i) == 3 * sizeof(GLint), "triangles must be packed int triples");
  gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(part.triangles.size() * sizeof(Eigen::Vector3i)),
                part.triangles.data(), GL_STATIC_DRAW);
  uploaded.buffers.push_back(indices);
  uploaded.num_indices = static_cast<GLsizei>(3 * part.triangles.size());
  gl.BindVertexArray(0);
  return uploaded;
}

}  // namespace

Mesh UploadMesh(const Context& context, const TriangleMesh& mesh, bool mipmaps, int max_texture_size) {
  const Functions& gl = context.functions();
  Mesh uploaded;
  std::vector<GLuint> material_textures(mesh.materials.size(), 0);
  try {
    for (const MeshPart& part : mesh.parts) {
      if (part.triangles.empty() || mesh.Coloring(part) != MeshColoring::kTexture) continue;
      GLuint& texture = material_textures[static_cast<size_t>(part.material)];
      if (texture != 0) continue;
      texture =
          UploadTexture(context, mesh.materials[static_cast<size_t>(part.material)].texture, mipmaps, max_texture_size);
      uploaded.textures.push_back(texture);
    }
    for (const MeshPart& part : mesh.parts) {
      if (!part.triangles.empty()) uploaded.parts.push_back(UploadPart(context, mesh, part, material_textures));
    }
    context.CheckErrors("uploading mesh '" + mesh.name + "'");
  } catch (...) {
    ReleaseMesh(gl, &uploaded);
    throw;
  }
  return uploaded;
}

void ReleaseMesh(const Functions& gl, Mesh* mesh) {
  for (Part& part : mesh->parts) {
    gl.DeleteBuffers(static_cast<GLsizei>(part.buffers.size()), part.buffers.data());
    gl.DeleteVertexArrays(1, &part.vertex_array);
  }
  if (!mesh->textures.empty()) gl.DeleteTextures(static_cast<GLsizei>(mesh->textures.size()), mesh->textures.data());
  *mesh = Mesh();
}

Program CreateProgram(const Context& context) {
  const Functions& gl = context.functions();
  const GLuint vertex = CompileShader(context, GL_VERTEX_SHADER, kVertexShader);
  const GLuint fragment = CompileShader(context, GL_FRAGMENT_SHADER, kFragmentShader);
  Program program;
  program.id = gl.CreateProgram();
  gl.AttachShader(program.id, vertex);
  gl.AttachShader(program.id, fragment);
  gl.LinkProgram(program.id);
  gl.DeleteShader(vertex);
  gl.DeleteShader(fragment);
  GLint ok = GL_FALSE;
  gl.GetProgramiv(program.id, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[2048] = {0};
    gl.GetProgramInfoLog(program.id, sizeof(log), nullptr, log);
    gl.DeleteProgram(program.id);
    throw RenderError(std::string("OpenGL: the renderer's shader program does not link: ") + log);
  }
  ProgramLocations& at = program.locations;
  at.camera_from_object = gl.GetUniformLocation(program.id, "camera_from_object");
  at.projection = gl.GetUniformLocation(program.id, "projection");
  at.coloring = gl.GetUniformLocation(program.id, "coloring");
  at.albedo = gl.GetUniformLocation(program.id, "albedo");
  at.uniform_color = gl.GetUniformLocation(program.id, "uniform_color");
  at.has_normals = gl.GetUniformLocation(program.id, "has_normals");
  at.shading = gl.GetUniformLocation(program.id, "shading");
  at.ambient = gl.GetUniformLocation(program.id, "ambient");
  at.label = gl.GetUniformLocation(program.id, "label");
  context.CheckErrors("building the shader program");
  return program;
}

void ReleaseProgram(const Functions& gl, Program* program) {
  if (program->id != 0) gl.DeleteProgram(program->id);
  program->id = 0;
}

void BindFramebuffer(const Context& context, int width, int height, Framebuffer* framebuffer) {
  const Functions& gl = context.functions();
  if (framebuffer->id != 0 && framebuffer->width == width && framebuffer->height == height) {
    gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer->id);
    return;
  }
  ReleaseFramebuffer(gl, framebuffer);
  gl.GenFramebuffers(1, &framebuffer->id);
  gl.BindFramebuffer(GL_FRAMEBUFFER, framebuffer->id);
  const struct {
    GLuint* id;
    GLenum format;
    GLenum attachment;
  } buffers[] = {{&framebuffer->color, GL_RGBA8, GL_COLOR_ATTACHMENT0},
                 {&framebuffer->depth_label, GL_RG32F, GL_COLOR_ATTACHMENT1},
                 {&framebuffer->depth_buffer, GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT}};
  for (const auto& buffer : buffers) {
    gl.GenRenderbuffers(1, buffer.id);
    gl.BindRenderbuffer(GL_RENDERBUFFER, *buffer.id);
    gl.RenderbufferStorage(GL_RENDERBUFFER, buffer.format, width, height);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, buffer.attachment, GL_RENDERBUFFER, *buffer.id);
  }
  const GLenum draw_buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  gl.DrawBuffers(2, draw_buffers);
  framebuffer->width = width;
  framebuffer->height = height;
  const GLenum status = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
  context.CheckErrors("creating a " + std::to_string(width) + "x" + std::to_string(height) + " framebuffer");
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    ReleaseFramebuffer(gl, framebuffer);
    throw RenderError("OpenGL: the " + std::to_string(width) + "x" + std::to_string(height) +
                      " framebuffer is incomplete (status " + std::to_string(status) + ")");
  }
}

void ReleaseFramebuffer(const Functions& gl, Framebuffer* framebuffer) {
  if (framebuffer->id == 0) return;
  gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
  GLuint renderbuffers[] = {framebuffer->color, framebuffer->depth_label, framebuffer->depth_buffer};
  gl.DeleteRenderbuffers(3, renderbuffers);
  gl.DeleteFramebuffers(1, &framebuffer->id);
  *framebuffer = Framebuffer();
}

void ReadFramebuffer(const Context& context, const Framebuffer& framebuffer, cv::Mat* color, cv::Mat* depth,
                     cv::Mat* labels) {
  const Functions& gl = context.functions();
  const int width = framebuffer.width;
  const int height = framebuffer.height;
  cv::Mat rgba(height, width, CV_8UC4);
  cv::Mat depth_label(height, width, CV_32FC2);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
  gl.ReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  gl.ReadBuffer(GL_COLOR_ATTACHMENT1);
  gl.ReadPixels(0, 0, width, height, GL_RG, GL_FLOAT, depth_label.data);
  context.CheckErrors("reading the rendered images");
  cv::cvtColor(rgba, *color, cv::COLOR_RGBA2RGB);
  cv::Mat channels[2];
  cv::split(depth_label, channels);
  *depth = channels[0];
  channels[1].convertTo(*labels, CV_16U);
}

}  // namespace ecv::gl
