// Private to the player: compiling and linking a GLSL 4.50 program from its stages, shared by the
// light-field ray-marcher (lightfield_gl_renderer.cc), the mesh rasteriser (mesh_gl_renderer.cc),
// the surfel splatter (surfel_gl_renderer.cc) and the tiles rasteriser (tiles_gl_renderer.cc); and
// the upload of the rasterisers' camera.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/glsl_conventions.h"
#include "gl_errors.h"

namespace calf::player::internal {

// One shader stage: its type (GL_VERTEX_SHADER ...), its source after the `#version` line, and a
// name for errors ("vertex", "ray-march").
struct GlStage {
  GLenum type;
  std::string source;
  const char* name;
};

// Compiles every stage with `#version 450 core` prepended and links them into a program.
// `program` names it in errors ("the mesh program"). Errors: CALF-E404 naming the stage that
// does not compile or the program that does not link, with the driver's log. Shaders are deleted
// either way; the caller owns the returned program.
inline Expected<GLuint> build_gl_program(const GlFunctions& gl,
                                         std::initializer_list<GlStage> stages,
                                         const std::string& program) {
  std::vector<GLuint> shaders;
  const auto release = [&] {
    for (GLuint s : shaders) gl.DeleteShader(s);
  };
  for (const GlStage& stage : stages) {
    const std::string text = "#version 450 core\n" + stage.source;
    const GLuint shader = gl.CreateShader(stage.type);
    shaders.push_back(shader);
    const char* source = text.c_str();
    gl.ShaderSource(shader, 1, &source, nullptr);
    gl.CompileShader(shader);
    GLint ok = 0;
    gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      std::vector<char> log(8192, '\0');
      gl.GetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
      release();
      return Status(kGlMissing,
                    program + ": the " + stage.name + " shader does not compile: " + log.data());
    }
  }
  const GLuint id = gl.CreateProgram();
  for (GLuint s : shaders) gl.AttachShader(id, s);
  gl.LinkProgram(id);
  release();
  GLint ok = 0;
  gl.GetProgramiv(id, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::vector<char> log(8192, '\0');
    gl.GetProgramInfoLog(id, static_cast<GLsizei>(log.size()), nullptr, log.data());
    gl.DeleteProgram(id);
    return Status(kGlMissing, program + " does not link: " + log.data());
  }
  return id;
}

// Sets the uniform `uniform CalfRasterCamera calf_camera;` (glsl_conventions.h) of `program`,
// which must be in use, to glsl_raster_camera(camera, near).
inline void upload_raster_camera(const GlFunctions& gl, GLuint program, const Camera& camera,
                                 double near) {
  const GlslRasterCamera c = glsl_raster_camera(camera, near);
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program, name); };
  gl.Uniform3f(loc("calf_camera.right"), c.right[0], c.right[1], c.right[2]);
  gl.Uniform3f(loc("calf_camera.up"), c.up[0], c.up[1], c.up[2]);
  gl.Uniform3f(loc("calf_camera.forward"), c.forward[0], c.forward[1], c.forward[2]);
  gl.Uniform1f(loc("calf_camera.scale_x"), c.scale_x);
  gl.Uniform1f(loc("calf_camera.scale_y"), c.scale_y);
  gl.Uniform1f(loc("calf_camera.near_distance"), c.near_distance);
}

}  // namespace calf::player::internal
