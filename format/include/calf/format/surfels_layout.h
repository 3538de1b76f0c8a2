// The surfels track (kind 3, format/SPEC.md §11.3): progressive blue-noise surfels (paper 001),
// one ordered surfel buffer per prototype of the clip's mesh track (§11.4), every prefix of which
// is a level of detail. This header holds what the frozen 1.0 file
// (tests/conformance/container/valid/v1_frozen.calf) fixed for the kind: its track header and
// stream tags. Below them (SPEC §11.3) the byte layout of its chunks, both directions: the
// versioned index chunk (stream 0) declared once with the fields visitor (container_fields.h),
// and the level chunks (stream 1) holding each prototype's quantised surfels in prefix order,
// cut at fixed surfel counts so that a reader fetches only the bytes of the prefix it draws.
// The encoder (encoder/surfels_encode.h) quantises and writes with serialize_index /
// encode_level; every decoder (decoder/surfels_track.h) reads with parse_index / decode_level.
// This is the one place that knows the quantisation and byte planes of §11.3.
//
// Parsers check every count and size against the chunk before use and every value before
// returning it: a chunk of the wrong size or a missing one is CALF-E230 (kSurfelsChunk), an
// unknown layout version or reserved flag bit E231, a mesh track that does not pair E232, a bad
// value E233, a count above a limit E234 (E235 is the encoder's: inconsistent input). Messages
// start with the caller's `what` ("prototype 3 level 2").
#pragma once

#include <cstdint>
#include <iterator>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/status.h"

namespace calf::container {

// Stream tags (SPEC.md §11.3).
#define CALF_SURFELS_STREAMS(X) X(kIndex, 0, "index") X(kSurfels, 1, "surfels")
enum class SurfelsStream : uint16_t { CALF_SURFELS_STREAMS(CALF_STREAM_ENUM) };

// Track header (26 bytes), frozen in 1.0; later fields are appended.
struct SurfelsTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kSurfels;
  static constexpr const char* kStreamNames[] = {CALF_SURFELS_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  // SPEC §11.3: object_count is the number of prototypes P the index chunk lists (one
  // per prototype of the paired mesh track, a prototype without surfels included), surfel_count
  // the sum of their surfel counts; both equal the index chunk's (CALF-E230). flags: reserved,
  // 0 (CALF-E231). The timing fields are the paired mesh track's (informative: surfels are in
  // object space and do not change over time).
  uint32_t object_count = 0;
  uint64_t surfel_count = 0;
  uint16_t flags = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
    v(s.object_count, "object_count");
    v(s.surfel_count, "surfel_count");
    v(s.flags, "flags");
  }
};
static_assert(fixed_size<SurfelsTrackHeader>() == 26);
static_assert(std::size(SurfelsTrackHeader::kStreamNames) ==
              static_cast<size_t>(SurfelsStream::kSurfels) + 1);

}  // namespace calf::container

namespace calf::surfels {

// ---- Constants (SPEC.md §11.3) ----

inline constexpr uint32_t kLayoutVersion = 1;
// Limits (a larger count is CALF-E234): the mesh track's prototype limit, and 2^26 surfels per
// prototype (its largest level chunk, 2^25 surfels, is 416 MiB raw: under the container's 1 GiB).
inline constexpr uint32_t kMaxPrototypes = 1u << 20;
inline constexpr uint32_t kMaxSurfels = 1u << 26;
// Raw bytes per surfel in a level chunk: 3 x u16 position, 2 x u16 octahedral normal, 3 x u8
// sRGB colour.
inline constexpr uint32_t kSurfelBytes = 13;
// Level 0 holds surfels [0, 1024); level k >= 1 holds [1024 * 2^(k-1), 1024 * 2^k).
inline constexpr uint32_t kFirstLevelSurfels = 1024;
// Quantisation steps: positions 65535 steps across the prototype's box per axis, normals 65535
// steps across the octahedral square per axis.
inline constexpr uint32_t kPositionSteps = 65535;
inline constexpr uint32_t kNormalSteps = 65535;

// PrototypeRecord::flags bit 0: the colours are the surface's own base colour (the object's
// material base colour is not applied); clear: they multiply the object's material base colour,
// as a mesh's vertex colours do (§11.4.3).
inline constexpr uint32_t kColourIsBase = 1;
inline constexpr uint32_t kPrototypeFlags = 1;

// ---- The index chunk (stream 0, §11.3.2) ----

// One prototype's surfel buffer: its count, the prefix-size parameters of paper 001 Eq. 1 and
// the box its positions are quantised in. 40 bytes.
struct PrototypeRecord {
  uint32_t surfel_count = 0;     // N, 0 .. kMaxSurfels (0: the prototype is drawn from the mesh)
  uint32_t flags = 0;            // kColourIsBase
  uint32_t prefix_count = 0;     // p_m: 1 .. N (0 when N = 0)
  float prefix_radius = 0;       // r_m, object space: > 0 (0 when N = 0)
  float box_min[3] = {0, 0, 0};  // the quantisation box, object space, min <= max per axis
  float box_max[3] = {0, 0, 0};
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.surfel_count, "surfel_count", container::Range{0, kMaxSurfels});
    v(s.flags, "flags");
    v(s.prefix_count, "prefix_count");
    v(s.prefix_radius, "prefix_radius", container::FloatRule::kFinite);
    v(s.box_min, "box_min", container::FloatRule::kFinite);
    v(s.box_max, "box_max", container::FloatRule::kFinite);
  }
};
static_assert(container::fixed_size<PrototypeRecord>() == 40);

// The whole index chunk: u32 layout version, u32 flags (0), u32 the paired mesh track's id, then
// the counted prototype records (prototype p of this track is prototype p of that mesh track).
// Nothing may follow the prototypes.
struct IndexChunk {
  uint32_t layout_version = kLayoutVersion;
  uint32_t flags = 0;       // reserved, 0
  uint32_t mesh_track = 0;  // the track id of the mesh track whose prototypes these are
  std::vector<PrototypeRecord> prototypes;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    v(s.layout_version, "layout_version");
    v(s.flags, "flags");
    v(s.mesh_track, "mesh_track");
    v(s.prototypes, "prototypes", container::Range{0, kMaxPrototypes});
  }
};

// Writes the index chunk. Errors: kContainerWriterMisuse for anything parse_index refuses.
Expected<std::vector<uint8_t>> serialize_index(const IndexChunk& index);
// Reads and checks the index chunk in §11.3.2's order: the layout version first (E231), every
// count and size (E230, E234), flags (E231), then values (E233). The mesh track id is checked
// by the reader against the file's tracks (E232), not here.
Expected<IndexChunk> parse_index(std::span<const uint8_t> raw, const std::string& what);

// ---- Levels (§11.3.1) ----

// The number of level chunks of a buffer of n surfels (0 for n = 0; 8 for 100,000), which is
// also the number of levels a prefix of n surfels needs.
uint32_t level_count(uint64_t n);
// Surfel range [begin, end) of level k of a buffer of n surfels (k < level_count(n)).
uint64_t level_begin(uint32_t k);
uint64_t level_end(uint32_t k, uint64_t n);
// The exact raw size of level k's chunk: kSurfelBytes per surfel.
uint64_t level_chunk_size(uint32_t k, uint64_t n);

// ---- Surfel values (§11.3.3) ----

// Quantised surfels as a level chunk holds them, surfel-major: 3 position codes (x, y, z), 2
// octahedral normal codes (u, v) and 3 sRGB-encoded colour bytes (r, g, b) per surfel.
struct SurfelCodes {
  std::vector<uint16_t> positions;  // 3 per surfel
  std::vector<uint16_t> normals;    // 2 per surfel
  std::vector<uint8_t> colours;     // 3 per surfel
  size_t size() const { return colours.size() / 3; }
};

// Decoded surfels: object-space positions, unit normals, linear RGB colours in [0, 1], 3 floats
// each per surfel, in prefix order.
struct SurfelArrays {
  std::vector<float> positions;
  std::vector<float> normals;
  std::vector<float> colours;
  size_t size() const { return positions.size() / 3; }
};

// Position code q of axis c in box [lo, hi]: float(((65535 - q) * lo + q * hi) / 65535) in
// binary64 (SPEC §11.3.3): lo for 0, hi for 65535, always within [lo, hi].
float decode_position(uint16_t q, float lo, float hi);
// Octahedral normal codes (u, v) to a unit vector (SPEC §11.3.3), out[3].
void decode_normal(uint16_t u, uint16_t v, float* out);
// sRGB-encoded byte to linear (SPEC §14's curve: calf/format/colour.h's linear_from_srgb8).
float decode_colour(uint8_t c);

// Codes surfels [begin, end) of `codes` as one level chunk (13 bytes per surfel).
// kContainerWriterMisuse when the arrays disagree in size or the range leaves them.
Expected<std::vector<uint8_t>> encode_level(const SurfelCodes& codes, uint64_t begin, uint64_t end);
// Decodes level k of prototype `p` (size E230) and appends its surfels to `out`, which must hold
// exactly the surfels of levels 0 .. k-1 (kInvalidArgument otherwise). Codes cannot be out of
// range: every code decodes to a value inside the box, a unit normal and a colour in [0, 1].
Status decode_level(std::span<const uint8_t> raw, const PrototypeRecord& p, uint32_t k,
                    SurfelArrays* out, const std::string& what);

// ---- Prefix size (§11.3.4, paper 001 Eq. 1; informative for players) ----

// The prefix length that covers the prototype's surface with discs of object-space radius r:
// ceil(p_m * (r_m / r)^2) in binary64, clamped to [1, N]; N for r <= 0 or NaN; 0 when N = 0.
uint32_t prefix_for_radius(const PrototypeRecord& p, double r);

}  // namespace calf::surfels
