// Checking a lightfield track by decoding all of it, and the conformance hashes of what it decodes
// to (format/SPEC.md §13): every face of every view at every frame goes through the reference
// decoder (lightfield_reference.h), which reads exactly the chunks SPEC §11.1 says a decoder needs
// and checks every count, rectangle and size. A file whose container is sound (every chunk hash
// matches) can still break its track's layout — a view index chunk missing or out of range, a
// t chunk too short, a rectangle outside its tile; this finds those. calf-verify runs it on every
// lightfield track; with --decode it also prints the hashes, the runner of the frozen conformance
// clips in tests/conformance/lightfield/.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "calf/decoder/lightfield_reference.h"
#include "calf/format/container.h"
#include "calf/format/status.h"

namespace calf::decoder {

// The conformance hash of one decoded face (SPEC §14): XXH3-64, seed 0, of the colour floats'
// IEEE-754 bit patterns, then the depth codes, then the material codes (absent without material),
// then per texel the coverage mask and near count (a track with coverage only), each value
// little-endian, in the order LightfieldFace holds them.
uint64_t face_hash(const LightfieldFace& face);

// One decoded face's hash.
struct FaceHash {
  uint32_t frame = 0, view = 0, face = 0;  // face in GL order
  uint64_t hash = 0;
};

struct LightfieldVerifyResult {
  // Layout problems, each naming view, face and frame where it has them (CALF-E202 / E203 and the
  // container's read errors), a dropped view (its index chunk unusable) once; at most the
  // max_problems asked for. A face that fails at one frame is not decoded at later frames.
  std::vector<Status> problems;
  // Frame-major (frame, view, face), only when asked for and only while no problem was found.
  std::vector<FaceHash> hashes;
  uint64_t faces_decoded = 0;
};

// Decodes track `track` of `reader` (a lightfield track) completely. Never fails as a call: an
// unopenable track (not lightfield, unknown format, a bad index chunk) is the result's one
// problem. `max_problems` >= 1.
LightfieldVerifyResult verify_lightfield_track(const container::Reader& reader, uint16_t track,
                                               bool with_hashes, size_t max_problems);

// The text form of one hash line, as calf-verify --decode prints it and the conformance files
// hold it: "track <t> frame <f> view <v> face <face> <16 hex digits>".
std::string face_hash_line(uint16_t track, const FaceHash& h);

}  // namespace calf::decoder
