#include "calf/player/gl_context.h"

// osmesa.h includes GL/gl.h, which declares (but never calls) the link-time entry points; only
// the OSMesa* functions are called directly.
#include <GL/osmesa.h>

#include <cstdio>
#include <cstring>
#include <string>

#include "gl_errors.h"

namespace calf::player {

using internal::kGlCall;
using internal::kGlMissing;

Expected<GlFunctions> load_gl_functions(GlGetProc get_proc) {
  if (get_proc == nullptr) return Status(kGlMissing, "no GL entry-point loader was given");
  GlFunctions gl;
#define CALF_GL_LOAD(type, name)                                                               \
  gl.name = reinterpret_cast<type>(get_proc("gl" #name));                                      \
  if (gl.name == nullptr) {                                                                    \
    return Status(kGlMissing, "the GL entry point gl" #name " is missing (needs OpenGL 4.5)"); \
  }
  CALF_GL_FUNCTIONS(CALF_GL_LOAD)
#undef CALF_GL_LOAD
  // Without a current context glGetString returns null (and a context below 3.0 has no
  // GL_MAJOR_VERSION query: the version stays 0 and is refused below).
  const auto* version = reinterpret_cast<const char*>(gl.GetString(GL_VERSION));
  if (version == nullptr) return Status(kGlMissing, "no OpenGL context is current");
  gl.GetIntegerv(GL_MAJOR_VERSION, &gl.major_version);
  gl.GetIntegerv(GL_MINOR_VERSION, &gl.minor_version);
  if (gl.major_version < 4 || (gl.major_version == 4 && gl.minor_version < 5)) {
    return Status(kGlMissing, "the GL renderer needs OpenGL 4.5, the context has " +
                                  std::to_string(gl.major_version) + "." +
                                  std::to_string(gl.minor_version) + " (" + version + ")");
  }
  const auto* renderer = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER));
  gl.renderer = renderer ? renderer : "";
  GLint count = 0;
  gl.GetIntegerv(GL_NUM_EXTENSIONS, &count);
  for (GLint i = 0; i < count; ++i) {
    const auto* e = reinterpret_cast<const char*>(gl.GetStringi(GL_EXTENSIONS, i));
    if (e == nullptr) continue;
    if (std::strcmp(e, "GL_EXT_texture_compression_s3tc") == 0) gl.s3tc = true;
    if (std::strcmp(e, "GL_EXT_texture_sRGB") == 0 ||
        std::strcmp(e, "GL_EXT_texture_compression_s3tc_srgb") == 0) {
      gl.s3tc_srgb = true;
    }
  }
  gl.s3tc_srgb = gl.s3tc_srgb && gl.s3tc;
  gl.GetIntegerv(GL_MAX_TEXTURE_SIZE, &gl.max_texture_size);
  gl.GetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &gl.max_array_layers);
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "querying the context"));
  return gl;
}

Status check_gl_error(const GlFunctions& gl, const char* what) {
  GLenum first = GL_NO_ERROR;
  // glGetError returns one recorded error per call; a lost context keeps returning one, so the
  // drain is bounded.
  for (int i = 0; i < 16; ++i) {
    const GLenum e = gl.GetError();
    if (e == GL_NO_ERROR) break;
    if (first == GL_NO_ERROR) first = e;
  }
  if (first == GL_NO_ERROR) return Status::Ok();
  char buf[32];
  std::snprintf(buf, sizeof buf, "GL error 0x%04X", first);
  return Status(kGlCall, std::string(what) + ": " + buf);
}

struct OsMesaContext::Handle {
  OSMesaContext ctx = nullptr;
  unsigned char pixel[4] = {0, 0, 0, 0};  // the 1 x 1 default framebuffer
  ~Handle() {
    if (ctx != nullptr) OSMesaDestroyContext(ctx);
  }
};

namespace {

GlProc osmesa_proc(const char* name) {
  return OSMesaGetProcAddress(name);
}

}  // namespace

GlGetProc OsMesaContext::proc_loader() {
  return &osmesa_proc;
}

Expected<std::unique_ptr<OsMesaContext>> OsMesaContext::make() {
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         4,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         5,
                         0};
  std::unique_ptr<OsMesaContext> c(new OsMesaContext());
  c->handle_ = std::make_unique<Handle>();
  c->handle_->ctx = OSMesaCreateContextAttribs(attribs, nullptr);
  if (c->handle_->ctx == nullptr) {
    return Status(kGlMissing, "OSMesa cannot create an OpenGL 4.5 core context");
  }
  CALF_RETURN_IF_ERROR(c->make_current());
  CALF_ASSIGN_OR_RETURN(c->gl_, load_gl_functions(proc_loader()));
  return c;
}

OsMesaContext::~OsMesaContext() = default;

Status OsMesaContext::make_current() {
  if (!OSMesaMakeCurrent(handle_->ctx, handle_->pixel, GL_UNSIGNED_BYTE, 1, 1)) {
    return Status(kGlMissing, "OSMesaMakeCurrent failed");
  }
  return Status::Ok();
}

}  // namespace calf::player
