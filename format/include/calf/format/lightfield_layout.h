// The lightfield track (kind 1, format/SPEC.md §11.1): its track header and stream tags, and the
// byte layout of its chunks, both directions. The fixed parts of every chunk (view index, t chunk
// head, region chunk head) are records declared once with the fields visitor
// (container_fields.h); the encoder writes them with write_fields / the write_* functions, every
// decoder reads them through the parse_* functions and turns payloads into GPU-ready bytes
// through the *_gpu_bytes functions. This is the one place that knows the block split, the byte
// planes and the chunk headers.
//
// Parsers check every count, rectangle and size against the chunk before use; a contradiction is
// CALF-E202 (kLightfieldChunk), a format outside §11.1 CALF-E203 (kLightfieldFormat). Messages
// start with the caller's `what` (e.g. "view 3 face 1 region 7 depth").
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::container {

// Stream tags (SPEC.md §11.1).
#define CALF_LIGHTFIELD_STREAMS(X) \
  X(kIndex, 0, "index")            \
  X(kColour, 1, "colour")          \
  X(kDepth, 2, "depth") X(kMaterial, 3, "material") X(kTParams, 4, "t") X(kCoverage, 5, "coverage")
enum class LightfieldStream : uint16_t { CALF_LIGHTFIELD_STREAMS(CALF_STREAM_ENUM) };

// Track header (36 bytes, SPEC.md §11.1); later fields are appended.
struct LightfieldTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kLightfield;
  static constexpr const char* kStreamNames[] = {CALF_LIGHTFIELD_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  uint32_t view_count = 1;
  uint32_t face_size = 1;          // cube face side, pixels
  uint32_t cell_size = 1;          // colour cell side, pixels
  uint32_t depth_region_size = 1;  // depth region side, pixels
  uint16_t colour_format = 0;      // PixelFormat
  uint16_t depth_format = 0;       // PixelFormat
  uint16_t material_format = 0;    // PixelFormat, kNone without a material stream
  uint16_t flags = 0;              // bit 0: colour is HDR
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
    v(s.view_count, "view_count", Range{1, kMaxViews});
    v(s.face_size, "face_size", Range{1, kMaxDimension});
    v(s.cell_size, "cell_size", Range{1, kMaxDimension});
    v(s.depth_region_size, "depth_region_size", Range{1, kMaxDimension});
    v(s.colour_format, "colour_format");
    v(s.depth_format, "depth_format");
    v(s.material_format, "material_format");
    v(s.flags, "flags");
  }
};
static_assert(fixed_size<LightfieldTrackHeader>() == 36);
static_assert(std::size(LightfieldTrackHeader::kStreamNames) ==
              static_cast<size_t>(LightfieldStream::kCoverage) + 1);

}  // namespace calf::container

namespace calf::lf {

// ---- Writing ----

// Appends `blocks` (whole BCn blocks) split into their endpoint part and their index part
// (§11.1 "Block split"): BC1 (8-byte blocks) = bytes 0-3 of every block, then bytes 4-7 of every
// block; BC5 (16-byte blocks, two BC4 halves) = bytes 0,1,8,9 of every block, then bytes 2-7,
// 10-15 of every block. Other formats are appended unchanged.
void append_block_split(std::vector<uint8_t>& out, std::span<const uint8_t> blocks,
                        size_t block_bytes, bool is_bc5);

// Appends `texels` of `bytes_per_texel` interleaved bytes as planes: byte 0 of every texel, then
// byte 1 of every texel, ... (§11.1 "Byte planes").
void append_planes(std::vector<uint8_t>& out, std::span<const uint8_t> texels,
                   size_t bytes_per_texel);

// Material codes (§11.1.6): reflect / refract weights round(255 x) of x clamped to [0, 1]; the
// index of refraction round(255 clamp((ior - 1) / 2, 0, 1)), so codes span ior 1 ... 3.
uint8_t material_weight_code(float weight);
uint8_t material_ior_code(float ior);
inline float material_weight_from_code(uint8_t code) {
  return code / 255.0f;
}
inline float material_ior_from_code(uint8_t code) {
  return 1.0f + 2.0f * (code / 255.0f);
}

// ---- Reading ----

inline constexpr uint32_t kLayoutVersion = 1;
inline constexpr size_t kViewIndexBytes = 52;

// A view's index chunk (§11.1.3), as the decoder uses it.
struct ViewIndex {
  Vec3 position;  // the viewpoint, scene units
  float z_near = 1, z_far = 2;
  bool has_depth = false;     // the view saw a finite depth (else every code is sky)
  bool has_material = false;  // material chunks exist for this view
  uint32_t depth_keyframe_interval = 1, depth_window = 1;
  float min_psnr_db = 0;  // informative: the encoder's Q
};

// The view index chunk's bytes (§11.1.3), declared once: ViewIndex with its two booleans as the
// flag bits of the chunk. A layout version other than 1, a position, z_near or z_far that is not
// finite, a reserved flag bit or K or W of 0 are refused by the field rules themselves.
struct ViewIndexRecord {
  uint32_t layout_version = kLayoutVersion;
  double position[3] = {0, 0, 0};
  float z_near = 1, z_far = 2;
  uint32_t flags = 0;  // bit 0 has_depth, bit 1 has_material
  uint32_t depth_keyframe_interval = 1, depth_window = 1;
  float min_psnr_db = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.layout_version, "layout version", container::Range{kLayoutVersion, kLayoutVersion});
    v(s.position, "position", container::FloatRule::kFinite);
    v(s.z_near, "z_near", container::FloatRule::kFinite);
    v(s.z_far, "z_far", container::FloatRule::kFinite);
    v(s.flags, "flags", container::Range{0, 3});
    v(s.depth_keyframe_interval, "depth_keyframe_interval", container::Range{1, UINT32_MAX});
    v(s.depth_window, "depth_window", container::Range{1, UINT32_MAX});
    v(s.min_psnr_db, "min_psnr_db");
  }
};
static_assert(container::fixed_size<ViewIndexRecord>() == kViewIndexBytes);

// Writes a view's index chunk. Errors: kContainerWriterMisuse for what parse_view_index refuses.
Expected<std::vector<uint8_t>> serialize_view_index(const ViewIndex& index);
// Refuses (CALF-E202) a chunk of another size or version, a position, z_near or z_far that is not
// finite, z_near / z_far outside 0 < z_near < z_far, reserved flag bits, and K or W of 0.
Expected<ViewIndex> parse_view_index(std::span<const uint8_t> raw, const std::string& what);

// A colour cell's t chunk (§11.1.4): the keyframes as a counted array (u32 K, K x u32), then
// frame_count t values that fill the rest of the chunk (their number is the chunk key's frame
// count, not on disk: a reader sizes `t` to it before reading).
struct CellTimeline {
  std::vector<uint32_t> keyframes;  // strictly increasing from 0, all < frame_count
  std::vector<uint8_t> t;           // frame_count values
  // The index in `keyframes` of the last keyframe <= frame.
  uint32_t bracket(uint32_t frame) const;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.keyframes, "keyframes", container::Range{1, container::kMaxFrames});
    v(s.t, "t", container::Length{s.t.size()});
  }
};
// Append a t chunk with container::write_fields(timeline, out, what).
Expected<CellTimeline> parse_t_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                     const std::string& what);

// How a region chunk's payload is coded (§11.1.6), from the track's depth / material format.
enum class RegionCoding : uint8_t {
  kR16,           // depth, two 16-bit planes
  kR16Predicted,  // depth, two 16-bit planes of prediction residuals (depth_predict.h)
  // depth, r16p whose P-frame rectangles hold a change mask and their changed texels' residuals
  // only (§11.1.9): their other texels keep the decoder's tile state.
  kR16PredictedMasked,
  kBc5,   // depth, BC5 with block split
  kRgb8,  // material, three byte planes
  kBc1,   // material, BC1 with block split
  // coverage (§11.1.11): per rectangle a bitmap of its edge texels, then the edge texels' mask
  // high bytes, mask low bytes and near counts as three planes; other texels are plain.
  kCoverage,
};
// Errors: CALF-E203 for a format §11.1 does not allow for the stream.
Expected<RegionCoding> depth_coding(uint16_t depth_format);
Expected<RegionCoding> material_coding(uint16_t material_format);
bool region_coding_is_block(RegionCoding coding);

// One rectangle of a region chunk: on disk u16 x, y, w, h (tile coordinates); `first_unit` is
// derived by the parser, not stored.
struct RegionRect {
  uint16_t x = 0, y = 0, w = 0, h = 0;  // tile coordinates
  uint64_t first_unit = 0;  // index of its first texel (raw codings) or block (block codings);
                            // kR16PredictedMasked: of its first stored (changed) texel
  // kR16PredictedMasked P-frame rectangles: the payload offset of its change mask; else kNoMask.
  static constexpr uint64_t kNoMask = UINT64_MAX;
  uint64_t mask_offset = kNoMask;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.x, "x");
    v(s.y, "y");
    v(s.w, "w");
    v(s.h, "h");
  }
};

// The head of a region chunk (§11.1.6), before its payload: F rectangle counts as a counted array
// (u32 F, F x u32 R_i), then the sum of R_i rectangles, frame by frame. Append one with
// container::write_fields(head, out, what), then the payload.
struct RegionHead {
  std::vector<uint32_t> rect_counts;  // R_i of each frame of the group
  std::vector<RegionRect> rects;      // every frame's rectangles in frame order
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.rect_counts, "rectangle counts", container::Range{1, container::kMaxFrames});
    uint64_t total = 0;
    for (uint32_t n : s.rect_counts) total += n;
    v(s.rects, "rectangles", container::Length{total});
  }
};

// A parsed region chunk; `payload` points into the chunk's bytes, which must outlive it.
struct RegionChunk {
  RegionCoding coding = RegionCoding::kR16;
  uint32_t tile_width = 0, tile_height = 0;
  uint32_t frame_count = 0;
  std::vector<uint32_t>
      first_rect;  // frame_count + 1 entries: frame i owns rects [first_rect[i], first_rect[i + 1])
  std::vector<RegionRect> rects;
  uint64_t units = 0;       // texels or blocks of all rects (kR16PredictedMasked: stored texels;
                            // kCoverage: edge texels)
  uint64_t mask_bytes = 0;  // kR16PredictedMasked, kCoverage: the masks before the planes; else 0
  std::span<const uint8_t> payload;
};
// `frame_count` is the chunk's key (ChunkKeys::frame_count); the chunk must agree with it.
Expected<RegionChunk> parse_region_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                         uint32_t tile_width, uint32_t tile_height,
                                         RegionCoding coding, const std::string& what);

// True when rect `index` stores only some of its texels (a kR16PredictedMasked P-frame rectangle):
// its other texels are the decoder's tile state, which region_rect_gpu_bytes then reads from `out`.
inline bool region_rect_reads_state(const RegionChunk& chunk, size_t index) {
  return chunk.coding == RegionCoding::kR16PredictedMasked &&
         chunk.rects[index].mask_offset != RegionRect::kNoMask;
}

// The GPU-ready bytes (lightfield_decoder.h's update formats) of rect `index` of a parsed region
// chunk: kR16, kR16Predicted, kR16PredictedMasked -> little-endian u16 codes; kBc5 / kBc1 -> whole
// blocks, row-major; kRgb8 -> RGBA8 (reflect, refract, ior, 255); kCoverage -> 4 bytes per texel
// (CoverageTexel::gpu_bytes: mask low byte, mask high byte, near count, far count). Replaces `out`,
// except when region_rect_reads_state(): then `out` must hold on entry the rectangle's codes in the
// decoder's tile state (2 w h bytes, little-endian, row-major; the frame before, or any frame of
// the window §11.1.3 allows), and only its changed texels are rewritten.
void region_rect_gpu_bytes(const RegionChunk& chunk, size_t index, std::vector<uint8_t>& out);
// The GPU format of those bytes.
container::PixelFormat region_gpu_format(RegionCoding coding);

// ---- Coverage (§11.1.11) ----

// The coverage of one texel (format/CAPTURE.md "Coverage"): the 4 x 4 cell mask of the cells that
// show the texel's own surface (bit 4 j + i for cell (i, j)) and how many of the others lie nearer
// than its depth; the rest, 16 - near - popcount(mask), lie farther (or are sky).
struct CoverageTexel {
  uint16_t mask = 0xFFFF;
  uint8_t near = 0;
  // Whether it is the plain texel, wholly its own surface: a coverage chunk stores only others.
  bool plain() const { return mask == 0xFFFF && near == 0; }
  // near <= 16 and near + popcount(mask) <= 16.
  bool valid() const;
  uint8_t far() const;  // 16 - near - popcount(mask); valid() texels only
  friend bool operator==(const CoverageTexel&, const CoverageTexel&) = default;
};
inline constexpr size_t kCoverageGpuBytes = 4;
// A coverage texel from its 4 GPU bytes (region_rect_gpu_bytes), and back.
inline CoverageTexel coverage_from_gpu(const uint8_t* p) {
  return {static_cast<uint16_t>(p[0] | p[1] << 8), p[2]};
}
void coverage_to_gpu(const CoverageTexel& t, uint8_t* p);

// Appends the coverage payload (§11.1.11) of `rects` (each `texels` of w x h row-major coverage
// texels, in the head's order): every rectangle's edge bitmap, then the three planes.
struct CoverageRect {
  uint32_t width = 0, height = 0;
  std::span<const CoverageTexel> texels;
};
void append_coverage_payload(std::vector<uint8_t>& out, std::span<const CoverageRect> rects);

// CALF-E203 unless `colour_format` is one §11.1 allows for colour (BC1, BC7, BC6H, rgba8, rgba16f,
// av1, av1hdr).
Status check_colour_format(uint16_t colour_format);

// The GPU-ready bytes of a w x h colour keyframe payload (§11.1.5): BC1 blocks unsplit, BC6H / BC7
// unchanged, rgba8 planes interleaved, rgba16f planes to little-endian halves. Replaces `out`.
// Errors: CALF-E202 for a payload of the wrong size, CALF-E203 for a format that is not colour.
Status colour_payload_gpu_bytes(uint16_t colour_format, std::span<const uint8_t> payload,
                                uint32_t width, uint32_t height, std::vector<uint8_t>& out,
                                const std::string& what);

// The pixel format of the colour updates a decoder yields for a track of `colour_format`: the
// format itself, but rgba8 for AV1 colour (its pictures are converted to sRGB-encoded RGBA8) and
// rgba16f for HDR AV1 colour (its 10-bit codes are half floats on the chunk's curve).
container::PixelFormat colour_gpu_format(uint16_t colour_format);

// ---- AV1 colour (§11.1.12) ----

// An AV1 colour chunk: the temporal units (low-overhead OBU format) of F consecutive frames of one
// cell, the first a key frame; `units` point into the chunk's bytes, which must outlive them.
struct Av1Gop {
  std::vector<std::span<const uint8_t>> units;
};
// The head is u32 F (= the chunk's frame_count key), F x u32 unit sizes (each >= 1), then the
// units back to back, nothing after. Errors: CALF-E067 (kAv1Chunk).
Expected<Av1Gop> parse_av1_gop(std::span<const uint8_t> raw, uint32_t frame_count,
                               const std::string& what);
// Appends an AV1 colour chunk of `units` (each non-empty) as parse_av1_gop reads it.
void append_av1_gop(std::vector<uint8_t>& out, std::span<const std::vector<uint8_t>> units);

}  // namespace calf::lf
