// The mesh track (kind 4, format/SPEC.md §11.4): a visible-set mesh (paper 004). This header
// holds what the frozen 1.0 file (tests/conformance/container/valid/v1_frozen.calf) fixed for
// the kind: its track header and stream tags. The chunk layouts, starting with the versioned
// index chunk (stream 0, SPEC.md §11 "Parameters of a kind"), belong to the visible-set issue
// and are appended here.
#pragma once

#include <cstdint>
#include <iterator>

#include "calf/format/container_types.h"

namespace calf::container {

// Stream tags (SPEC.md §11.4).
#define CALF_MESH_STREAMS(X) \
  X(kIndex, 0, "index")      \
  X(kVertices, 1, "vertices") X(kTriangles, 2, "triangles") X(kVisibility, 3, "visibility")
enum class MeshStream : uint16_t { CALF_MESH_STREAMS(CALF_STREAM_ENUM) };

// Track header (34 bytes), frozen in 1.0; later fields are appended.
struct MeshTrackHeader {
  static constexpr TrackKind kKind = TrackKind::kMesh;
  static constexpr const char* kStreamNames[] = {CALF_MESH_STREAMS(CALF_STREAM_NAME)};
  uint32_t frame_count = 1;
  uint32_t fps_numerator = 24;
  uint32_t fps_denominator = 1;
  uint64_t vertex_count = 0;
  uint64_t triangle_count = 0;
  uint32_t segment_count = 0;  // view-region perimeter segments
  uint16_t flags = 0;
  template <class Self, class V>
  static constexpr void fields(Self& s, V& v) {
    CALF_TRACK_TIMING_FIELDS(s, v);
    v(s.vertex_count, "vertex_count");
    v(s.triangle_count, "triangle_count");
    v(s.segment_count, "segment_count");
    v(s.flags, "flags");
  }
};
static_assert(fixed_size<MeshTrackHeader>() == 34);
static_assert(std::size(MeshTrackHeader::kStreamNames) ==
              static_cast<size_t>(MeshStream::kVisibility) + 1);

}  // namespace calf::container
