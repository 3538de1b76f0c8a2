// Checking a tiles track by decoding all of it, and the conformance hashes of what it decodes to
// (format/SPEC.md §11.2.6): the index chunk, the quads and the whole atlas through TilesTrack
// (tiles_track.h), which checks every count, size and value. calf-verify runs it on every tiles
// track; with --decode it also prints the hashes, the runner of the frozen conformance clips in
// tests/conformance/tiles/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "calf/decoder/tiles_track.h"
#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf::decoder {

// Conformance hash of the quads (SPEC §11.2.6): XXH3-64, seed 0, of the tile count (u32 LE), the
// view region's six binary64 (min x, y, z, max x, y, z; LE bit patterns), then every tile's 24
// binary32 (corner 0 .. 3: x, y, z, U, V, W; LE bit patterns).
uint64_t tiles_quads_hash(const TileSet& set);
// Conformance hash of the atlas: XXH3-64, seed 0, of width and height (u32 LE each), then the
// decoded RGBA8 texels as they are, rows from the top.
uint64_t tiles_atlas_hash(const TileSet& set);

struct TilesVerifyResult {
  // Layout problems (CALF-E210 - E213 and the container's read errors), each naming the chunk,
  // tile or band; at most the max_problems asked for. An unopenable track is one problem.
  std::vector<Status> problems;
  // "track T tiles quads <hex>" and "track T tiles atlas <hex>", only when asked for and only
  // while no problem was found.
  std::vector<std::string> hash_lines;
  uint64_t tiles_decoded = 0, texels_decoded = 0;
  bool skipped = false;  // the track has no index chunk: nothing to decode (SPEC §11)
};

// Decodes track `track` of `reader` (a tiles track) completely. Never fails as a call. A tiles
// track without any index chunk holds no representation (SPEC §11, as the tiles track of
// v1_frozen.calf): it is skipped, not a problem. `max_problems` >= 1.
TilesVerifyResult verify_tiles_track(const container::Reader& reader, uint16_t track,
                                     bool with_hashes, size_t max_problems);

}  // namespace calf::decoder
