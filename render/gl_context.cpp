#include "render/gl_context.h"

#include <cstdio>
#include <cstdlib>

#include "render/renderer.h"

namespace ecv::gl {
namespace {

constexpr int kGlMajor = 3;
constexpr int kGlMinor = 3;

std::string Hex(unsigned value) {
  char text[16];
  std::snprintf(text, sizeof(text), "0x%04X", value);
  return text;
}

// MESA_GL_VERSION_OVERRIDE below 3.3 is the usual reason for a refused context; name it when set.
std::string EnvironmentHint() {
  const char* version_override = std::getenv("MESA_GL_VERSION_OVERRIDE");
  if (version_override == nullptr) return "";
  return " (MESA_GL_VERSION_OVERRIDE=" + std::string(version_override) + " is set; unset it)";
}

}  // namespace

Context::Context() {
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            0,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            kGlMajor,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            kGlMinor,
                            0};
  context_ = OSMesaCreateContextAttribs(attributes, nullptr);
  if (context_ == nullptr) {
    throw RenderError("OSMesa: could not create an offscreen OpenGL " + std::to_string(kGlMajor) + "." +
                      std::to_string(kGlMinor) +
                      " core context (OSMesaCreateContextAttribs failed); expected libOSMesa from Mesa >= 11.2 "
                      "with the llvmpipe or softpipe driver" +
                      EnvironmentHint());
  }
  try {
    MakeCurrent();
    LoadFunctions();
  } catch (...) {
    OSMesaDestroyContext(context_);
    throw;
  }
}

void Context::LoadFunctions() {
#define ECV_GL_LOAD(name)                                                                                  \
  functions_.name = reinterpret_cast<decltype(functions_.name)>(OSMesaGetProcAddress("gl" #name));         \
  if (functions_.name == nullptr) {                                                                        \
    throw RenderError("OSMesa: OSMesaGetProcAddress(\"gl" #name "\") returned null; expected OpenGL 3.3"); \
  }
  ECV_GL_FUNCTIONS(ECV_GL_LOAD)
#undef ECV_GL_LOAD
  const auto* version = functions_.GetString(GL_VERSION);
  const auto* renderer = functions_.GetString(GL_RENDERER);
  if (version == nullptr) {
    throw RenderError(
        "OSMesa: glGetString(GL_VERSION) returned null after OSMesaMakeCurrent, so GL calls would do nothing; "
        "expected a current OSMesa context (is a libGL linked before libOSMesa?)");
  }
  version_ = reinterpret_cast<const char*>(version);
  renderer_ = renderer != nullptr ? reinterpret_cast<const char*>(renderer) : "unknown";
}

Context::~Context() {
  if (context_ != nullptr) OSMesaDestroyContext(context_);
}

void Context::MakeCurrent() {
  if (OSMesaGetCurrentContext() == context_) return;
  if (!OSMesaMakeCurrent(context_, buffer_, GL_UNSIGNED_BYTE, 1, 1)) {
    throw RenderError("OSMesa: OSMesaMakeCurrent failed for the renderer's context");
  }
}

void Context::CheckErrors(const std::string& what) const {
  const GLenum error = functions_.GetError();
  if (error == GL_NO_ERROR) return;
  while (functions_.GetError() != GL_NO_ERROR) {
  }
  const std::string name = error == GL_OUT_OF_MEMORY       ? "GL_OUT_OF_MEMORY"
                           : error == GL_INVALID_VALUE     ? "GL_INVALID_VALUE"
                           : error == GL_INVALID_OPERATION ? "GL_INVALID_OPERATION"
                           : error == GL_INVALID_ENUM      ? "GL_INVALID_ENUM"
                                                           : Hex(error);
  throw RenderError("OpenGL error " + name + " while " + what);
}

}  // namespace ecv::gl
