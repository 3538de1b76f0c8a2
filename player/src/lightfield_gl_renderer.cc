#include "calf/player/lightfield_gl_renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "calf/player/glsl_conventions.h"
#include "gl_errors.h"
#include "gl_program.h"
#include "gl_raster_target.h"
#include "gl_raymarch_shader.h"
#include "sampling.h"

namespace calf::player {

using internal::GlViewRecord;
using internal::kGlMissing;

namespace {

Status option_error(const std::string& what) {
  return Status(ErrorId::kPlayerOptions, what);
}

// The CPU renderer's checks (both renderers accept the same options), plus the GL limits.
Status check_options(const LightfieldRenderOptions& o) {
  CALF_RETURN_IF_ERROR(validate_render_options(o));
  if (o.coverage_layers > 0) return option_error("coverage_layers is the CPU reference's only");
  if (o.surface_hint_coverage > 1) {
    return option_error("surface_hint_coverage 2 and 3 are the CPU reference's only");
  }
  return Status::Ok();
}

// The frame's active views: below the view count, at most as many as the shader's view block holds.
Status check_active_views(std::span<const uint32_t> active_views, size_t view_count) {
  CALF_RETURN_IF_ERROR(validate_active_views(active_views, view_count));
  const size_t active = active_views.empty() ? view_count : active_views.size();
  if (active > internal::kGlMaxActiveViews) {
    return option_error(std::to_string(active) + " active views, the GL renderer takes at most " +
                        std::to_string(internal::kGlMaxActiveViews));
  }
  return Status::Ok();
}

// The camera's frame scaled for the ray formula of calf/format/camera.h: the shader's ray is
// normalize(forward + a * right + b * up) with a, b in [-1, 1] at the image edges.
Status camera_axes(const Camera& c, Vec3* forward, Vec3* right, Vec3* up) {
  CALF_RETURN_IF_ERROR(validate_camera(c));
  const CameraFrame frame = camera_frame(c);
  const double h = std::tan(c.fov_y / 2);
  const double aspect = static_cast<double>(c.width) / c.height;
  *forward = frame.forward;
  *right = frame.right * (h * aspect);
  *up = frame.up * h;
  return Status::Ok();
}

}  // namespace

Expected<LightfieldRenderOptions> march_range_for(const GlTextureLayout& layout, const Vec3& eye,
                                                  LightfieldRenderOptions options) {
  std::vector<MarchView> m;
  for (const GlViewInfo& v : layout.views)
    m.push_back({v.position, v.range.z_near(), v.range.z_far()});
  return calf::player::march_range_for(m, eye, std::move(options));
}

LightfieldGlRenderer::LightfieldGlRenderer(const GlViews& views,
                                           const LightfieldRenderOptions& options)
    : views_(&views), gl_(&views.gl()), options_(options) {}

LightfieldGlRenderer::~LightfieldGlRenderer() {
  if (program_ != 0) gl_->DeleteProgram(program_);
  if (vao_ != 0) gl_->DeleteVertexArrays(1, &vao_);
  if (view_buffer_ != 0) gl_->DeleteBuffers(1, &view_buffer_);
}

Expected<std::unique_ptr<LightfieldGlRenderer>> LightfieldGlRenderer::make(
    const GlViews& views, const LightfieldRenderOptions& options) {
  CALF_RETURN_IF_ERROR(check_options(options));
  std::unique_ptr<LightfieldGlRenderer> r(new LightfieldGlRenderer(views, options));
  CALF_RETURN_IF_ERROR(r->build_program());
  return r;
}

Status LightfieldGlRenderer::set_options(const LightfieldRenderOptions& options) {
  CALF_RETURN_IF_ERROR(check_options(options));
  if (options.surface_hints != options_.surface_hints) {
    // The hint count is compiled into the shader (see build_program): a new program.
    const LightfieldRenderOptions old = options_;
    const GLuint old_program = program_;
    options_ = options;
    program_ = 0;
    if (Status s = build_program(); !s.ok()) {
      if (program_ != 0) gl_->DeleteProgram(program_);
      program_ = old_program;
      options_ = old;
      return s;
    }
    gl_->DeleteProgram(old_program);
    return Status::Ok();
  }
  options_ = options;
  return Status::Ok();
}

Status LightfieldGlRenderer::build_program() {
  const GlFunctions& gl = *gl_;
  std::string defines =
      "#define CALF_MAX_VIEWS " + std::to_string(internal::kGlMaxActiveViews) + "\n";
  if (views_->depth_is_bc5()) defines += "#define CALF_DEPTH_BC5\n";
  defines += "#define CALF_HINTS " + std::to_string(options_.surface_hints) + "\n";
  // The coverage test is compiled only where some view has coverage faces: the shader of a view
  // set without coverage is the one it always was.
  if (views_->has_coverage()) defines += "#define CALF_COVERAGE\n";
  const Expected<GLuint> program = internal::build_gl_program(
      gl,
      {{GL_VERTEX_SHADER, internal::kGlFullscreenVertex, "vertex"},
       {GL_FRAGMENT_SHADER, defines + kGlslConventions + internal::kGlRaymarchFragment,
        "ray-march"}},
      "the ray-march program");
  if (!program.ok()) return program.status();
  program_ = *program;
  if (vao_ == 0) gl.GenVertexArrays(1, &vao_);
  if (view_buffer_ == 0) gl.GenBuffers(1, &view_buffer_);
  return check_gl_error(gl, "building the ray-march program");
}

Status LightfieldGlRenderer::draw(const Camera& camera, std::span<const uint32_t> active_views) {
  CALF_RETURN_IF_ERROR(check_active_views(active_views, views_->layout().views.size()));
  Vec3 forward, right, up;
  CALF_RETURN_IF_ERROR(camera_axes(camera, &forward, &right, &up));
  const GlFunctions& gl = *gl_;
  const GlTextureLayout& layout = views_->layout();
  const LightfieldRenderOptions& o = options_;

  // The active views, eye-relative, in the order given.
  std::vector<uint32_t> active(active_views.begin(), active_views.end());
  if (active.empty()) {
    for (uint32_t v = 0; v < layout.views.size(); ++v) active.push_back(v);
  }
  std::vector<GlViewRecord> records;
  for (uint32_t v : active) {
    const GlViewInfo& info = layout.views[v];
    const Vec3 rel = info.position - camera.position;
    const GlslLogRange range = glsl_log_range(info.range);
    records.push_back(
        {{static_cast<float>(rel.x), static_cast<float>(rel.y), static_cast<float>(rel.z)},
         range.log_near,
         range.step,
         range.inv_step,
         range.z_near,
         range.z_far,
         info.face_size,
         info.cell_size,
         6 * v,
         views_->material_base(v),
         views_->coverage_base(v),
         {0, 0, 0}});
  }
  // The whole block is backed, also past the active views (GL leaves a short buffer undefined).
  const size_t active_count = records.size();
  records.resize(internal::kGlMaxActiveViews);
  gl.BindBuffer(GL_UNIFORM_BUFFER, view_buffer_);
  gl.BufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(records.size() * sizeof(GlViewRecord)),
                records.data(), GL_STREAM_DRAW);
  gl.BindBufferBase(GL_UNIFORM_BUFFER, 0, view_buffer_);

  const GlViews::Textures& tex = views_->textures();
  const GLuint units[5] = {tex.colour, tex.depth, tex.cells, tex.material, tex.coverage};
  for (GLenum unit = 0; unit < 5; ++unit) {
    gl.ActiveTexture(GL_TEXTURE0 + unit);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, units[unit]);
  }
  gl.ActiveTexture(GL_TEXTURE0);

  gl.UseProgram(program_);
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
  const auto f = [](double x) { return static_cast<float>(x); };
  gl.Uniform1ui(loc("view_count"), static_cast<GLuint>(active_count));
  gl.Uniform1ui(loc("colour_slots"), views_->colour_slots());
  gl.Uniform1ui(loc("steps"), o.steps);
  gl.Uniform1ui(loc("refine_steps"), o.refine_steps);
  gl.Uniform1f(loc("march_near"), f(o.near));
  gl.Uniform1f(loc("march_log_ratio"), f(std::log(o.far / o.near)));
  gl.Uniform1f(loc("min_view_distance"), f(o.min_view_distance < 0 ? o.near : o.min_view_distance));
  gl.Uniform1f(loc("footprint_limit"), f(o.depth_footprint - 1e-9));
  gl.Uniform1f(loc("smooth_log_ratio"), f(std::log1p(o.smooth_depth_ratio)));
  gl.Uniform1f(loc("depth_decay"), f(o.depth_decay));
  gl.Uniform1f(loc("cam_decay"), f(o.cam_decay));
  gl.Uniform1ui(loc("blend_views"), o.blend_views);
  gl.Uniform1f(loc("colour_depth_tolerance"), f(o.colour_depth_tolerance));
  gl.Uniform1f(loc("colour_sharpen"), f(o.colour_sharpen));
  gl.Uniform1f(loc("colour_sharpen_jump_texels"), f(o.colour_sharpen_jump_texels));
  gl.Uniform1f(loc("mixed_penalty_factor"), f(std::exp(-o.mixed_texel_penalty)));
  gl.Uniform1f(loc("mixed_texel_bend_texels"), f(o.mixed_texel_bend_texels));
  gl.Uniform1ui(loc("coverage_mode"), o.coverage);
  gl.Uniform1f(loc("coverage_threshold"), f(o.coverage_threshold));
  gl.Uniform1f(loc("coverage_cluster"), f(o.coverage_cluster));
  gl.Uniform1ui(loc("coverage_agreement"), o.coverage_agreement);
  gl.Uniform1i(loc("tight_march_start"), o.tight_march_start ? 1 : 0);
  gl.Uniform1i(loc("bilinear_colour"), o.bilinear_colour ? 1 : 0);
  gl.Uniform1i(loc("depth_aware_colour"), o.depth_aware_colour ? 1 : 0);
  gl.Uniform1f(loc("surface_hint_margin_texels"), f(o.surface_hint_margin_texels));
  gl.Uniform1ui(loc("surface_hint_vetoes"), o.surface_hint_vetoes);
  gl.Uniform1ui(loc("surface_hint_substeps"), o.surface_hint_substeps);
  gl.Uniform1ui(loc("surface_hint_coverage"), o.surface_hint_coverage);
  gl.Uniform1i(loc("rr"), o.rr ? 1 : 0);
  gl.Uniform1i(loc("rr_replace_view_reflection"), o.rr_replace_view_reflection ? 1 : 0);
  gl.Uniform1f(loc("rr_start"), f(o.rr_start));
  gl.Uniform1ui(loc("rr_max_depth"), o.rr_max_depth);
  gl.Uniform2ui(loc("image_size"), camera.width, camera.height);
  gl.Uniform1ui(loc("supersample"), o.supersample);
  gl.Uniform3f(loc("cam_forward"), f(forward.x), f(forward.y), f(forward.z));
  gl.Uniform3f(loc("cam_right"), f(right.x), f(right.y), f(right.z));
  gl.Uniform3f(loc("cam_up"), f(up.x), f(up.y), f(up.z));

  for (GLenum cap : {GL_DEPTH_TEST, GL_BLEND, GL_SCISSOR_TEST, GL_CULL_FACE, GL_STENCIL_TEST}) {
    gl.Disable(cap);
  }
  gl.Viewport(0, 0, static_cast<GLsizei>(camera.width), static_cast<GLsizei>(camera.height));
  gl.BindVertexArray(vao_);
  // One pass per eye ray of a pixel, added up by blending: llvmpipe ends every loop of a shader
  // invocation once all of them together have run 65535 iterations (its loop limiter), and one
  // invocation marching 4 x 4 rays at 128 steps with 4 hint views runs past that.
  const uint32_t rays = o.supersample * o.supersample;
  gl.Uniform1ui(loc("ray_count"), 1);
  if (rays > 1) {
    gl.Enable(GL_BLEND);
    gl.BlendEquationSeparate(GL_FUNC_ADD, GL_MIN);
    gl.BlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE);
  }
  const GLint ray_first = loc("ray_first");
  for (uint32_t ray = 0; ray < rays; ++ray) {
    gl.Uniform1ui(ray_first, ray);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
  }
  gl.Disable(GL_BLEND);
  gl.BindVertexArray(0);
  return check_gl_error(gl, "drawing the ray-march pass");
}

Status LightfieldGlRenderer::render(const Camera& camera, std::span<const uint32_t> active_views,
                                    RenderedImage* out) {
  Vec3 forward, right, up;
  CALF_RETURN_IF_ERROR(camera_axes(camera, &forward, &right, &up));
  if (target_ == nullptr) {
    target_ = std::make_unique<internal::GlRasterTarget>(*gl_, /*with_depth=*/false);
  }
  CALF_RETURN_IF_ERROR(
      target_->bind_and_clear(camera.width, camera.height, "the ray-march render target"));
  CALF_RETURN_IF_ERROR(draw(camera, active_views));
  CALF_RETURN_IF_ERROR(target_->read_back("reading back the frame", out));
  // The shader marks a pixel whose loops the driver cut short with distance -1.
  const size_t cut = static_cast<size_t>(
      std::count_if(out->depth.begin(), out->depth.end(), [](float z) { return z < 0; }));
  if (cut > 0) {
    return Status(ErrorId::kPlayerGl,
                  std::to_string(cut) + " of " + std::to_string(out->depth.size()) +
                      " pixels: the GL driver ended the ray-march's loops early (llvmpipe allows "
                      "65535 loop iterations a pixel and ray); fewer steps or hint views, or the "
                      "CPU renderer, render them whole");
  }
  return Status::Ok();
}

}  // namespace calf::player
