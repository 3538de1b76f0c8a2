// The GL function table and its checks (calf/player/gl_context.h): a missing entry point, an old
// context, a missing extension, a shader that does not compile and a GL error each give a clear
// Status naming what is missing. Missing features are simulated with loaders that wrap OSMesa's
// and hide or fake one thing.
#include "calf/player/gl_context.h"

#include <GL/osmesa.h>
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "../gl_test_context.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_gl_renderer.h"

namespace calf::player {
namespace {

using ::calf::test::gl_context;

GlProc real(const char* name) {
  return OsMesaContext::proc_loader()(name);
}

// Loaders that hide or fake one thing (plain functions: a GlGetProc carries no state).
GlProc without_tex_storage(const char* name) {
  return std::strcmp(name, "glTexStorage3D") == 0 ? nullptr : real(name);
}

void APIENTRY version_33(GLenum pname, GLint* v) {
  if (pname == GL_MAJOR_VERSION) {
    *v = 3;
  } else if (pname == GL_MINOR_VERSION) {
    *v = 3;
  } else {
    reinterpret_cast<PFNGLGETINTEGERVPROC>(real("glGetIntegerv"))(pname, v);
  }
}
GlProc old_context(const char* name) {
  return std::strcmp(name, "glGetIntegerv") == 0 ? reinterpret_cast<GlProc>(&version_33)
                                                 : real(name);
}

const GLubyte* APIENTRY no_extension(GLenum, GLuint) {
  return reinterpret_cast<const GLubyte*>("GL_CALF_nothing");
}
GlProc without_extensions(const char* name) {
  return std::strcmp(name, "glGetStringi") == 0 ? reinterpret_cast<GlProc>(&no_extension)
                                                : real(name);
}

void APIENTRY shader_fails(GLuint shader, GLenum pname, GLint* v) {
  reinterpret_cast<PFNGLGETSHADERIVPROC>(real("glGetShaderiv"))(shader, pname, v);
  if (pname == GL_COMPILE_STATUS) *v = GL_FALSE;
}
GlProc failing_compiler(const char* name) {
  return std::strcmp(name, "glGetShaderiv") == 0 ? reinterpret_cast<GlProc>(&shader_fails)
                                                 : real(name);
}

GlTextureLayout one_view(container::PixelFormat colour) {
  GlTextureLayout layout;
  layout.views = {{{0, 0, 0}, *LogDepthRange::make(0.5, 10), 8, 8, false}};
  layout.colour_format = colour;
  return layout;
}

TEST(GlContext, LoadsEveryEntryPointFromACurrentContext) {
  CALF_REQUIRE_GL();
  const GlFunctions& gl = gl_context()->gl();
  EXPECT_GE(gl.major_version * 10 + gl.minor_version, 45);
  EXPECT_FALSE(gl.renderer.empty());
  EXPECT_GE(gl.max_texture_size, 2048);
  EXPECT_GE(gl.max_array_layers, 256);
  std::printf("%s, GL %d.%d, S3TC %d, sRGB S3TC %d, max texture %d, max layers %d\n",
              gl.renderer.c_str(), gl.major_version, gl.minor_version, gl.s3tc, gl.s3tc_srgb,
              gl.max_texture_size, gl.max_array_layers);
  const Expected<GlFunctions> again = load_gl_functions(OsMesaContext::proc_loader());
  ASSERT_TRUE(again.ok()) << again.status().to_string();
  EXPECT_EQ(again->TexStorage3D, gl.TexStorage3D);
}

TEST(GlContext, MissingThingsAreNamed) {
  CALF_REQUIRE_GL();
  const Status null_loader = load_gl_functions(nullptr).status();
  EXPECT_EQ(null_loader.number(), 404);

  const Status missing = load_gl_functions(&without_tex_storage).status();
  EXPECT_EQ(missing.number(), 404);
  EXPECT_NE(missing.message().find("glTexStorage3D"), std::string::npos) << missing.to_string();

  const Status old = load_gl_functions(&old_context).status();
  EXPECT_EQ(old.number(), 404);
  EXPECT_NE(old.message().find("OpenGL 4.5"), std::string::npos) << old.to_string();
  EXPECT_NE(old.message().find("3.3"), std::string::npos) << old.to_string();

  // Without S3TC, BC1 layouts are refused by name; BC7 needs no extension.
  const Expected<GlFunctions> bare = load_gl_functions(&without_extensions);
  ASSERT_TRUE(bare.ok()) << bare.status().to_string();
  EXPECT_FALSE(bare->s3tc);
  const Status bc1 = GlViews::make(*bare, one_view(container::PixelFormat::kBc1)).status();
  EXPECT_EQ(bc1.number(), 404);
  EXPECT_NE(bc1.message().find("GL_EXT_texture_compression_s3tc"), std::string::npos)
      << bc1.to_string();
  EXPECT_TRUE(GlViews::make(*bare, one_view(container::PixelFormat::kBc7)).ok());
  // Too many views for the context's array layers.
  GlFunctions small = gl_context()->gl();
  small.max_array_layers = 24;  // two views of 6 faces x 2 keyframe slots
  GlTextureLayout two = one_view(container::PixelFormat::kRgba8);
  two.views.push_back(two.views[0]);
  EXPECT_TRUE(GlViews::make(small, two).ok());
  two.views.push_back(two.views[0]);
  EXPECT_EQ(GlViews::make(small, two).status().number(), 404);
}

TEST(GlContext, ShaderFailuresAndGlErrorsAreReported) {
  CALF_REQUIRE_GL();
  const Expected<GlFunctions> gl = load_gl_functions(&failing_compiler);
  ASSERT_TRUE(gl.ok());
  std::unique_ptr<GlViews> views = *GlViews::make(*gl, one_view(container::PixelFormat::kRgba8));
  const Status compile = LightfieldGlRenderer::make(*views, {}).status();
  EXPECT_EQ(compile.number(), 404);
  EXPECT_NE(compile.message().find("does not compile"), std::string::npos) << compile.to_string();

  const GlFunctions& real_gl = gl_context()->gl();
  EXPECT_TRUE(check_gl_error(real_gl, "nothing").ok());
  real_gl.BindTexture(0x1234, 0);  // not a texture target: GL_INVALID_ENUM
  const Status error = check_gl_error(real_gl, "binding a bad target");
  EXPECT_EQ(error.number(), 412);
  EXPECT_NE(error.message().find("binding a bad target: GL error 0x0500"), std::string::npos)
      << error.to_string();
  EXPECT_TRUE(check_gl_error(real_gl, "drained").ok());
}

TEST(GlContext, NoCurrentContextIsAnError) {
  CALF_REQUIRE_GL();
  ASSERT_TRUE(OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0));
  const Status none = load_gl_functions(OsMesaContext::proc_loader()).status();
  ASSERT_TRUE(gl_context()->make_current().ok());
  EXPECT_EQ(none.number(), 404);
  EXPECT_NE(none.message().find("no OpenGL context"), std::string::npos) << none.to_string();
}

}  // namespace
}  // namespace calf::player
