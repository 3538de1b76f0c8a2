// The tiles track (kind 2, format/SPEC.md §11.2): layered quad tiles with an RGBA atlas (paper
// 000, Seurat). This header holds what the frozen 1.0 file
// (tests/conformance/container/valid/v1_frozen.calf) fixed for the kind: its track header and
// stream tags. Below them (SPEC §11.2) the byte layout of its chunks, both directions: the
// versioned index chunk (stream 0) declared once with the fields visitor (container_fields.h),
// the quads chunk (stream 2: every tile's four corners, positions and projective texture
// coordinates as lossless binary32, predicted and in byte planes) and the atlas chunks (stream 1:
// bands of texel rows, BC7 blocks or plain RGBA8).
// The encoder (encoder/tiles_encode.h) writes with serialize_index / encode_quads /
// atlas band helpers; every decoder (decoder/tiles_track.h) reads with parse_index / decode_quads.
// This is the one place that knows the prediction and byte planes of §11.2.
//
// Parsers check every count and size against the chunk before use and every value before
// returning it: a chunk of the wrong size or a missing one is CALF-E210 (kTilesChunk), an
// unknown layout version, flag, atlas format or frame count E211, a bad value E212, a count above
// a limit E213 (E214 is the encoder's: inconsistent input). Messages start with the caller's
// `what` ("tiles quads").
#pragma once

#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"

namespace calf::container {

// Stream tags (SPEC.md §11.2).
#define CALF_TILES_STREAMS(X) X(kIndex, 0, "index") X(kAtlas, 1, "atlas") X(kQuads, 2, "quads")
enum class TilesStream : uint16_t { CALF_TILES_STREAMS(CALF_STREAM_ENUM) };

// Track header (28 bytes), frozen in 1.0; later fields are appended.
struct TilesTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kTiles;
  static constexpr const char* kStreamNames[] = {CALF_TILES_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  // SPEC §11.2: frame_count is 1 in layout 1 (a static view region; CALF-E211
  // otherwise). tile_count: the tiles of the quads chunk (<= tiles::kMaxTiles, E213).
  // atlas_format: PixelFormat kBc7 (8) or kRgba8 (1) (E211 otherwise). flags: reserved, 0 (E211).
  uint32_t tile_count = 0;
  uint32_t atlas_width = 1;
  uint32_t atlas_height = 1;
  uint16_t atlas_format = 0;  // PixelFormat
  uint16_t flags = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
    v(s.tile_count, "tile_count");
    v(s.atlas_width, "atlas_width", Range{1, kMaxDimension});
    v(s.atlas_height, "atlas_height", Range{1, kMaxDimension});
    v(s.atlas_format, "atlas_format");
    v(s.flags, "flags");
  }
};
static_assert(fixed_size<TilesTrackHeader>() == 28);
static_assert(std::size(TilesTrackHeader::kStreamNames) ==
              static_cast<size_t>(TilesStream::kQuads) + 1);

}  // namespace calf::container

namespace calf::tiles {

// ---- Constants (SPEC.md §11.2) ----

inline constexpr uint32_t kLayoutVersion = 1;
// Limits (a larger count is CALF-E213): 2^22 tiles (a quads chunk of 384 MiB raw, under the
// container's 1 GiB), and the atlas side of the header (16,384).
inline constexpr uint32_t kMaxTiles = 1u << 22;
inline constexpr uint32_t kMaxAtlasSize = container::kMaxDimension;
// Raw bytes per tile in the quads chunk: 4 corners x (3 position + 3 uvw) binary32.
inline constexpr uint32_t kTileBytes = 96;
inline constexpr uint32_t kTileWords = 24;
// Atlas formats (PixelFormat values).
inline constexpr uint16_t kAtlasRgba8 = static_cast<uint16_t>(container::PixelFormat::kRgba8);
inline constexpr uint16_t kAtlasBc7 = static_cast<uint16_t>(container::PixelFormat::kBc7);
// The atlas band height calf's encoder writes (texel rows per atlas chunk).
inline constexpr uint32_t kDefaultBandRows = 1024;

// ---- The index chunk (stream 0, §11.2.2) ----

// 60 bytes: u32 layout version, u32 flags (0), the view region (f64 x 3 min, f64 x 3 max) and the
// atlas band height. Nothing may follow.
struct IndexChunk {
  uint32_t layout_version = kLayoutVersion;
  uint32_t flags = 0;              // reserved, 0
  double view_min[3] = {0, 0, 0};  // TileSet::view_volume, finite, min <= max per axis
  double view_max[3] = {0, 0, 0};
  // Texel rows per atlas chunk: a multiple of 4 in [4, 16384]; the last band holds the rest.
  uint32_t band_rows = kDefaultBandRows;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.layout_version, "layout_version");
    v(s.flags, "flags");
    v(s.view_min, "view_min", container::FloatRule::kFinite);
    v(s.view_max, "view_max", container::FloatRule::kFinite);
    v(s.band_rows, "band_rows", container::Range{4, kMaxAtlasSize});
  }
};
static_assert(container::fixed_size<IndexChunk>() == 60);

// Writes the index chunk. Errors: kContainerWriterMisuse for anything parse_index refuses.
Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index);
// Reads and checks the index chunk in §11.2.2's order: the layout version first (E211), the
// size (E210), a non-finite view region (E212), band_rows above 16,384 (E213), then flags (E211)
// and values: band_rows below 4 or not a multiple of 4, an inverted or out-of-bound view region
// (E212).
Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, const std::string& what);

// Checks the track header's own rules of layout 1 (frame_count 1, atlas format, flags: E211;
// tile_count: E213).
Status check_header(const container::TilesTrackHeader& header);

// ---- Quads chunk (stream 2, §11.2.3) ----

// The exact raw size of the quads chunk of n tiles (96 n).
uint64_t quads_chunk_size(uint64_t tile_count);
// Whether a corner's values follow §11.2.3's rules (finite position within +-1e12, finite
// (U, V, W), W > 0, 0 <= U <= W, 0 <= V <= W); on failure `field` names the first bad one.
bool corner_ok(const TileCorner& c, const char** field);
// Codes `tiles` (kContainerWriterMisuse above kMaxTiles). Lossless: the decoder returns every
// float bit for bit.
Expected<std::vector<uint8_t>> encode_quads(std::span<const Tile> tiles);
// Decodes and checks `tile_count` tiles (size E210, values E212 naming the tile, corner and
// field). Replaces `out`.
Status decode_quads(std::span<const uint8_t> raw, uint32_t tile_count, std::vector<Tile>* out,
                    const std::string& what);

// ---- Atlas chunks (stream 1, §11.2.4) ----

// The number of bands of an atlas `height` rows high cut every `band_rows` rows.
uint32_t band_count(uint32_t height, uint32_t band_rows);
// Texel rows [first, end) of band b.
uint32_t band_first_row(uint32_t b, uint32_t band_rows);
uint32_t band_end_row(uint32_t b, uint32_t height, uint32_t band_rows);
// The exact raw size of band b: width * rows * 4 (rgba8), or ceil(width / 4) * ceil(rows / 4) *
// 16 (BC7); 0 for another format.
uint64_t band_chunk_size(uint16_t format, uint32_t width, uint32_t height, uint32_t band_rows,
                         uint32_t b);

}  // namespace calf::tiles
