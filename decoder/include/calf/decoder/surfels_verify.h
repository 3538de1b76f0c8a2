// Checking a surfels track by decoding all of it, and the conformance hashes of what it decodes
// to (format/SPEC.md §11.3.6): the index chunk, the pairing with its mesh track, then every
// prototype's whole buffer through SurfelsTrack (surfels_track.h), which checks every count and
// size. calf-verify runs it on every surfels track; with --decode it also prints the hashes, the
// runner of the frozen conformance clips in tests/conformance/surfels/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "calf/decoder/surfels_track.h"
#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf::decoder {

// Conformance hash of prototype p (SPEC §11.3.6): XXH3-64, seed 0, of little-endian 32-bit
// words: the record's surfel count, flags, prefix count and prefix radius (binary32 bits), then
// the decoded positions, normals and colours, each array in order (floats as their IEEE-754 bit
// patterns).
uint64_t surfels_prototype_hash(const surfels::PrototypeRecord& record, const SurfelBuffer& buffer);

struct SurfelsVerifyResult {
  // Layout problems (CALF-E230-E234, E232 for the pairing, and the container's read errors),
  // each naming the chunk or prototype; at most the max_problems asked for. An unopenable track
  // is one problem.
  std::vector<Status> problems;
  // "track T surfels P <hex>" lines, one per prototype, only when asked for and only while no
  // problem was found.
  std::vector<std::string> hash_lines;
  uint64_t prototypes_decoded = 0, surfels_decoded = 0;
  bool skipped = false;  // the track has no index chunk: nothing to decode (SPEC §11)
};

// Decodes track `track` of `reader` (a surfels track) completely, and opens the mesh track it
// names to check the pairing (only its index chunk is read: calf-verify checks that track on its
// own). Never fails as a call. A surfels track without any index chunk holds no representation
// (SPEC §11, as the surfels track of v1_frozen.calf): it is skipped, not a problem.
// `max_problems` >= 1.
SurfelsVerifyResult verify_surfels_track(const container::Reader& reader, uint16_t track,
                                         bool with_hashes, size_t max_problems);

}  // namespace calf::decoder
