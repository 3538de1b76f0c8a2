// The tiles track's chunk layouts (format/SPEC.md §11.2); the rules are in tiles_layout.h.
#include "calf/format/tiles_layout.h"

#include <bit>
#include <cmath>

#include "calf/format/coordinates.h"

namespace calf::tiles {
namespace {

using container::cat;

Status error(ErrorId id, const std::string& what, const std::string& message) {
  return Status(id, what + ": " + message);
}

// Word w of tile t in the order of §11.2.3: corner k = w / 6, field j = w % 6 (x, y, z, U, V, W).
uint32_t word(const Tile& t, uint32_t w) {
  const TileCorner& c = t.corners[w / 6];
  const uint32_t j = w % 6;
  return std::bit_cast<uint32_t>(j < 3 ? c.position[j] : c.uvw[j - 3]);
}

void set_word(Tile& t, uint32_t w, uint32_t v) {
  TileCorner& c = t.corners[w / 6];
  const uint32_t j = w % 6;
  (j < 3 ? c.position[j] : c.uvw[j - 3]) = std::bit_cast<float>(v);
}

const char* const kFieldNames[6] = {"x", "y", "z", "U", "V", "W"};

}  // namespace

// ---- Index ----

Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index) {
  std::vector<uint8_t> out;
  CALF_RETURN_IF_ERROR(container::write_fields(index, out, "tiles index"));
  Expected<IndexChunk> back = parse_index(out, "tiles index");
  if (!back.ok()) return Status(ErrorId::kContainerWriterMisuse, back.status().message());
  return out;
}

Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, const std::string& what) {
  // The layout version comes first and alone: a later layout may change everything after it.
  if (raw.size() < 4)
    return error(ErrorId::kTilesChunk, what, cat(raw.size(), " bytes, too short for a version"));
  const uint32_t version = static_cast<uint32_t>(container::load_le(raw.data(), 4));
  if (version != kLayoutVersion)
    return error(ErrorId::kTilesUnsupported, what, cat("layout version ", version, ", expected 1"));
  IndexChunk x;
  container::FieldReader r(raw, ErrorId::kTilesChunk, ErrorId::kTilesValue, what,
                           ErrorId::kTilesLimit);
  CALF_RETURN_IF_ERROR(container::read_fields(x, r));
  if (r.remaining() != 0)
    return error(ErrorId::kTilesChunk, what, cat(r.remaining(), " bytes after the fields"));
  if (x.flags != 0)
    return error(ErrorId::kTilesUnsupported, what, cat("reserved flags ", x.flags, " set"));
  if (x.band_rows % 4 != 0)
    return error(ErrorId::kTilesValue, what,
                 cat("band_rows ", x.band_rows, " is not a multiple of 4"));
  for (int c = 0; c < 3; ++c) {
    if (!coordinate_ok(x.view_min[c]) || !coordinate_ok(x.view_max[c]) ||
        !(x.view_min[c] <= x.view_max[c])) {
      return error(ErrorId::kTilesValue, what,
                   cat("view region axis ", c, " [", x.view_min[c], ", ", x.view_max[c],
                       "] is inverted or beyond +-1e12"));
    }
  }
  return x;
}

Status check_header(const container::TilesTrackHeader& h) {
  if (h.frame_count != 1)
    return Status(ErrorId::kTilesUnsupported, cat("tiles track header: frame_count ", h.frame_count,
                                                  " (layout 1 holds one static frame)"));
  if (h.flags != 0)
    return Status(ErrorId::kTilesUnsupported,
                  cat("tiles track header: reserved flags in ", h.flags));
  if (h.atlas_format != kAtlasBc7 && h.atlas_format != kAtlasRgba8)
    return Status(ErrorId::kTilesUnsupported,
                  cat("tiles track header: atlas_format ", h.atlas_format,
                      " is neither BC7 (8) nor rgba8 (1)"));
  if (h.tile_count > kMaxTiles)
    return Status(ErrorId::kTilesLimit,
                  cat("tiles track header: tile_count ", h.tile_count, " is above ", kMaxTiles));
  return Status::Ok();
}

// ---- Quads ----

uint64_t quads_chunk_size(uint64_t tile_count) {
  return kTileBytes * tile_count;
}

bool corner_ok(const TileCorner& c, const char** field) {
  for (int j = 0; j < 3; ++j) {
    if (!coordinate_ok(c.position[j])) {
      *field = kFieldNames[j];
      return false;
    }
  }
  const float u = c.uvw[0], v = c.uvw[1], w = c.uvw[2];
  if (!std::isfinite(w) || !(w > 0.0f)) {
    *field = "W";
    return false;
  }
  // (u, v) = (U / W, V / W) in [0, 1], compared without dividing: exact for W > 0.
  if (!(u >= 0.0f && u <= w)) {
    *field = "U";
    return false;
  }
  if (!(v >= 0.0f && v <= w)) {
    *field = "V";
    return false;
  }
  return true;
}

Expected<std::vector<uint8_t>> encode_quads(std::span<const Tile> tiles) {
  const size_t n = tiles.size();
  if (n > kMaxTiles)
    return Status(ErrorId::kContainerWriterMisuse, cat("tiles quads: ", n, " tiles"));
  // Residuals in component planes: plane w holds word w of every tile. Corner 0 is predicted by
  // the previous tile's corner 0 (builders emit neighbouring tiles together), corners 1-3 by
  // corner 0 of their own tile (a tile is small against its distance), through the binary32 bit
  // patterns, modulo 2^32.
  std::vector<uint32_t> res(size_t{kTileWords} * n);
  for (size_t t = 0; t < n; ++t) {
    for (uint32_t w = 0; w < kTileWords; ++w) {
      const uint32_t j = w % 6;
      const uint32_t pred = w < 6 ? (t ? word(tiles[t - 1], w) : 0u) : word(tiles[t], j);
      res[w * n + t] = word(tiles[t], w) - pred;
    }
  }
  std::vector<uint8_t> out(4 * res.size());
  for (size_t i = 0; i < res.size(); ++i) {
    for (size_t b = 0; b < 4; ++b)
      out[b * res.size() + i] = static_cast<uint8_t>(res[i] >> (8 * b));
  }
  return out;
}

Status decode_quads(std::span<const uint8_t> raw, uint32_t tile_count, std::vector<Tile>* out,
                    const std::string& what) {
  if (raw.size() != quads_chunk_size(tile_count))
    return error(ErrorId::kTilesChunk, what,
                 cat(raw.size(), " bytes, expected ", quads_chunk_size(tile_count), " for ",
                     tile_count, " tiles"));
  const size_t n = tile_count, words = size_t{kTileWords} * n;
  std::vector<Tile> tiles(n);
  for (size_t t = 0; t < n; ++t) {
    for (uint32_t w = 0; w < kTileWords; ++w) {
      const size_t i = w * n + t;
      const uint32_t r = static_cast<uint32_t>(raw[i]) |
                         static_cast<uint32_t>(raw[words + i]) << 8 |
                         static_cast<uint32_t>(raw[2 * words + i]) << 16 |
                         static_cast<uint32_t>(raw[3 * words + i]) << 24;
      const uint32_t j = w % 6;
      const uint32_t pred = w < 6 ? (t ? word(tiles[t - 1], w) : 0u) : word(tiles[t], j);
      set_word(tiles[t], w, r + pred);
    }
    for (uint32_t k = 0; k < 4; ++k) {
      const char* field = "";
      if (!corner_ok(tiles[t].corners[k], &field)) {
        const TileCorner& c = tiles[t].corners[k];
        return error(
            ErrorId::kTilesValue, what,
            cat("tile ", t, " corner ", k, " ", field, ": position (", c.position[0], ", ",
                c.position[1], ", ", c.position[2], ") uvw (", c.uvw[0], ", ", c.uvw[1], ", ",
                c.uvw[2], ") (want a finite position within +-1e12, W > 0, 0 <= U, V <= W)"));
      }
    }
  }
  *out = std::move(tiles);
  return Status::Ok();
}

// ---- Atlas ----

uint32_t band_count(uint32_t height, uint32_t band_rows) {
  return band_rows ? (height + band_rows - 1) / band_rows : 0;
}

uint32_t band_first_row(uint32_t b, uint32_t band_rows) {
  return b * band_rows;
}

uint32_t band_end_row(uint32_t b, uint32_t height, uint32_t band_rows) {
  const uint64_t end = (uint64_t{b} + 1) * band_rows;
  return end < height ? static_cast<uint32_t>(end) : height;
}

uint64_t band_chunk_size(uint16_t format, uint32_t width, uint32_t height, uint32_t band_rows,
                         uint32_t b) {
  const uint64_t first = band_first_row(b, band_rows), end = band_end_row(b, height, band_rows);
  if (end <= first) return 0;
  const uint64_t rows = end - first;
  if (format == kAtlasRgba8) return uint64_t{width} * rows * 4;
  if (format == kAtlasBc7) return (uint64_t{width} + 3) / 4 * ((rows + 3) / 4) * 16;
  return 0;
}

}  // namespace calf::tiles
