// Fuzz target: the tiles track reader (decoder/include/calf/decoder/tiles_track.h, SPEC §11.2) on
// arbitrary bytes. Opens them as a .calf file from memory, opens every tiles track, decodes its
// quads and its atlas (BC7 or rgba8) and verifies it with hashes. Any crash, sanitizer report or
// hang is a bug; errors are expected. Seeded with small tiles clips and damaged copies whose
// chunks are stored uncompressed (written by tests/integration/tiles_track_test.cc's generator),
// so that mutations reach the track's parsers rather than only the container's hashes.
#include <cstddef>
#include <cstdint>
#include <span>

#include "calf/decoder/tiles_track.h"
#include "calf/decoder/tiles_verify.h"
#include "calf/format/container.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf;
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  for (uint16_t t = 0; t < r->tracks().size(); ++t) {
    auto track = decoder::TilesTrack::open(*r, t);
    if (!track.ok()) continue;
    // open() bounds the tile count and atlas by real chunk bytes; cap the work per input anyway.
    if (uint64_t{track->atlas_width()} * track->atlas_height() > (1u << 22)) continue;
    std::vector<Tile> tiles;
    (void)track->quads(&tiles).ok();
    std::vector<uint8_t> atlas;
    (void)track->atlas(&atlas).ok();
    (void)decoder::verify_tiles_track(*r, t, true, 4);
  }
  return 0;
}
