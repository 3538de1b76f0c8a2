// calf-encode --mode tiles: one frame of a capture set into a tiles track (paper 000, Seurat;
// docs/TILES.md, format/SPEC.md §11.2): every knob of the builder and the track encoder.
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

#include "calf/encoder/tiles_build.h"
#include "calf/encoder/tiles_encode.h"
#include "calf_encode/common.h"

namespace calf::tools {

struct TilesOptions {
  uint32_t frame = 0;  // the capture frame the tiles are built from
  encoder::TilesBuildOptions build;
  encoder::TilesEncodeOptions encode;
};

inline constexpr const char* kTilesGroup = "Tiles options (--mode tiles)";

// The tiles mode's options (--tiles-*), in the group kTilesGroup.
void add_options(CLI::App& app, TilesOptions& options);

// Builds the tile set of `options.frame` of the capture set common.input (its directory or
// manifest.json) and writes it as the only track of the clip common.output (written whole or not
// at all). Options outside their ranges are usage errors (exit 2). Prints the build report and
// the bytes to stderr; errors print one line. Returns the command's exit status.
int run(const CommonOptions& common, const TilesOptions& options);

}  // namespace calf::tools
