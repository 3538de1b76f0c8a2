// The OpenGL 4.5 splatter of a surfel draw list (surfel_renderer.h). Eye-relative coordinates
// throughout, as the mesh renderer: the CPU folds the eye into each object's translation in
// double.
#include <cmath>
#include <string>
#include <vector>

#include "calf/player/mesh_draw_list.h"
#include "calf/player/surfel_renderer.h"
#include "gl_errors.h"
#include "gl_program.h"
#include "gl_raster_target.h"
#include "object_transform.h"

namespace calf::player {
namespace {

constexpr const char* kVertexShader = R"(
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
out vec3 v_position;
out vec3 v_normal;
out vec3 v_colour;
void main() {
  v_position = position;
  v_normal = normal;
  v_colour = colour;
}
)";

// Each point becomes its disc's bounding parallelogram in world space (surfel_renderer.h).
constexpr const char* kGeometryShader = R"(
layout(points) in;
layout(triangle_strip, max_vertices = 4) out;
in vec3 v_position[];
in vec3 v_normal[];
in vec3 v_colour[];
// Object -> eye-relative world: columns of the 3 x 3 part and the translation minus the eye.
uniform vec3 model_x, model_y, model_z, model_t;
uniform float radius;
uniform vec3 tint;
uniform CalfRasterCamera calf_camera;  // glsl_conventions.h
uniform vec3 light;
uniform float ambient;
out vec3 g_rel;
out vec2 g_disc;
flat out vec3 g_colour;
// surfel_tangents() of surfel_draw_list.h.
void tangents(vec3 n, out vec3 u, out vec3 v) {
  vec3 a = abs(n);
  vec3 e = vec3(0.0, 0.0, 1.0);
  if (a.x <= a.y && a.x <= a.z) {
    e = vec3(1.0, 0.0, 0.0);
  } else if (a.y <= a.z) {
    e = vec3(0.0, 1.0, 0.0);
  }
  u = normalize(cross(n, e));
  v = cross(n, u);
}
vec3 linear(vec3 p) { return model_x * p.x + model_y * p.y + model_z * p.z; }
void main() {
  vec3 u, v;
  tangents(v_normal[0], u, v);
  vec3 c = linear(v_position[0]) + model_t;
  vec3 du = linear(u * radius), dv = linear(v * radius);
  vec3 n = normalize(cross(du, dv));
  if (dot(n, c) > 0.0) n = -n;  // the side the eye sees
  vec3 shaded = tint * v_colour[0] * (ambient + (1.0 - ambient) * max(0.0, dot(n, light)));
  const vec2 corners[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0),
                                  vec2(1.0, 1.0));
  for (int i = 0; i < 4; ++i) {
    vec3 rel = c + du * corners[i].x + dv * corners[i].y;
    g_rel = rel;
    g_disc = corners[i];
    g_colour = shaded;
    gl_Position = calf_raster_position(rel, calf_camera);
    EmitVertex();
  }
  EndPrimitive();
}
)";

constexpr const char* kFragmentShader = R"(
in vec3 g_rel;
in vec2 g_disc;
flat in vec3 g_colour;
layout(location = 0) out vec4 out_colour;
void main() {
  if (dot(g_disc, g_disc) > 1.0) discard;
  out_colour = vec4(g_colour, length(g_rel));
}
)";

template <class T>
GLuint make_array_buffer(const GlFunctions& gl, const std::vector<T>& data) {
  GLuint b = 0;
  gl.GenBuffers(1, &b);
  gl.BindBuffer(GL_ARRAY_BUFFER, b);
  const std::vector<T> one(3);  // an empty prototype still gets a buffer
  const std::vector<T>& d = data.empty() ? one : data;
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(d.size() * sizeof(T)), d.data(),
                GL_STATIC_DRAW);
  return b;
}

}  // namespace

GlSurfelRenderer::GlSurfelRenderer(const GlFunctions& gl) : gl_(&gl) {}

Expected<std::unique_ptr<GlSurfelRenderer>> GlSurfelRenderer::make(const GlFunctions& gl) {
  std::unique_ptr<GlSurfelRenderer> r(new GlSurfelRenderer(gl));
  r->target_ = std::make_unique<internal::GlRasterTarget>(gl, /*with_depth=*/true);
  const Expected<GLuint> program = internal::build_gl_program(
      gl,
      {{GL_VERTEX_SHADER, kVertexShader, "vertex"},
       {GL_GEOMETRY_SHADER, std::string(kGlslConventions) + kGeometryShader, "geometry"},
       {GL_FRAGMENT_SHADER, kFragmentShader, "fragment"}},
      "the surfel program");
  if (!program.ok()) return program.status();
  r->program_ = *program;
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "building the surfel program"));
  return r;
}

GlSurfelRenderer::~GlSurfelRenderer() {
  release_buffers();
  if (program_ != 0) gl_->DeleteProgram(program_);
}

void GlSurfelRenderer::release_buffers() {
  const GlFunctions& gl = *gl_;
  for (PrototypeBuffers& p : prototypes_) {
    for (GLuint b : {p.positions, p.normals, p.colours}) {
      if (b != 0) gl.DeleteBuffers(1, &b);
    }
    if (p.vao != 0) gl.DeleteVertexArrays(1, &p.vao);
  }
  prototypes_.clear();
}

Status GlSurfelRenderer::upload(const SurfelDrawList& list) {
  CALF_RETURN_IF_ERROR(validate_surfel_draw_list(list));
  const GlFunctions& gl = *gl_;
  release_buffers();
  for (const SurfelDrawPrototype& p : list.prototypes) {
    PrototypeBuffers b;
    b.surfel_count = static_cast<uint32_t>(p.surfel_count());
    gl.GenVertexArrays(1, &b.vao);
    gl.BindVertexArray(b.vao);
    const std::vector<float>* arrays[3] = {&p.positions, &p.normals, &p.colours};
    GLuint* buffers[3] = {&b.positions, &b.normals, &b.colours};
    for (GLuint a = 0; a < 3; ++a) {
      *buffers[a] = make_array_buffer(gl, *arrays[a]);
      gl.VertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
      gl.EnableVertexAttribArray(a);
    }
    gl.BindVertexArray(0);
    prototypes_.push_back(b);
  }
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  return check_gl_error(gl, "uploading the surfel buffers");
}

Status GlSurfelRenderer::render(const SurfelDrawList& list, const Camera& camera,
                                const SurfelRenderOptions& options, RenderedImage* out) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_surfel_render_options(options));
  CALF_RETURN_IF_ERROR(validate_surfel_draw_list(list));
  if (list.prototypes.size() != prototypes_.size()) {
    return Status(ErrorId::kSurfelGlStructure,
                  "the draw list has " + std::to_string(list.prototypes.size()) +
                      " surfel prototypes, the upload " + std::to_string(prototypes_.size()) +
                      " (upload the draw list again)");
  }
  for (size_t p = 0; p < prototypes_.size(); ++p) {
    if (list.prototypes[p].surfel_count() != prototypes_[p].surfel_count) {
      return Status(ErrorId::kSurfelGlStructure,
                    "surfel prototype " + std::to_string(p) +
                        " changed its surfel count (upload the draw list again)");
    }
  }
  const GlFunctions& gl = *gl_;
  CALF_RETURN_IF_ERROR(
      target_->bind_and_clear(camera.width, camera.height, "the surfel render target"));
  for (GLenum cap : {GL_BLEND, GL_SCISSOR_TEST, GL_CULL_FACE, GL_STENCIL_TEST}) gl.Disable(cap);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_GREATER);
  gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  gl.UseProgram(program_);
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
  const auto f = [](double x) { return static_cast<float>(x); };
  const auto vec3 = [&](GLint location, const Vec3& v) {
    gl.Uniform3f(location, f(v.x), f(v.y), f(v.z));
  };
  internal::upload_raster_camera(gl, program_, camera, options.near);
  gl.Uniform3f(loc("light"), kMeshKeyLight[0], kMeshKeyLight[1], kMeshKeyLight[2]);
  gl.Uniform1f(loc("ambient"), kMeshAmbient);
  const GLint model_x = loc("model_x"), model_y = loc("model_y"), model_z = loc("model_z"),
              model_t = loc("model_t"), radius = loc("radius"), tint = loc("tint");
  for (const SurfelDrawObject& o : list.objects) {
    if (o.count == 0) continue;
    const internal::ObjectTransform t(o.transform);
    vec3(model_x, {t.r[0][0], t.r[1][0], t.r[2][0]});
    vec3(model_y, {t.r[0][1], t.r[1][1], t.r[2][1]});
    vec3(model_z, {t.r[0][2], t.r[1][2], t.r[2][2]});
    vec3(model_t, t.translation() - camera.position);
    gl.Uniform1f(radius, o.radius);
    gl.Uniform3f(tint, o.tint[0], o.tint[1], o.tint[2]);
    gl.BindVertexArray(prototypes_[o.prototype].vao);
    gl.DrawArrays(GL_POINTS, 0, static_cast<GLsizei>(o.count));
  }
  gl.BindVertexArray(0);
  // Leave the state other renderers (the light field's full-screen pass, the HUD) expect.
  gl.Disable(GL_DEPTH_TEST);
  gl.ClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "drawing the surfels"));
  return target_->read_back("reading back the surfel frame", out);
}

}  // namespace calf::player
