// Checking a mesh track by decoding all of it, and the conformance hashes of what it decodes to
// (format/SPEC.md §11.4.7): the index chunk, then every prototype and every object through
// MeshTrack (mesh_track.h), which checks every count, size, index and value. calf-verify runs it on
// every mesh track; with --decode it also prints the hashes, the runner of the frozen conformance
// clips in tests/conformance/mesh/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf::decoder {

// Conformance hashes (SPEC §11.4.7): XXH3-64, seed 0, of the decoded values as little-endian
// 32-bit words (floats as their IEEE-754 bit patterns).
//  prototype: positions, normals, colours, indices, triangle materials, state times, state
//             positions, UVs, each array in order (absent arrays add nothing);
//  object:    prototype, material, all_triangles (1 or 0), the transforms' 12 floats each in
//             order, then the subset's triangle indices.
uint64_t prototype_hash(const MeshPrototype& prototype);
uint64_t object_hash(const MeshObject& object);
//  texture:   width, height, then the texels' bytes as they are (each texel one word R | G << 8
//             | B << 16 | A << 24), rows top first.
uint64_t texture_hash(const mesh::TextureTexels& texture);

struct MeshVerifyResult {
  // Layout problems (CALF-E220-E224 and the container's read errors), each naming the chunk,
  // prototype or object; at most the max_problems asked for. An unopenable track is one problem.
  std::vector<Status> problems;
  // "track T prototype P <hex>", then "track T object O <hex>", then "track T texture X <hex>"
  // lines, only when asked for and only
  // while no problem was found.
  std::vector<std::string> hash_lines;
  uint64_t prototypes_decoded = 0, objects_decoded = 0, textures_decoded = 0;
  bool skipped = false;  // the track has no index chunk: nothing to decode (SPEC §11)
};

// Decodes track `track` of `reader` (a mesh track) completely. Never fails as a call. A mesh track
// without any index chunk holds no representation (SPEC §11, as the tracks of v1_frozen.calf): it
// is skipped, not a problem. `max_problems` >= 1.
MeshVerifyResult verify_mesh_track(const container::Reader& reader, uint16_t track,
                                   bool with_hashes, size_t max_problems);

}  // namespace calf::decoder
