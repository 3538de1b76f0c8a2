// The two rasterisers of a tile set (paper 000, Seurat, Sec. 6; calf/format/tile_set.h): the
// OpenGL 4.5 one (GlTilesRenderer, the product) and the scalar CPU one (render_tiles_cpu, the
// reference it is tested against, tests/player/tiles_renderer_test.cc: colour PSNR >= 45 dB
// between the two). Both draw with exactly these rules and produce what every representation
// produces (rendered_image.h): linear colour and radial depth, +inf depth where nothing is drawn.
//
// Geometry. Each tile is the two triangles (0, 1, 2) and (0, 2, 3) of its corners, drawn from both
// sides (no back-face culling). Coverage is the mesh rasterisers' (mesh_draw_list.h): a pixel
// centre (i + 0.5, j + 0.5) is covered when the projected triangle covers it by the top-left rule,
// only the part of a triangle farther than `near` along the camera's forward axis is drawn, there
// is no far plane. A covered pixel's ray meets the triangle's plane at radial distance t; the
// homogeneous texture coordinate (U, V, W) is interpolated there (perspective-correct: barycentric
// coordinates of the hit point in scene space; GL's smooth varyings) and divided per pixel:
// (u, v) = (U / W, V / W).
//
// Colour space (the choice this file documents). The atlas holds sRGB-encoded RGB premultiplied
// by alpha after encoding (tile_set.h). Blending and filtering happen on premultiplied LINEAR
// colour, converted once per texel when the set is loaded (tiles_linear_atlas):
//   a = A / 255;  rgb = a * linear_from_srgb(min(1, C / A))  (0 where A = 0),
// each value then rounded to a half float (the GL texture is RGBA16F holding exactly these
// halves, so both backends filter the same numbers). Decoding per texel before filtering and
// blending is what makes a 50 % edge texel half as bright as its opaque neighbour; letting the
// GPU's sRGB sampler decode the premultiplied bytes instead would darken every partial texel
// (decode(a e) is about a^2.2 decode(e)). Cost: 8 bytes of GPU memory per texel (128 MiB for a
// 4096² atlas), twice RGBA8.
//
// Texture filtering: bilinear (GL_LINEAR, one level, no mipmaps: Seurat sizes each tile's texels
// to its projected size from the view region) with CLAMP_TO_EDGE on the whole atlas; texel (i, j)'s
// centre is ((i + 0.5) / w, (j + 0.5) / h), v = 0 at the atlas's top row. The builder pads each
// tile's rectangle by one texel, so the filter never reaches a neighbour's texels.
//
// Blend modes (TilesBlend):
//   kSorted (default, Seurat's): tiles drawn back to front — by decreasing distance from the eye
//     to the tile's centre (the mean of its four corners, in double), ties in increasing tile
//     index (tiles_back_to_front) — sorted for each eye at each render, and composited with the
//     premultiplied over operator out = src + (1 - src.a) dst in float (the GL target is RGBA32F),
//     over a background of 0. No depth test, but an occlusion pre-pass (occlusion_alpha > 0, the
//     default): every tile is rasterised once first, and each pixel keeps the radial distance
//     D of its nearest fragment whose filtered alpha is >= occlusion_alpha; the sorted pass then
//     drops every fragment farther than D * (1 + occlusion_epsilon). A fragment behind a nearly
//     opaque one adds at most (1 - occlusion_alpha) of its colour in a correct order, so this
//     changes little where the sort is right, and removes what the sort gets wrong: one distance
//     per tile cannot order tiles that cross or abut at an angle (a column's side face, whose
//     centre is nearer the eye than its front face, drawn over the front face from behind it).
//     Measured on interior (docs/TILES.md "Occlusion pass"). GL keeps D as float bits in a
//     storage buffer (atomicMin: non-negative floats order as their bit patterns) and tests it in
//     the second pass; the CPU keeps an array.
//   kAlphaTest: any order, a depth test (nearest wins, ties keep the first drawn tile, lower index;
//     reversed Z on GL as the mesh renderer) and an alpha test: a fragment whose filtered alpha is
//     below 0.5 is dropped, one that passes writes its colour unpremultiplied (rgb / a) as opaque.
//     The single-sample form of alpha to coverage: no order needed, hard silhouettes (what the
//     paper's Sec. 6 suggests when a real depth buffer is needed).
//
// Depth output: the radial distance from the eye centre to the nearest tile whose filtered alpha
// at the pixel is >= 0.5 (in kSorted, GL keeps the minimum in the target's alpha channel with
// a MIN blend and dual-source blending for the colour); +inf where no tile reaches 0.5, even
// where fainter tiles left some colour. So Playback's depth compositing treats a pixel as this
// representation's only where it is at least half covered.
//
// Background: colour 0 and depth +inf where no tile is drawn, as the mesh and surfel renderers
// (the sky is whatever tiles the builder made of it).
//
// Overdraw (TilesFrameStats): every rasterised fragment counts (whatever its alpha, and in
// kAlphaTest also those the tests drop); mean = fragments / pixels with at least one, peak = the
// largest count of a pixel. GL counts with an atomic counter per pixel in a storage buffer
// (TilesRenderOptions::measure_overdraw; off saves one buffer clear and read-back per render).
#pragma once

#include <GL/glcorearb.h>

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"
#include "calf/player/gl_context.h"
#include "calf/player/rendered_image.h"

namespace calf::player {

namespace internal {
class GlRasterTarget;
}

enum class TilesBlend : uint8_t {
  kSorted,     // back to front, premultiplied over (default)
  kAlphaTest,  // depth test + alpha test at 0.5, any order
};

// "sort" / "alpha-test" (the calf-play spelling).
std::string_view tiles_blend_name(TilesBlend blend);
// The blend named `name`; CALF-E478 for another name.
Expected<TilesBlend> tiles_blend_from_name(std::string_view name);

struct TilesRenderOptions {
  // The near clipping distance along the camera's forward axis, in scene units: > 0 and finite.
  double near = 0.01;
  TilesBlend blend = TilesBlend::kSorted;
  // kSorted's occlusion pre-pass (above): the filtered alpha at which a fragment hides what lies
  // behind it, in [0.5, 1], or 0 for none (Seurat's plain sort). Measured on interior, 9 views,
  // capture viewpoints / novel views, dB: 256² 37.65 / 40.39 without, 39.23 / 41.76 at 0.9;
  // 512² 35.63 / 40.18 without, 38.17 / 42.40 at 0.9 (docs/TILES.md "Occlusion pass").
  double occlusion_alpha = 0.9;
  // How much farther than the occluder (relative) a fragment must be to be dropped, so that tiles
  // of one surface (overlapping by the builder's dilation) never hide each other. (0, 1].
  double occlusion_epsilon = 1e-3;
  // Count fragments per pixel (TilesFrameStats); the CPU always counts.
  bool measure_overdraw = true;
};

// What one render drew.
struct TilesFrameStats {
  uint64_t fragments = 0;       // rasterised fragments (see above); 0 when not measured
  uint64_t covered_pixels = 0;  // pixels with at least one fragment
  uint32_t peak = 0;            // the largest fragment count of one pixel
  bool measured = false;
  // fragments / covered_pixels, 0 with none.
  double mean_overdraw() const {
    return covered_pixels > 0 ? static_cast<double>(fragments) / covered_pixels : 0.0;
  }
};

// The atlas as both renderers filter it: premultiplied linear RGBA as half-float bit patterns
// (see "Colour space" above), row 0 at the top.
struct TilesLinearAtlas {
  uint32_t width = 0, height = 0;
  std::vector<uint16_t> rgba_half;  // 4 per texel
};

// CALF-E477 unless `set` is drawable, naming the first fault: an atlas of other than width x
// height x 4 bytes, tiles with an empty atlas, a non-finite view region, corner position or uvw,
// or a w not > 0 (or not finite U / W, V / W). An empty set (no tiles, any valid atlas) is
// drawable.
[[nodiscard]] Status validate_tile_set(const TileSet& set);
// CALF-E478 unless `options` are valid (near > 0 and finite, a listed blend mode, occlusion_alpha
// 0 or in [0.5, 1], occlusion_epsilon in (0, 1]).
[[nodiscard]] Status validate_tiles_render_options(const TilesRenderOptions& options);

// The premultiplied linear atlas of `set` (which must be valid).
TilesLinearAtlas tiles_linear_atlas(const TileSet& set);

// The tiles of `set` in kSorted's drawing order for an eye at `eye` (see above).
void tiles_back_to_front(const TileSet& set, const Vec3& eye, std::vector<uint32_t>* order);

// Renders `set` (with `atlas` = tiles_linear_atlas(set)) for `camera` into `out` (resized to the
// camera's image); `stats` (may be null) gets the overdraw. Errors: CALF-E477 (set, or an atlas of
// another size), CALF-E478 (options), CALF-E403 (camera). Deterministic.
Status render_tiles_cpu(const TileSet& set, const TilesLinearAtlas& atlas, const Camera& camera,
                        const TilesRenderOptions& options, RenderedImage* out,
                        TilesFrameStats* stats);

// The GL rasteriser. All calls need the GL context of `gl` current on the calling thread.
class GlTilesRenderer {
 public:
  // Compiles the shaders. Errors: CALF-E404 when a shader does not compile or link.
  static Expected<std::unique_ptr<GlTilesRenderer>> make(const GlFunctions& gl);
  ~GlTilesRenderer();
  GlTilesRenderer(const GlTilesRenderer&) = delete;
  GlTilesRenderer& operator=(const GlTilesRenderer&) = delete;

  // Uploads the tiles' corners (relative to the view region's centre, so floats keep their
  // precision far from the origin) and `atlas` (tiles_linear_atlas(set)) as an RGBA16F texture,
  // replacing an earlier upload. Errors: CALF-E477 (invalid set; an atlas wider or taller than
  // the context's GL_MAX_TEXTURE_SIZE), CALF-E412.
  Status upload(const TileSet& set, const TilesLinearAtlas& atlas);

  // Draws the uploaded set (`set` is the one uploaded: the sort reads its corners) for `camera`
  // into `out`; `stats` (may be null) gets the overdraw when options.measure_overdraw. Errors:
  // CALF-E403 (camera), CALF-E478 (options), CALF-E477 (a set of another tile count than the
  // upload), CALF-E412 (GL).
  Status render(const TileSet& set, const Camera& camera, const TilesRenderOptions& options,
                RenderedImage* out, TilesFrameStats* stats);

 private:
  explicit GlTilesRenderer(const GlFunctions& gl);
  void release();

  const GlFunctions* gl_;
  GLuint program_ = 0, vao_ = 0, vertices_ = 0, indices_ = 0, atlas_ = 0, counts_ = 0,
         occluders_ = 0;
  size_t tile_count_ = 0, counts_size_ = 0, occluders_size_ = 0;
  Vec3 origin_;  // the view region's centre the vertices are relative to
  std::vector<uint32_t> order_, index_data_;
  std::unique_ptr<internal::GlRasterTarget> target_;
};

}  // namespace calf::player
