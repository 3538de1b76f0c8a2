// The tiles track (kind 2, format/SPEC.md §11.2): layered quad tiles (paper 000). This header
// holds what the frozen 1.0 file (tests/conformance/container/valid/v1_frozen.calf) fixed for
// the kind: its track header and stream tags. The chunk layouts, starting with the versioned
// index chunk (stream 0, SPEC.md §11 "Parameters of a kind"), belong to the tiles issue and are
// appended here.
#pragma once

#include <cstdint>
#include <iterator>

#include "calf/format/container_types.h"

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
