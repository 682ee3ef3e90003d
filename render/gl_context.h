#pragma once

// Internal to ecv_render: the OSMesa context and the GL entry points. Only render/*.cpp include this;
// the public headers do not expose GL.

#include <string>

#define GL_GLEXT_PROTOTYPES 1  // declarations only, for decltype below; nothing links against libGL
#include <GL/osmesa.h>         // includes GL/gl.h and GL/glext.h

namespace ecv::gl {

// Every GL function the renderer calls. All of them, GL 1.1 ones included, are fetched with
// OSMesaGetProcAddress, so calls reach OSMesa's dispatch even when a libGL is loaded in the process.
// clang-format off
#define ECV_GL_FUNCTIONS(X) \
  X(GetString) X(GetError) X(GetIntegerv) X(Viewport) X(Enable) X(Disable) X(DepthFunc) X(DepthMask) X(Clear) \
  X(ClearDepth) X(ReadPixels) X(ReadBuffer) X(PixelStorei) X(GenTextures) X(DeleteTextures) X(BindTexture) \
  X(TexImage2D) X(TexParameteri) X(DrawElements) X(Finish) X(ActiveTexture) X(GenBuffers) X(DeleteBuffers) \
  X(BindBuffer) X(BufferData) X(CreateShader) X(ShaderSource) X(CompileShader) X(GetShaderiv) \
  X(GetShaderInfoLog) X(DeleteShader) X(CreateProgram) X(AttachShader) X(LinkProgram) X(GetProgramiv) \
  X(GetProgramInfoLog) X(DeleteProgram) X(UseProgram) X(GetUniformLocation) X(Uniform1i) X(Uniform1f) \
  X(Uniform3f) X(UniformMatrix4fv) X(VertexAttribPointer) X(EnableVertexAttribArray) \
  X(DisableVertexAttribArray) X(VertexAttrib2f) X(VertexAttrib3f) X(DrawBuffers) X(GenVertexArrays) \
  X(DeleteVertexArrays) X(BindVertexArray) X(GenFramebuffers) X(DeleteFramebuffers) X(BindFramebuffer) \
  X(FramebufferRenderbuffer) X(CheckFramebufferStatus) X(GenRenderbuffers) X(DeleteRenderbuffers) \
  X(BindRenderbuffer) X(RenderbufferStorage) X(GenerateMipmap) X(ClearBufferfv) X(CullFace) X(FrontFace)
// clang-format on

/// Pointers to the GL functions above, named without the "gl" prefix: `gl.DrawElements(...)`.
struct Functions {
#define ECV_GL_DECLARE(name) decltype(&::gl##name) name = nullptr;  // NOLINT(bugprone-macro-parentheses)
  ECV_GL_FUNCTIONS(ECV_GL_DECLARE)
#undef ECV_GL_DECLARE
};

/// An OSMesa GL 3.3 core context rendering into framebuffer objects (its own buffer is 1x1 and unused).
/// Created once per Renderer. Throws RenderError when it cannot be created or made current, when
/// glGetString(GL_VERSION) gives nothing (GL calls would silently do nothing) or when a GL function is
/// missing.
class Context {
 public:
  Context();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  /// Makes this context current in the calling thread (cheap when it already is).
  void MakeCurrent();

  const Functions& functions() const { return functions_; }

  /// GL_VERSION and GL_RENDERER, e.g. "4.5 (Core Profile) Mesa 22.3.6", "llvmpipe (LLVM 15.0.6, 256 bits)".
  const std::string& version() const { return version_; }
  const std::string& renderer() const { return renderer_; }

  /// Throws RenderError naming `what` if a GL error is pending.
  void CheckErrors(const std::string& what) const;

 private:
  void LoadFunctions();

  OSMesaContext context_ = nullptr;
  unsigned char buffer_[4] = {0, 0, 0, 0};  // the 1x1 RGBA default framebuffer OSMesa requires
  Functions functions_;
  std::string version_;
  std::string renderer_;
};

}  // namespace ecv::gl
