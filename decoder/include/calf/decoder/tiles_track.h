// Reading a tiles track (kind 2, format/SPEC.md §11.2): layered quad tiles with an RGBA atlas
// (paper 000, Seurat) for one static view region, back into a TileSet (calf/format/tile_set.h).
//
// open() reads the index chunk only and checks the header, the chunk keys and that the quads
// chunk and every atlas band exist with their exact sizes (so every count is bounded by real
// bytes before anything is allocated). quads() decodes the tiles, atlas() the atlas as RGBA8
// (BC7 decoded on the CPU by calf/format/bc.h), atlas_payload() the atlas as stored (BC7 blocks a
// GL player uploads as they are, or the RGBA8 texels). decode() does all of it.
// The encoder side is encoder/tiles_encode.h; the conformance hashes tiles_verify.h.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"
#include "calf/format/tiles_layout.h"

namespace calf::decoder {

class TilesTrack {
 public:
  // Reads track `track`'s header and index chunk (stream 0) and checks the chunk index (SPEC
  // §11.2.5). `reader` must outlive the result. Errors: kInvalidArgument (no such track, not a
  // tiles track), the container's read errors, CALF-E210 - E213.
  static Expected<TilesTrack> open(const container::Reader& reader, uint16_t track);

  const container::TilesTrackHeader& header() const { return header_; }
  uint16_t track() const { return track_; }
  uint32_t tile_count() const { return header_.tile_count; }
  uint32_t atlas_width() const { return header_.atlas_width; }
  uint32_t atlas_height() const { return header_.atlas_height; }
  // tiles::kAtlasBc7 or tiles::kAtlasRgba8.
  uint16_t atlas_format() const { return header_.atlas_format; }
  // The index chunk as read: view region and band height.
  const tiles::IndexChunk& index() const;
  Box3 view_volume() const;

  // Decodes the quads chunk (the container's errors, then CALF-E210 / E212 naming the tile).
  Status quads(std::vector<Tile>* out) const;
  // The atlas as stored, every band in order: ceil(W / 4) * ceil(H / 4) BC7 blocks of 16 bytes,
  // row-major (bc.h's layout), or W * H * 4 RGBA8 bytes. The container's errors name the band.
  Status atlas_payload(std::vector<uint8_t>* out) const;
  // The atlas as RGBA8 texels, W * H * 4 bytes from the top row (BC7 decoded exactly as
  // calf/format/bc.h defines; the texels are premultiplied as the encoder's input was, a BC7
  // texel's colour may exceed its alpha by the block's error).
  Status atlas(std::vector<uint8_t>* out) const;
  // The whole tile set.
  Status decode(TileSet* out) const;

 private:
  TilesTrack() = default;
  const container::Reader* reader_ = nullptr;
  uint16_t track_ = 0;
  container::TilesTrackHeader header_;
  struct Index;  // the index chunk and the chunk ids (owned by the implementation)
  std::shared_ptr<const Index> index_;
};

// TilesTrack::open then decode: track `track` of `reader` as a TileSet.
Expected<TileSet> decode_tiles_track(const container::Reader& reader, uint16_t track);

}  // namespace calf::decoder
