// The tiles kind's entry in the decoder table (kind_table.h).
#include <fmt/core.h>

#include "calf/decoder/kind_table.h"
#include "calf/decoder/tiles_verify.h"
#include "calf/format/tiles_layout.h"

namespace calf::decoder {
namespace {

// decoded[0]: tiles, decoded[1]: texels.
TrackVerification verify(const container::Reader& reader, uint16_t track, bool with_hashes,
                         size_t max_problems) {
  TilesVerifyResult r = verify_tiles_track(reader, track, with_hashes, max_problems);
  TrackVerification out;
  out.problems = std::move(r.problems);
  out.hash_lines = std::move(r.hash_lines);
  out.decoded[0] = r.tiles_decoded;
  out.decoded[1] = r.texels_decoded;
  out.skipped = r.skipped;
  return out;
}

// Named when a tiles track was decoded, even one of no tiles.
std::string verified_summary(const VerifiedTotals& totals) {
  return totals.tracks ? fmt::format(", {} tiles and their atlas decoded", totals.decoded[0]) : "";
}

// From the header and the directory (SPEC §11.2: the quads chunk is stream 2, the atlas bands
// stream 1).
std::optional<TrackFigures> figures(const container::Reader& reader,
                                    const container::Track& track) {
  const auto* h = std::get_if<container::TilesTrackHeader>(&track.header);
  if (!h) return std::nullopt;
  const uint64_t tiles = h->tile_count, width = h->atlas_width, height = h->atlas_height;
  const char* format = container::pixel_format_name(h->atlas_format);
  uint64_t quads_stored = 0, atlas_stored = 0;
  for (const auto& c : reader.chunks()) {
    if (c.keys.track != track.id) continue;
    if (c.keys.stream == static_cast<uint16_t>(container::TilesStream::kQuads))
      quads_stored += c.stored_size;
    if (c.keys.stream == static_cast<uint16_t>(container::TilesStream::kAtlas))
      atlas_stored += c.stored_size;
  }
  const double per_tile =
      tiles ? static_cast<double>(quads_stored) / static_cast<double>(tiles) : 0.0;
  const double per_texel = width && height ? 8.0 * static_cast<double>(atlas_stored) /
                                                 static_cast<double>(width * height)
                                           : 0.0;
  // The format names are plain identifiers: a JSON string needs no escapes.
  return TrackFigures{
      fmt::format("tiles: {} tiles, {} triangles, quads {} stored bytes ({:.3f} bytes per tile), "
                  "atlas {} x {} {} {} stored bytes ({:.3f} bits per texel)",
                  tiles, 2 * tiles, quads_stored, per_tile, width, height, format, atlas_stored,
                  per_texel),
      fmt::format("\"tiles\":{{\"tiles\":{},\"triangles\":{},\"quads_stored_bytes\":{},"
                  "\"bytes_per_tile\":{:.3f},\"atlas_width\":{},\"atlas_height\":{},"
                  "\"atlas_format\":\"{}\",\"atlas_stored_bytes\":{},"
                  "\"atlas_bits_per_texel\":{:.3f}}}",
                  tiles, 2 * tiles, quads_stored, per_tile, width, height, format, atlas_stored,
                  per_texel)};
}

}  // namespace

extern const DecoderKind kTilesDecoderKind = {
    .kind = container::TrackKind::kTiles,
    .verify = verify,
    .verified_summary = verified_summary,
    .figures = figures,
};

}  // namespace calf::decoder
