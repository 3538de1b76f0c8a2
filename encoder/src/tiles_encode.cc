// The tiles track encoder: validate, code quads and atlas bands, ordered assembly (rules in
// tiles_encode.h).
#include "calf/encoder/tiles_encode.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"
#include "calf/format/coordinates.h"

namespace calf::encoder {
namespace {

using container::cat;
using container::ChunkKeys;
using container::StoredChunk;
using container::TilesStream;

Status input_error(const std::string& message) {
  return Status(ErrorId::kTilesInput, "tile set: " + message);
}

// PSNR in dB of `b` against `a` (same size, 8-bit peak); infinity when equal.
double psnr(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    se += d * d;
  }
  if (se == 0 || a.empty()) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 * static_cast<double>(a.size()) / se);
}

}  // namespace

Status validate_tile_set(const TileSet& t) {
  if (t.atlas_width < 1 || t.atlas_width > tiles::kMaxAtlasSize || t.atlas_height < 1 ||
      t.atlas_height > tiles::kMaxAtlasSize)
    return input_error(cat("atlas ", t.atlas_width, " x ", t.atlas_height, " (each side 1 .. ",
                           tiles::kMaxAtlasSize, ")"));
  const size_t texels = size_t{t.atlas_width} * t.atlas_height;
  if (t.atlas_rgba.size() != 4 * texels)
    return input_error(cat("atlas of ", t.atlas_rgba.size(), " bytes, expected ", 4 * texels,
                           " for ", t.atlas_width, " x ", t.atlas_height, " RGBA8"));
  for (size_t i = 0; i < texels; ++i) {
    const uint8_t* p = &t.atlas_rgba[4 * i];
    if (p[0] > p[3] || p[1] > p[3] || p[2] > p[3])
      return input_error(cat("atlas texel (", i % t.atlas_width, ", ", i / t.atlas_width,
                             ") RGBA (", int{p[0]}, ", ", int{p[1]}, ", ", int{p[2]}, ", ",
                             int{p[3]}, ") has colour above alpha (the atlas is premultiplied)"));
  }
  const Box3& v = t.view_volume;
  const double lo[3] = {v.min.x, v.min.y, v.min.z}, hi[3] = {v.max.x, v.max.y, v.max.z};
  for (int c = 0; c < 3; ++c) {
    if (!coordinate_ok(lo[c]) || !coordinate_ok(hi[c]) || !(lo[c] <= hi[c]))
      return input_error(cat("view region axis ", c, " [", lo[c], ", ", hi[c],
                             "] is inverted or not finite within +-1e12"));
  }
  if (t.tiles.size() > tiles::kMaxTiles)
    return Status(ErrorId::kTilesLimit,
                  cat("tile set: ", t.tiles.size(), " tiles, above ", tiles::kMaxTiles));
  for (size_t i = 0; i < t.tiles.size(); ++i) {
    for (int k = 0; k < 4; ++k) {
      const char* field = "";
      const TileCorner& c = t.tiles[i].corners[k];
      if (!tiles::corner_ok(c, &field))
        return input_error(cat("tile ", i, " corner ", k, " ", field, ": position (", c.position[0],
                               ", ", c.position[1], ", ", c.position[2], ") uvw (", c.uvw[0], ", ",
                               c.uvw[1], ", ", c.uvw[2],
                               ") (want a finite position within +-1e12, W > 0, 0 <= U, V <= W)"));
    }
  }
  return Status::Ok();
}

Status validate_tiles_encode_options(const TilesEncodeOptions& options) {
  if (options.threads > 256)
    return Status(ErrorId::kEncoderOption, cat("threads ", options.threads, " is above 256"));
  if (static_cast<uint16_t>(options.supercompression) >= container::kCompressionCount)
    return Status(ErrorId::kEncoderOption, "unknown supercompression");
  if (options.bc7_quality < 0 || options.bc7_quality > 2)
    return Status(ErrorId::kEncoderOption,
                  cat("BC7 quality ", options.bc7_quality, " is not 0, 1 or 2"));
  if (options.band_rows < 4 || options.band_rows > tiles::kMaxAtlasSize ||
      options.band_rows % 4 != 0)
    return Status(ErrorId::kEncoderOption, cat("atlas band rows ", options.band_rows,
                                               " is not a multiple of 4 in [4, 16384]"));
  return Status::Ok();
}

Status encode_tiles_track(const TileSet& input, const TilesEncodeOptions& options,
                          container::Writer* writer, TilesEncodeStats* stats) {
  CALF_RETURN_IF_ERROR(validate_tiles_encode_options(options));
  CALF_RETURN_IF_ERROR(validate_tile_set(input));

  const uint32_t width = input.atlas_width, height = input.atlas_height;
  const bool bc7 = options.atlas_format == TilesAtlasFormat::kBc7;
  container::TilesTrackHeader header;
  header.fps_numerator = options.fps_numerator;
  header.fps_denominator = options.fps_denominator;
  header.tile_count = static_cast<uint32_t>(input.tiles.size());
  header.atlas_width = width;
  header.atlas_height = height;
  header.atlas_format = bc7 ? tiles::kAtlasBc7 : tiles::kAtlasRgba8;
  CALF_RETURN_IF_ERROR(tiles::check_header(header));
  tiles::IndexChunk index;
  const Box3& v = input.view_volume;
  index.view_min[0] = v.min.x, index.view_min[1] = v.min.y, index.view_min[2] = v.min.z;
  index.view_max[0] = v.max.x, index.view_max[1] = v.max.y, index.view_max[2] = v.max.z;
  index.band_rows = options.band_rows;
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> index_raw, tiles::serialize_index(index));
  CALF_ASSIGN_OR_RETURN(const std::vector<uint8_t> quads_raw, tiles::encode_quads(input.tiles));

  // The atlas payload as a decoder reads it: BC7 blocks of the whole atlas (block rows never
  // straddle a band: band_rows is a multiple of 4) or the texels.
  std::vector<uint8_t> payload;
  double atlas_psnr = std::numeric_limits<double>::infinity();
  if (bc7) {
    payload.resize(bc::encode_bound(bc::Format::kBc7, width, height));
    bc::Image8 image;
    image.pixels = input.atlas_rgba.data();
    image.width = width;
    image.height = height;
    image.row_stride = size_t{4} * width;
    image.channels = 4;
    bc::Bc7Options bo;
    bo.quality = options.bc7_quality;
    bo.threads = static_cast<int>(options.threads);
    CALF_RETURN_IF_ERROR(bc::encode_bc7(image, payload.data(), payload.size(), bo));
    if (stats) {
      std::vector<uint8_t> decoded(input.atlas_rgba.size());
      CALF_RETURN_IF_ERROR(bc::decode_image(bc::Format::kBc7, payload.data(), payload.size(), width,
                                            height, decoded.data(), decoded.size(),
                                            size_t{4} * width));
      atlas_psnr = psnr(input.atlas_rgba, decoded);
    }
  } else {
    payload = input.atlas_rgba;
  }

  // Independent parts: the index, the quads and every band, each compressed into its own slot.
  const uint32_t bands = tiles::band_count(height, options.band_rows);
  struct Part {
    Status status;
    ChunkKeys keys;
    std::span<const uint8_t> raw;
    StoredChunk chunk;
  };
  std::vector<Part> parts(2 + bands);
  parts[0].keys.stream = static_cast<uint16_t>(TilesStream::kIndex);
  parts[0].raw = index_raw;
  parts[1].keys.stream = static_cast<uint16_t>(TilesStream::kQuads);
  parts[1].raw = quads_raw;
  uint64_t at = 0;
  for (uint32_t b = 0; b < bands; ++b) {
    const uint64_t size =
        tiles::band_chunk_size(header.atlas_format, width, height, options.band_rows, b);
    Part& p = parts[2 + b];
    p.keys.stream = static_cast<uint16_t>(TilesStream::kAtlas);
    p.keys.region = b;
    p.raw = std::span<const uint8_t>(payload).subspan(at, size);
    at += size;
  }
  if (at != payload.size())
    return Status(ErrorId::kInternal,
                  cat("tiles atlas: bands hold ", at, " of ", payload.size(), " bytes"));
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, parts.size(), 1),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i < range.end(); ++i) {
                          Expected<StoredChunk> c = container::compress_chunk(
                              parts[i].raw, options.supercompression, options.levels);
                          if (c.ok())
                            parts[i].chunk = std::move(*c);
                          else
                            parts[i].status = c.status();
                        }
                      });
  });

  CALF_ASSIGN_OR_RETURN(
      const uint16_t track,
      writer->add_track(header, options.required ? container::kTrackRequired : uint16_t{0}));
  TilesEncodeStats s;
  s.tiles = header.tile_count;
  s.atlas_width = width;
  s.atlas_height = height;
  s.atlas_bands = bands;
  s.atlas_psnr_db = atlas_psnr;
  for (size_t i = 0; i < parts.size(); ++i) {
    Part& part = parts[i];
    CALF_RETURN_IF_ERROR(part.status);
    part.keys.track = track;
    CALF_RETURN_IF_ERROR(writer->add_stored_chunk(part.keys, part.chunk).status());
    const uint64_t stored = part.chunk.bytes.size();
    if (i == 0) {
      s.index_stored = stored;
    } else if (i == 1) {
      s.quads_raw = part.chunk.raw_size;
      s.quads_stored = stored;
    } else {
      s.atlas_raw += part.chunk.raw_size;
      s.atlas_stored += stored;
    }
  }
  if (stats) *stats = s;
  return Status::Ok();
}

}  // namespace calf::encoder
