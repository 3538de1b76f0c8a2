// calf-encode --mode tiles (compiled into calf-encode only): one frame of a capture set into a
// tiles track (paper 000, Seurat; docs/TILES.md, format/SPEC.md §11.2). The options are parsed by
// calf_encode.cc; this file builds, encodes, writes and reports.
#pragma once

#include <cstdint>
#include <string>

#include "calf/capture/image_budget.h"
#include "calf/encoder/tiles_build.h"
#include "calf/encoder/tiles_encode.h"

namespace calf::tools {

struct TilesModeOptions {
  uint32_t frame = 0;  // the capture frame the tiles are built from
  encoder::TilesBuildOptions build;
  encoder::TilesEncodeOptions encode;
  bool quiet = false;                                           // no progress line
  uint64_t max_image_pixels = capture::kDefaultMaxImagePixels;  // the capture set's budget
};

// Builds the tile set of `options.frame` of the capture set at `input` (its directory or
// manifest.json) and writes it as the only track of the clip `out` (written whole or not at
// all). Prints the build report and the bytes to stderr; errors print one line. Returns the
// command's exit status.
int encode_tiles(const std::string& input, const std::string& out, const TilesModeOptions& options);

}  // namespace calf::tools
