// The OpenGL 4.5 rasteriser of a tile set (tiles_renderer.h). Vertices are stored relative to the
// view region's centre and moved to eye-relative coordinates in the vertex shader by a uniform
// computed in double, so floats keep their precision wherever the scene lies.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "calf/player/tiles_renderer.h"
#include "gl_errors.h"
#include "gl_program.h"
#include "gl_raster_target.h"

namespace calf::player {

namespace {

constexpr const char* kVertexShader = R"(
layout(location = 0) in vec3 position;  // relative to the view region's centre
layout(location = 1) in vec3 uvw;       // (u w, v w, w)
uniform vec3 eye_offset;                // the eye minus the view region's centre
uniform CalfRasterCamera calf_camera;  // glsl_conventions.h
out vec3 v_rel;
out vec3 v_uvw;
void main() {
  v_rel = position - eye_offset;
  v_uvw = uvw;
  gl_Position = calf_raster_position(v_rel, calf_camera);
}
)";

constexpr const char* kFragmentShader = R"(
in vec3 v_rel;
in vec3 v_uvw;  // perspective-correct (smooth) interpolation of (U, V, W)
// Premultiplied linear RGBA16F (layer 0 of an array texture), LINEAR, CLAMP_TO_EDGE, one level.
uniform sampler2DArray atlas;
uniform bool alpha_test, count_fragments;
// The occlusion pre-pass (tiles_renderer.h): occlusion_prepass keeps, per pixel, the smallest
// distance of a fragment with alpha >= occlusion_alpha (float bits: non-negative floats order as
// their bit patterns); occlusion_test then drops fragments farther than it times occlusion_behind.
uniform bool occlusion_prepass, occlusion_test;
uniform float occlusion_alpha, occlusion_behind;
uniform uint image_width;
layout(std430, binding = 0) buffer Counts { uint counts[]; };
layout(std430, binding = 1) buffer Occluders { uint occluders[]; };
// Dual-source blending: colour (rgb) and radial depth (a) in index 0, the blend weight src.a in
// index 1, so the depth channel can take a MIN blend while the colour takes the over operator.
layout(location = 0, index = 0) out vec4 out_colour;
layout(location = 0, index = 1) out vec4 out_weight;
void main() {
  uint pixel = uint(gl_FragCoord.y) * image_width + uint(gl_FragCoord.x);
  vec4 t = texture(atlas, vec3(v_uvw.xy / v_uvw.z, 0.0));
  float d = length(v_rel);
  if (occlusion_prepass) {
    if (t.a >= occlusion_alpha) atomicMin(occluders[pixel], floatBitsToUint(d));
    discard;
  }
  if (count_fragments) atomicAdd(counts[pixel], 1u);
  if (occlusion_test && d > uintBitsToFloat(occluders[pixel]) * occlusion_behind) discard;
  if (alpha_test) {
    if (t.a < 0.5) discard;
    out_colour = vec4(t.rgb / t.a, d);
    out_weight = vec4(1.0);
  } else {
    out_colour = vec4(t.rgb, t.a >= 0.5 ? d : uintBitsToFloat(0x7f800000u));
    out_weight = vec4(t.a);
  }
}
)";

Status set_error(const std::string& what) {
  return Status(ErrorId::kTilesDraw, what);
}

// Sets the storage buffer `*buffer` (created, or re-sized from `*size` entries, as needed) to
// `pixels` copies of `value` and binds it at `binding`: the per-pixel counters and occluders.
// The GL fills it (glClearBufferData), so no frame builds or uploads a copy.
void fill_pixel_buffer(const GlFunctions& gl, size_t pixels, uint32_t value, GLuint binding,
                       GLuint* buffer, size_t* size) {
  if (*buffer == 0) gl.GenBuffers(1, buffer);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, *buffer);
  if (*size != pixels) {
    gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(pixels * sizeof(uint32_t)),
                  nullptr, GL_DYNAMIC_READ);
    *size = pixels;
  }
  gl.ClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &value);
  gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, *buffer);
}

}  // namespace

GlTilesRenderer::GlTilesRenderer(const GlFunctions& gl)
    : gl_(&gl), target_(std::make_unique<internal::GlRasterTarget>(gl, true)) {}

GlTilesRenderer::~GlTilesRenderer() {
  release();
  if (program_ != 0) gl_->DeleteProgram(program_);
}

void GlTilesRenderer::release() {
  const GlFunctions& gl = *gl_;
  for (GLuint* b : {&vertices_, &indices_, &counts_, &occluders_}) {
    if (*b != 0) gl.DeleteBuffers(1, b);
    *b = 0;
  }
  if (vao_ != 0) gl.DeleteVertexArrays(1, &vao_);
  if (atlas_ != 0) gl.DeleteTextures(1, &atlas_);
  vao_ = atlas_ = 0;
  tile_count_ = counts_size_ = occluders_size_ = 0;
}

Expected<std::unique_ptr<GlTilesRenderer>> GlTilesRenderer::make(const GlFunctions& gl) {
  std::unique_ptr<GlTilesRenderer> r(new GlTilesRenderer(gl));
  Expected<GLuint> program = internal::build_gl_program(
      gl,
      {{GL_VERTEX_SHADER, std::string(kGlslConventions) + kVertexShader, "vertex"},
       {GL_FRAGMENT_SHADER, kFragmentShader, "fragment"}},
      "the tiles program");
  if (!program.ok()) return program.status();
  r->program_ = *program;
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "building the tiles program"));
  return r;
}

Status GlTilesRenderer::upload(const TileSet& set, const TilesLinearAtlas& atlas) {
  CALF_RETURN_IF_ERROR(validate_tile_set(set));
  const GlFunctions& gl = *gl_;
  if (atlas.width != set.atlas_width || atlas.height != set.atlas_height ||
      atlas.rgba_half.size() != size_t{4} * atlas.width * atlas.height) {
    return set_error("the linear atlas is not the tile set's");
  }
  if (std::max(atlas.width, atlas.height) > static_cast<uint32_t>(gl.max_texture_size)) {
    return set_error("the tile atlas of " + std::to_string(atlas.width) + " x " +
                     std::to_string(atlas.height) + " exceeds GL_MAX_TEXTURE_SIZE " +
                     std::to_string(gl.max_texture_size));
  }
  release();
  origin_ = (set.view_volume.min + set.view_volume.max) / 2;
  std::vector<float> vertices;
  vertices.reserve(24 * set.tiles.size());
  for (const Tile& t : set.tiles) {
    for (const TileCorner& c : t.corners) {
      vertices.push_back(static_cast<float>(c.position[0] - origin_.x));
      vertices.push_back(static_cast<float>(c.position[1] - origin_.y));
      vertices.push_back(static_cast<float>(c.position[2] - origin_.z));
      for (float v : c.uvw) vertices.push_back(v);
    }
  }
  if (vertices.empty()) vertices.resize(6);       // a zero-sized store cannot be bound
  constexpr GLsizei kStride = 6 * sizeof(float);  // position, uvw
  gl.GenVertexArrays(1, &vao_);
  gl.BindVertexArray(vao_);
  gl.GenBuffers(1, &vertices_);
  gl.BindBuffer(GL_ARRAY_BUFFER, vertices_);
  gl.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
                vertices.data(), GL_STATIC_DRAW);
  gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kStride, nullptr);
  gl.EnableVertexAttribArray(0);
  gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kStride,
                         reinterpret_cast<const void*>(3 * sizeof(float)));
  gl.EnableVertexAttribArray(1);
  gl.GenBuffers(1, &indices_);
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, indices_);  // recorded in the vertex array
  gl.BindVertexArray(0);
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  tile_count_ = set.tiles.size();
  if (atlas.width > 0 && atlas.height > 0) {
    // An array texture of one layer (the loader's upload entry point is TexSubImage3D, as for
    // the mesh textures), holding exactly the halves the CPU reference filters.
    gl.GenTextures(1, &atlas_);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, atlas_);
    const auto w = static_cast<GLsizei>(atlas.width), h = static_cast<GLsizei>(atlas.height);
    gl.TexStorage3D(GL_TEXTURE_2D_ARRAY, 1, GL_RGBA16F, w, h, 1);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, w, h, 1, GL_RGBA, GL_HALF_FLOAT,
                     atlas.rgba_half.data());
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);
  }
  return check_gl_error(gl, "uploading the tiles");
}

Status GlTilesRenderer::render(const TileSet& set, const Camera& camera,
                               const TilesRenderOptions& options, RenderedImage* out,
                               TilesFrameStats* stats) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_tiles_render_options(options));
  if (set.tiles.size() != tile_count_ || vao_ == 0) {
    return set_error("the tile set has " + std::to_string(set.tiles.size()) +
                     " tiles, the upload " + std::to_string(tile_count_) +
                     " (upload the set again)");
  }
  const GlFunctions& gl = *gl_;
  const bool sorted = options.blend == TilesBlend::kSorted;
  const bool count = options.measure_overdraw;
  const size_t pixels = size_t{camera.width} * camera.height;
  CALF_RETURN_IF_ERROR(
      target_->bind_and_clear(camera.width, camera.height, "the tiles render target"));
  // One counter per pixel, zeroed for this render.
  if (count) fill_pixel_buffer(gl, pixels, 0, 0, &counts_, &counts_size_);
  // One occluder distance per pixel, +inf (as float bits) for this render.
  const bool occlusion = sorted && options.occlusion_alpha > 0;
  if (occlusion) fill_pixel_buffer(gl, pixels, 0x7f800000u, 1, &occluders_, &occluders_size_);
  for (GLenum cap : {GL_SCISSOR_TEST, GL_CULL_FACE, GL_STENCIL_TEST}) gl.Disable(cap);
  if (sorted) {
    gl.Disable(GL_DEPTH_TEST);
    gl.Enable(GL_BLEND);
    // Colour: src + (1 - src.a) dst with src.a from the second output; depth channel: the minimum.
    gl.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC1_ALPHA, GL_ONE, GL_ONE);
    gl.BlendEquationSeparate(GL_FUNC_ADD, GL_MIN);
  } else {
    gl.Disable(GL_BLEND);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_GREATER);  // reversed Z: nearer is greater; ties keep the first drawn
  }
  gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  gl.UseProgram(program_);
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
  const auto f = [](double x) { return static_cast<float>(x); };
  const auto vec3 = [&](const char* name, const Vec3& v) {
    gl.Uniform3f(loc(name), f(v.x), f(v.y), f(v.z));
  };
  vec3("eye_offset", camera.position - origin_);
  internal::upload_raster_camera(gl, program_, camera, options.near);
  gl.Uniform1i(loc("alpha_test"), sorted ? 0 : 1);
  gl.Uniform1i(loc("count_fragments"), count ? 1 : 0);
  gl.Uniform1f(loc("occlusion_alpha"), f(options.occlusion_alpha));
  gl.Uniform1f(loc("occlusion_behind"), f(1 + options.occlusion_epsilon));
  gl.Uniform1i(loc("occlusion_test"), 0);
  gl.Uniform1ui(loc("image_width"), camera.width);
  gl.Uniform1i(loc("atlas"), 0);
  gl.ActiveTexture(GL_TEXTURE0);
  gl.BindTexture(GL_TEXTURE_2D_ARRAY, atlas_);

  if (tile_count_ > 0 && atlas_ != 0) {
    if (sorted) {
      tiles_back_to_front(set, camera.position, &order_);
    } else {
      order_.resize(tile_count_);
      for (size_t t = 0; t < tile_count_; ++t) order_[t] = static_cast<uint32_t>(t);
    }
    // Two triangles per tile in drawing order; GL blends primitives in the order they are given.
    index_data_.resize(6 * tile_count_);
    for (size_t k = 0; k < tile_count_; ++k) {
      const uint32_t v = 4 * order_[k];
      const uint32_t tri[6] = {v, v + 1, v + 2, v, v + 2, v + 3};
      std::copy(tri, tri + 6, &index_data_[6 * k]);
    }
    gl.BindVertexArray(vao_);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER,
                  static_cast<GLsizeiptr>(index_data_.size() * sizeof(uint32_t)),
                  index_data_.data(), GL_STREAM_DRAW);
    const auto draw = [&] {
      gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(index_data_.size()), GL_UNSIGNED_INT,
                      nullptr);
    };
    if (occlusion) {
      // Every pre-pass fragment is discarded after its atomicMin: nothing reaches the target.
      gl.Uniform1i(loc("occlusion_prepass"), 1);
      draw();
      gl.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
      gl.Uniform1i(loc("occlusion_test"), 1);
    }
    gl.Uniform1i(loc("occlusion_prepass"), 0);
    draw();
    gl.BindVertexArray(0);
  }

  // Leave the state other renderers (the light field's full-screen pass, the HUD) expect.
  gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);
  gl.Disable(GL_BLEND);
  gl.BlendEquationSeparate(GL_FUNC_ADD, GL_FUNC_ADD);
  gl.BlendFuncSeparate(GL_ONE, GL_ZERO, GL_ONE, GL_ZERO);
  gl.Disable(GL_DEPTH_TEST);
  gl.ClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "drawing the tiles"));

  if (stats != nullptr) *stats = TilesFrameStats{};
  if (count) {
    std::vector<uint32_t> counts(pixels);
    gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, counts_);
    gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                        static_cast<GLsizeiptr>(pixels * sizeof(uint32_t)), counts.data());
    gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, 0);
    CALF_RETURN_IF_ERROR(check_gl_error(gl, "reading the tiles' fragment counts"));
    if (stats != nullptr) {
      stats->measured = true;
      for (uint32_t n : counts) {
        stats->fragments += n;
        stats->covered_pixels += n > 0 ? 1 : 0;
        stats->peak = std::max(stats->peak, n);
      }
    }
  }
  return target_->read_back("reading back the tiles frame", out);
}

}  // namespace calf::player
