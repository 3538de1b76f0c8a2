// The viewpoint textures on the GPU: the GL image of the decoder's texture state
// (calf/decoder/lightfield_decoder.h) that the GL ray-march renderer
// (calf/player/lightfield_gl_renderer.h) reads.
//
// Per view, in 2D array textures whose layers are (view, face[, slot]) — the shader fetches texels
// with texelFetch and does its own filtering and cross-face taps through the cube conventions
// (calf/player/glsl_conventions.h), exactly as the CPU reference does, never hardware cube
// filtering:
//
//   colour    layer (6 v + f) * S + slot, S = 2 keyframe slots (1 for a layout without keyframe
//             interpolation); format by the clip's colour format, decoded to linear by the GPU:
//               kBc1 -> COMPRESSED_SRGB_S3TC_DXT1     kBc7 -> COMPRESSED_SRGB_ALPHA_BPTC_UNORM
//               kBc6h -> COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT
//               kRgba8 -> SRGB8_ALPHA8                kRgba16f -> RGBA16F
//   cells     layer 6 v + f, one R16UI texel per colour cell: t | a_slot << 8 (CellParams); the
//             shader shows mix(slot a, slot 1 - a, t / 255) per texel
//   depth     layer 6 v + f, log-16 codes (65535 = sky): R16UI (kR16 storage; kR16 updates as they
//             are, kBc5 updates decoded on the CPU by calf/format/bc.h, code = 256 R + G), or
//             COMPRESSED_RG_RGTC2 (kBc5 storage: the GPU decodes, the shader forms 256 R + G)
//   material  layer 6 m + f for the m-th view with material: RGBA8 codes (reflect, refract, ior
//             code; kBc1 updates decoded on the CPU) or COMPRESSED_RGB_S3TC_DXT1 (kBc1 storage);
//             reflect = R, refract = G, ior = 1 + 2 B (format/SPEC.md §11.1.6)
//   coverage  layer 6 c + f for the c-th view with coverage (format/CAPTURE.md "Coverage", SPEC
//             §11.1.11): RGBA8UI, the decoder's kCoverage bytes as they are (mask low byte, mask
//             high byte, near count, far count of the texel's 16 cells); a 1-texel placeholder
//             when no view has coverage
//
// Initial state matches a fresh calf::player::View: colour black, depth sky, t = 0 / slot 0,
// material (0, 0, 1), coverage plain (every cell the texel's own surface).
//
// Why BC5 depth defaults to R16 storage: the BC5 interpolants are rounded differently by
// different decoders (llvmpipe's differs from the reference by up to 2 LSB, docs/BLOCK_CODECS.md),
// and an LSB of the high byte is 256 codes, a ~3 % depth step at typical ranges. Decoding on the
// CPU makes the GPU hold exactly the codes the encoder measured; kBc5 storage halves depth memory
// and upload bytes at that risk (docs/RENDERING.md, "GL renderer", has the measured difference).
//
// All calls need the GL context the object was made in to be current.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "calf/decoder/lightfield_decoder.h"
#include "calf/format/container.h"
#include "calf/format/geometry.h"
#include "calf/format/log_depth.h"
#include "calf/format/status.h"
#include "calf/player/gl_context.h"
#include "calf/player/view_set.h"

namespace calf::player {

// One view as the GPU holds it.
struct GlViewInfo {
  Vec3 position;                                     // P_j, scene units
  LogDepthRange range = *LogDepthRange::make(1, 2);  // its log-16 depth range
  uint32_t face_size = 1;                            // texels per face side
  uint32_t cell_size = 1;                            // colour cell side (texels) of the t table
  bool has_material = false;                         // material faces exist for the view
  bool has_coverage = false;                         // coverage faces exist for the view
};

struct GlTextureLayout {
  std::vector<GlViewInfo> views;
  // Storage formats (container::PixelFormat); see the table above for what each accepts.
  container::PixelFormat colour_format = container::PixelFormat::kRgba16f;
  container::PixelFormat depth_format = container::PixelFormat::kR16;
  container::PixelFormat material_format = container::PixelFormat::kRgba8;
  // Two keyframe slots per colour face (a clip) or one (a ViewSet: t is always 0).
  bool colour_two_slots = true;
};

// The layout for a clip's lightfield track: every view with the track's face and cell size, its
// position, range and material flag from `views` (LightfieldDecoder::view(v) for v < view_count),
// the track's formats; depth kept as R16 unless `keep_bc5_depth`. Errors: CALF-E410 for a view
// count other than the header's or a depth format other than r16 / BC5 (the other formats are
// checked by GlViews::make), CALF-E020 for a view's invalid z_near / z_far. `coverage`: every view
// gets coverage faces (a track with a coverage stream decoded with
// LightfieldDecoderOptions::coverage).
Expected<GlTextureLayout> layout_for_clip(const container::LightfieldTrackHeader& header,
                                          std::span<const decoder::LightfieldViewInfo> views,
                                          bool keep_bc5_depth = false, bool coverage = false);

// A ViewSet as updates: the layout (rgba16f colour, one slot; r16 depth; rgba8 material codes:
// reflect and refract round(255 x), ior round(255 clamp((ior - 1) / 2, 0, 1)); coverage for the
// views that have it: shares as counts round(16 x) of the 16 cells, the decoder's kCoverage
// bytes) and one update per face and stream plus one CellParams (t = 0) per face, so that the GL
// renderer draws exactly the views the CPU renderer draws (colour rounded to half floats,
// material to its 8-bit codes; coverage is exact for shares in sixteenths, which every producer
// writes, format/CAPTURE.md).
// Not copyable: the updates point into `bytes`.
struct ViewSetUpload {
  GlTextureLayout layout;
  decoder::LightfieldFrameUpdates frame;
  std::vector<std::vector<uint8_t>> bytes;

  ViewSetUpload() = default;
  ViewSetUpload(ViewSetUpload&&) = default;
  ViewSetUpload& operator=(ViewSetUpload&&) = default;
  ViewSetUpload(const ViewSetUpload&) = delete;
  ViewSetUpload& operator=(const ViewSetUpload&) = delete;
};
// Errors: CALF-E410 for an empty view set.
Expected<ViewSetUpload> updates_from_view_set(const ViewSet& views);

class GlViews {
 public:
  // Allocates and initialises the textures. Errors: CALF-E410 (no views, a face or cell size
  // outside 1..16384, views of different face sizes with a compressed format, an unsupported
  // storage format), CALF-E404 (BC1 without the S3TC / sRGB extensions, more layers or a larger
  // face than the context allows), CALF-E412 (GL refused an allocation).
  static Expected<std::unique_ptr<GlViews>> make(const GlFunctions& gl, GlTextureLayout layout);
  ~GlViews();
  GlViews(const GlViews&) = delete;
  GlViews& operator=(const GlViews&) = delete;

  // Applies a frame's updates in order, then its cells' (t, a_slot). Stops at the first bad
  // update (those before it stay applied). Errors: as apply_update / set_cells.
  Status apply(const decoder::LightfieldFrameUpdates& frame);
  // One update. Errors (CALF-E411, nothing is written): view, face or slot out of range, material
  // or coverage for a view without it, an empty rect or one leaving the face, a format the storage
  // does not take, block rects not 4-aligned (width / height may be short only at the face's edge),
  // a byte count other than the rect needs; CALF-E412 when GL reports an error.
  Status apply_update(const decoder::TextureUpdate& update);
  // Sets (t, a_slot) of the given cells. Errors (CALF-E411): a view, face or cell index out of
  // range, a_slot > 1 (or a_slot 1 / t > 0 with one slot).
  Status set_cells(std::span<const decoder::CellParams> cells);

  const GlTextureLayout& layout() const { return layout_; }
  const GlFunctions& gl() const { return gl_; }

  // For the renderer: GL texture names and the layer bases.
  struct Textures {
    GLuint colour = 0, depth = 0, cells = 0, material = 0, coverage = 0;
  };
  const Textures& textures() const { return tex_; }
  // The first material layer of view v (6 m for the m-th view with material), -1 without.
  int material_base(uint32_t v) const { return material_base_[v]; }
  // The first coverage layer of view v (6 c for the c-th view with coverage), -1 without.
  int coverage_base(uint32_t v) const { return coverage_base_[v]; }
  // Whether any view has coverage faces.
  bool has_coverage() const { return coverage_layers_ > 0; }
  uint32_t cells_per_side(uint32_t v) const;
  // Colour slots per face (2 or 1).
  uint32_t colour_slots() const { return layout_.colour_two_slots ? 2 : 1; }
  // Whether the depth texture holds BC5 (the shader then forms the code from R and G).
  bool depth_is_bc5() const { return layout_.depth_format == container::PixelFormat::kBc5; }

 private:
  GlViews(const GlFunctions& gl, GlTextureLayout layout);
  Status allocate();
  Status upload(GLuint texture, GLenum storage, bool compressed, GLenum format, GLenum type,
                const PixelRect& rect, int layer, const void* data, size_t size);
  Status upload_cells();

  GlFunctions gl_;
  GlTextureLayout layout_;
  Textures tex_;
  uint32_t size_ = 1;       // texture width = height: the largest face
  uint32_t cell_side_ = 1;  // cells texture width = height
  std::vector<int> material_base_;
  std::vector<int> coverage_base_;
  int coverage_layers_ = 0;
  std::vector<uint32_t> cells_per_side_;
  std::vector<uint16_t> cells_;       // CPU copy of the cells texture, layer-major
  std::vector<uint8_t> cells_dirty_;  // per layer
};

}  // namespace calf::player
