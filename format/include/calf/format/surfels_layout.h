// The surfels track (kind 3, format/SPEC.md §11.3): progressive surfels (paper 001). This header
// holds what the frozen 1.0 file (tests/conformance/container/valid/v1_frozen.calf) fixed for
// the kind: its track header and stream tags. The chunk layouts, starting with the versioned
// index chunk (stream 0, SPEC.md §11 "Parameters of a kind"), belong to the surfels issue and
// are appended here.
#pragma once

#include <cstdint>
#include <iterator>

#include "calf/format/container_types.h"

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
