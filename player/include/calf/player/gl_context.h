// The OpenGL entry points calf's GL renderer uses, loaded through a caller-given loader, and a
// headless OSMesa context to run them in.
//
// The player never calls a GL function by its link-time name: a process may link libGL's
// dispatch library (GLVND), which knows nothing of an OSMesa context, while OSMesa's own entry
// points know nothing of a GLX / EGL window. Every call therefore goes through a GlFunctions table
// filled from the loader of whichever context is current:
//
//   OSMesa   load_gl_functions(OSMesaGetProcAddress)   (or OsMesaContext below)
//   GLFW     load_gl_functions(glfwGetProcAddress)     after glfwMakeContextCurrent
//
// Both loaders have the GlGetProc signature (a function pointer returned by name), so they are
// passed as they are. A loader returning void* (SDL_GL_GetProcAddress, eglGetProcAddress through
// a cast) needs a one-line wrapper.
//
// What calf needs (checked by load_gl_functions, each miss a CALF-E404 naming it): an OpenGL 4.5
// core context (immutable texture storage, SSBOs, glClearTexImage, integer 2D array textures, and
// the RGTC (BC4/BC5) and BPTC (BC6H/BC7) compressed formats are all core by 4.5) and every entry
// point of the table. S3TC (BC1) and its sRGB variant are extensions
// (GL_EXT_texture_compression_s3tc, GL_EXT_texture_sRGB): their presence is recorded here and
// required only by texture layouts that use BC1 (calf/player/gl_views.h).
#pragma once

#include <GL/glcorearb.h>

#include <memory>
#include <string>

#include "calf/format/status.h"

namespace calf::player {

// A GL entry point as loaders return it, and a loader: name -> entry point (nullptr if unknown).
using GlProc = void (*)();
using GlGetProc = GlProc (*)(const char* name);

// Every GL entry point the player calls: X(type, name) for the field `name` loaded as "gl<name>".
// clang-format off
#define CALF_GL_FUNCTIONS(X)                                        \
  X(PFNGLGETERRORPROC, GetError)                                    \
  X(PFNGLGETSTRINGPROC, GetString)                                  \
  X(PFNGLGETSTRINGIPROC, GetStringi)                                \
  X(PFNGLGETINTEGERVPROC, GetIntegerv)                              \
  X(PFNGLFINISHPROC, Finish)                                        \
  X(PFNGLDISABLEPROC, Disable)                                      \
  X(PFNGLVIEWPORTPROC, Viewport)                                    \
  X(PFNGLPIXELSTOREIPROC, PixelStorei)                              \
  X(PFNGLGENTEXTURESPROC, GenTextures)                              \
  X(PFNGLDELETETEXTURESPROC, DeleteTextures)                        \
  X(PFNGLBINDTEXTUREPROC, BindTexture)                              \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture)                          \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri)                          \
  X(PFNGLTEXSTORAGE2DPROC, TexStorage2D)                            \
  X(PFNGLTEXSTORAGE3DPROC, TexStorage3D)                            \
  X(PFNGLTEXSUBIMAGE3DPROC, TexSubImage3D)                          \
  X(PFNGLCOMPRESSEDTEXSUBIMAGE3DPROC, CompressedTexSubImage3D)      \
  X(PFNGLCLEARTEXIMAGEPROC, ClearTexImage)                          \
  X(PFNGLCREATESHADERPROC, CreateShader)                            \
  X(PFNGLSHADERSOURCEPROC, ShaderSource)                            \
  X(PFNGLCOMPILESHADERPROC, CompileShader)                          \
  X(PFNGLGETSHADERIVPROC, GetShaderiv)                              \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                    \
  X(PFNGLDELETESHADERPROC, DeleteShader)                            \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram)                          \
  X(PFNGLATTACHSHADERPROC, AttachShader)                            \
  X(PFNGLLINKPROGRAMPROC, LinkProgram)                              \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                            \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                  \
  X(PFNGLUSEPROGRAMPROC, UseProgram)                                \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                          \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                \
  X(PFNGLUNIFORM1IPROC, Uniform1i)                                  \
  X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                \
  X(PFNGLUNIFORM1FPROC, Uniform1f)                                  \
  X(PFNGLUNIFORM2FPROC, Uniform2f)                                  \
  X(PFNGLUNIFORM2UIPROC, Uniform2ui)                                \
  X(PFNGLUNIFORM3FPROC, Uniform3f)                                  \
  X(PFNGLGENBUFFERSPROC, GenBuffers)                                \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                          \
  X(PFNGLBINDBUFFERPROC, BindBuffer)                                \
  X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                        \
  X(PFNGLBUFFERDATAPROC, BufferData)                                \
  X(PFNGLGETBUFFERSUBDATAPROC, GetBufferSubData)                    \
  X(PFNGLDISPATCHCOMPUTEPROC, DispatchCompute)                      \
  X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                          \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays)                      \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                      \
  X(PFNGLDRAWARRAYSPROC, DrawArrays)                                \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers)                      \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                      \
  X(PFNGLFRAMEBUFFERTEXTURE2DPROC, FramebufferTexture2D)            \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)        \
  X(PFNGLDRAWBUFFERSPROC, DrawBuffers)                              \
  X(PFNGLREADBUFFERPROC, ReadBuffer)                                \
  X(PFNGLREADPIXELSPROC, ReadPixels)                                \
  X(PFNGLENABLEPROC, Enable)                                        \
  X(PFNGLDEPTHFUNCPROC, DepthFunc)                                  \
  X(PFNGLCLIPCONTROLPROC, ClipControl)                              \
  X(PFNGLCLEARBUFFERFVPROC, ClearBufferfv)                          \
  X(PFNGLDRAWELEMENTSPROC, DrawElements)                            \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)              \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray)      \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)    \
  X(PFNGLVERTEXATTRIB3FPROC, VertexAttrib3f)                        \
  X(PFNGLBUFFERSUBDATAPROC, BufferSubData)                          \
  X(PFNGLCLEARBUFFERDATAPROC, ClearBufferData)                      \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate)                  \
  X(PFNGLBLENDEQUATIONSEPARATEPROC, BlendEquationSeparate)
// clang-format on

// The loaded table plus what the context offers. Valid only while the context it was loaded in
// is current (on the thread that made it current).
struct GlFunctions {
#define CALF_GL_FIELD(type, name) type name = nullptr;
  CALF_GL_FUNCTIONS(CALF_GL_FIELD)
#undef CALF_GL_FIELD
  int major_version = 0, minor_version = 0;
  std::string renderer;    // GL_RENDERER, for reports ("llvmpipe (LLVM 15.0.6, 256 bits)")
  bool s3tc = false;       // GL_EXT_texture_compression_s3tc (BC1)
  bool s3tc_srgb = false;  // sRGB BC1 (GL_EXT_texture_sRGB or GL_EXT_texture_compression_s3tc_srgb)
  int max_texture_size = 0;  // GL_MAX_TEXTURE_SIZE
  int max_array_layers = 0;  // GL_MAX_ARRAY_TEXTURE_LAYERS
};

// Loads every entry point through `get_proc` from the context current on this thread and checks
// that it is OpenGL 4.5 or later. Errors (CALF-E404): a null loader, no current context, a version
// below 4.5 ("needs OpenGL 4.5, the context has 3.3"), an entry point the loader does not know
// ("glTexStorage3D is missing").
Expected<GlFunctions> load_gl_functions(GlGetProc get_proc);

// The first pending GL error as a Status (CALF-E412 "<what>: GL error 0x0501"), or Ok; drains
// every pending error so the next check starts clean.
Status check_gl_error(const GlFunctions& gl, const char* what);

// A headless OpenGL 4.5 core context from OSMesa (llvmpipe on a machine without a GPU driver),
// current on the creating thread, with a 1 x 1 default framebuffer: calf renders into its own
// framebuffer objects. Not copyable; destroying it destroys the context (and every GL object in
// it).
class OsMesaContext {
 public:
  // Errors (CALF-E404): OSMesa cannot create a 4.5 core context, or it lacks something
  // load_gl_functions() needs.
  static Expected<std::unique_ptr<OsMesaContext>> make();
  ~OsMesaContext();
  OsMesaContext(const OsMesaContext&) = delete;
  OsMesaContext& operator=(const OsMesaContext&) = delete;

  // OSMesaGetProcAddress, with the GlGetProc signature.
  static GlGetProc proc_loader();
  const GlFunctions& gl() const { return gl_; }
  // Makes the context current on the calling thread again (after another context was).
  Status make_current();

 private:
  OsMesaContext() = default;
  struct Handle;
  std::unique_ptr<Handle> handle_;
  GlFunctions gl_;
};

}  // namespace calf::player
