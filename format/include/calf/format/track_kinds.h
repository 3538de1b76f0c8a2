// The one list of calf's track kinds (format/SPEC.md §6.1, §11). Like errors.h's error list, every
// per-kind table derives from it: the enum and names here, header types, stream names, header
// coding and printing in track_registry.h, the checks of tests/format/track_registry_test.cc.
// Adding a kind: docs/ARCHITECTURE.md, "Checklist: adding a track kind".
#ifdef CALF_EXTRA_TRACK_KINDS_HEADER    // a build's own kinds (tests/test_kind/), listed first
#include CALF_EXTRA_TRACK_KINDS_HEADER  // defines CALF_EXTRA_TRACK_KINDS(X)
#else
#define CALF_EXTRA_TRACK_KINDS(X)
#endif
#pragma once

#include <cstdint>

namespace calf::container {

// X(Name, number, "name", "SPEC section"). `Name` gives the enumerator k<Name>, the header type
// <Name>TrackHeader and the stream enum <Name>Stream. Numbers are stable forever; 0 is invalid.
#define CALF_TRACK_KINDS(X)              \
  CALF_EXTRA_TRACK_KINDS(X)              \
  X(Lightfield, 1, "lightfield", "11.1") \
  X(Tiles, 2, "tiles", "11.2")           \
  X(Surfels, 3, "surfels", "11.3")       \
  X(Mesh, 4, "mesh", "11.4")             \
  /* end of the list: every line above ends with a backslash */
// Track kinds (SPEC.md §6.1). A reader that meets another kind skips the track, unless the
// track is marked must-understand (kTrackRequired), then it refuses the file (CALF-E050).
enum class TrackKind : uint16_t {
#define CALF_TRACK_KIND_ENUM(Name, number, name, section) k##Name = number,
  CALF_TRACK_KINDS(CALF_TRACK_KIND_ENUM)
#undef CALF_TRACK_KIND_ENUM
};
inline constexpr uint16_t kTrackRequired = 1;  // TrackRecord::flags bit 0

// Every registered kind, in list order: for code and tests that walk the registry.
inline constexpr TrackKind kTrackKinds[] = {
#define CALF_TRACK_KIND_VALUE(Name, number, name, section) TrackKind::k##Name,
    CALF_TRACK_KINDS(CALF_TRACK_KIND_VALUE)
#undef CALF_TRACK_KIND_VALUE
};

// True for a kind in the list.
constexpr bool is_known_track_kind(uint16_t kind) {
  for (TrackKind k : kTrackKinds) {
    if (static_cast<uint16_t>(k) == kind) return true;
  }
  return false;
}

const char* track_kind_name(uint16_t kind);     // "lightfield", ..., "unknown"
const char* track_kind_section(uint16_t kind);  // "11.1", ..., "" (SPEC.md section)

// A kind's stream tags are declared in its layout header with the same X pattern:
//   #define CALF_LIGHTFIELD_STREAMS(X) X(kIndex, 0, "index") X(kColour, 1, "colour") ...
//   enum class LightfieldStream : uint16_t { CALF_LIGHTFIELD_STREAMS(CALF_STREAM_ENUM) };
//   static constexpr const char* kStreamNames[] = {CALF_LIGHTFIELD_STREAMS(CALF_STREAM_NAME)};
// Tags are dense from 0, and tag 0 is every kind's index chunk (SPEC.md §11).
#define CALF_STREAM_ENUM(Name, number, name) Name = number,
#define CALF_STREAM_NAME(Name, number, name) name,

}  // namespace calf::container
