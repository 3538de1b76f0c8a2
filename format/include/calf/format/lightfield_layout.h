// The byte layout of the lightfield track's chunks (format/SPEC.md §11.1), both directions: the
// encoder writes through the put_* / append_* helpers, every decoder parses through the parse_*
// functions and turns payloads into GPU-ready bytes through the *_gpu_bytes functions. This is the
// one place that knows the block split, the byte planes and the chunk headers.
//
// Parsers check every count, rectangle and size against the chunk before use; a contradiction is
// CALF-E202 (kLightfieldChunk), a format outside §11.1 CALF-E203 (kLightfieldFormat). Messages
// start with the caller's `what` (e.g. "view 3 face 1 region 7 depth").
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_types.h"
#include "calf/format/status.h"

namespace calf::lf {

// ---- Writing ----

inline void put_u16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v));
  out.push_back(static_cast<uint8_t>(v >> 8));
}
inline void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_u64(std::vector<uint8_t>& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_f32(std::vector<uint8_t>& out, float f) {
  uint32_t v;
  std::memcpy(&v, &f, 4);
  put_u32(out, v);
}
inline void put_f64(std::vector<uint8_t>& out, double f) {
  uint64_t v;
  std::memcpy(&v, &f, 8);
  put_u64(out, v);
}

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
inline float material_weight_from_code(uint8_t code) { return code / 255.0f; }
inline float material_ior_from_code(uint8_t code) { return 1.0f + 2.0f * (code / 255.0f); }

// ---- Reading ----

// A bounds-checked little-endian cursor over one chunk's raw bytes.
class ByteCursor {
 public:
  ByteCursor(std::span<const uint8_t> bytes, std::string what)
      : b_(bytes), what_(std::move(what)) {}
  size_t left() const { return b_.size() - pos_; }
  Expected<uint16_t> u16();
  Expected<uint32_t> u32();
  Expected<float> f32();
  Expected<double> f64();
  std::span<const uint8_t> rest() const { return b_.subspan(pos_); }

 private:
  Status ends_inside(const char* type) const;
  std::span<const uint8_t> b_;
  size_t pos_ = 0;
  std::string what_;
};

inline constexpr uint32_t kLayoutVersion = 1;
inline constexpr size_t kViewIndexBytes = 52;

// A view's index chunk (§11.1.3).
struct ViewIndex {
  double position[3] = {0, 0, 0};
  float z_near = 1, z_far = 2;
  bool has_depth = false;     // the view saw a finite depth (else every code is sky)
  bool has_material = false;  // material chunks exist for this view
  uint32_t depth_keyframe_interval = 1, depth_window = 1;
  float min_psnr_db = 0;  // informative: the encoder's Q
};
std::vector<uint8_t> serialize_view_index(const ViewIndex& index);
// Also refuses z_near / z_far that are not finite with 0 < z_near < z_far, and K or W of 0.
Expected<ViewIndex> parse_view_index(std::span<const uint8_t> raw, const std::string& what);

// A colour cell's t chunk (§11.1.4).
struct CellTimeline {
  std::vector<uint32_t> keyframes;  // strictly increasing from 0, all < frame_count
  std::vector<uint8_t> t;           // frame_count values
  // The index in `keyframes` of the last keyframe <= frame.
  uint32_t bracket(uint32_t frame) const;
};
Expected<CellTimeline> parse_t_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                     const std::string& what);

// How a region chunk's payload is coded (§11.1.6), from the track's depth / material format.
enum class RegionCoding : uint8_t {
  kR16,   // depth, two 16-bit planes
  kBc5,   // depth, BC5 with block split
  kRgb8,  // material, three byte planes
  kBc1,   // material, BC1 with block split
};
// Errors: CALF-E203 for a format §11.1 does not allow for the stream.
Expected<RegionCoding> depth_coding(uint16_t depth_format);
Expected<RegionCoding> material_coding(uint16_t material_format);
bool region_coding_is_block(RegionCoding coding);

struct RegionRect {
  uint16_t x = 0, y = 0, w = 0, h = 0;  // tile coordinates
  uint64_t first_unit = 0;  // index of its first texel (raw codings) or block (block codings)
};

// A parsed region chunk; `payload` points into the chunk's bytes, which must outlive it.
struct RegionChunk {
  RegionCoding coding = RegionCoding::kR16;
  uint32_t tile_width = 0, tile_height = 0;
  uint32_t frame_count = 0;
  std::vector<uint32_t> first_rect;  // frame_count + 1 entries: frame i owns rects [first_rect[i], first_rect[i + 1])
  std::vector<RegionRect> rects;
  uint64_t units = 0;  // texels or blocks of all rects
  std::span<const uint8_t> payload;
};
// `frame_count` is the chunk's key (ChunkKeys::frame_count); the chunk must agree with it.
Expected<RegionChunk> parse_region_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                         uint32_t tile_width, uint32_t tile_height,
                                         RegionCoding coding, const std::string& what);

// The GPU-ready bytes (clip_decoder.h's update formats) of rect `index` of a parsed region chunk:
// kR16 -> little-endian u16 codes; kBc5 / kBc1 -> whole blocks, row-major; kRgb8 -> RGBA8
// (reflect, refract, ior, 255). Replaces `out`.
void region_rect_gpu_bytes(const RegionChunk& chunk, size_t index, std::vector<uint8_t>& out);
// The GPU format of those bytes.
container::PixelFormat region_gpu_format(RegionCoding coding);

// CALF-E203 unless `colour_format` is one §11.1 allows for colour (BC1, BC7, BC6H, rgba8, rgba16f).
Status check_colour_format(uint16_t colour_format);

// The GPU-ready bytes of a w x h colour keyframe payload (§11.1.5): BC1 blocks unsplit, BC6H / BC7
// unchanged, rgba8 planes interleaved, rgba16f planes to little-endian halves. Replaces `out`.
// Errors: CALF-E202 for a payload of the wrong size, CALF-E203 for a format that is not colour.
Status colour_payload_gpu_bytes(uint16_t colour_format, std::span<const uint8_t> payload,
                                uint32_t width, uint32_t height, std::vector<uint8_t>& out,
                                const std::string& what);

}  // namespace calf::lf
