// The tiles track encoder (kind 2, format/SPEC.md §11.2): a tile set (calf/format/tile_set.h:
// layered quad tiles with projective texture coordinates and a premultiplied sRGB RGBA8 atlas,
// what the tiles builder makes) in, a tiles track of a .calf container out.
//
// The encoder does not build tiles; what it does:
//   validate  every corner, the view region and the atlas (CALF-E214 names the tile, corner,
//             field or texel at fault; E213 for more tiles than §11.2 holds), before anything is
//             written;
//   code      the quads chunk (lossless binary32, §11.2.3), and the atlas as BC7 blocks
//             (options.bc7_quality, calf/encoder/bc_encode.h) or plain RGBA8, cut into bands of
//             1024 texel rows, each band its own chunk; bands are compressed options.threads at a
//             time;
//   assemble  index, quads, then the atlas bands in order.
// The bytes depend on the input and the options only, never on `threads`. What a decoder gets
// back: the tiles and the view region bit for bit; the atlas exactly (rgba8) or as BC7 decodes
// it (measured in SPEC §11.2.6 "Size": PSNR printed by the round-trip test).
// Only one frame: a tile set is one static view region (SPEC §11.2 says how a later layout would
// store several).
#pragma once

#include <cstdint>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"
#include "calf/format/tiles_layout.h"

namespace calf::encoder {

enum class TilesAtlasFormat : uint8_t {
  kBc7,    // BC7 blocks (4 bits per texel before supercompression), what GPUs sample directly
  kRgba8,  // the texels as they are (lossless, 32 bits per texel)
};

struct TilesEncodeOptions {
  TilesAtlasFormat atlas_format = TilesAtlasFormat::kBc7;
  // BC7 search effort: 0 fast, 1 default, 2 slow (bc_encode.h lists the modes each tries).
  int bc7_quality = 1;
  // Supercompression of every chunk of the track (zstd decodes fast; LZMA2 is smallest).
  container::Compression supercompression = container::Compression::kZstd;
  container::CompressionOptions levels;  // zstd level / LZMA preset (fixed per clip)
  // Texel rows per atlas chunk: a multiple of 4 in [4, 16384] (kEncoderOption otherwise).
  uint32_t band_rows = tiles::kDefaultBandRows;
  uint32_t threads = 1;  // 0 = all cores; never changes the output
  // Timing of the one frame (informative).
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  // Mark the track must-understand (SPEC §6.1): true when the clip is made to be played as
  // tiles; false when it only adds tiles beside a representation older readers can play.
  bool required = true;
};

struct TilesEncodeStats {
  uint32_t tiles = 0;
  uint32_t atlas_width = 0, atlas_height = 0;
  uint32_t atlas_bands = 0;
  uint64_t index_stored = 0;
  uint64_t quads_raw = 0, quads_stored = 0;  // 96 raw bytes per tile
  uint64_t atlas_raw = 0, atlas_stored = 0;  // BC7 blocks or RGBA8 texels
  // The atlas as decoded against the input (RGBA, all four channels, 8-bit peak): infinity for
  // rgba8 (lossless).
  double atlas_psnr_db = 0;
};

// Checks `tiles` without writing (what encode_tiles_track checks first). Errors: kTilesInput (an
// atlas side of 0 or above 16,384, an atlas buffer of another size than width * height * 4, a
// texel whose colour exceeds its alpha, a non-finite or inverted view region, a corner breaking
// §11.2.3: position not finite within +-1e12, W not > 0, U or V outside [0, W]), kTilesLimit
// (more than 2^22 tiles).
Status validate_tile_set(const TileSet& tiles);

// Checks the options alone (what encode_tiles_track checks first), so that a command can refuse
// them before building anything. Errors: kEncoderOption (threads above 256, an unknown
// supercompression, bc7_quality outside 0..2, band_rows not a multiple of 4 in [4, 16384]).
Status validate_tiles_encode_options(const TilesEncodeOptions& options);

// Encodes `tiles` into a new tiles track of `writer` (does not finish the writer), marked
// must-understand as options.required says. `stats` (optional) receives
// the figures. Errors: validate_tile_set's; kEncoderOption (threads above 256, an unknown
// supercompression, bc7_quality outside 0..2, band_rows not a multiple of 4 in [4, 16384]); the
// BC7 encoder's and the container's errors passed through.
Status encode_tiles_track(const TileSet& tiles, const TilesEncodeOptions& options,
                          container::Writer* writer, TilesEncodeStats* stats = nullptr);

}  // namespace calf::encoder
