// The reference full-frame decoder of the lightfield track (format/SPEC.md §11.1): view v, face f,
// frame n -> linear RGB colour, log-16 depth codes and material codes, with no culling and no
// caching. It reads exactly the chunks SPEC §11.1 says a decoder needs (one t chunk and at most two
// keyframe chunks per cell, one region chunk per depth / material tile) and checks every count,
// rectangle and size against the chunk before use: a corrupt file gives CALF-E202, an unknown
// pixel format CALF-E203, never a crash. The fast view-dependent decoder is built on the same
// layout; this one is what it is tested against.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/status.h"

namespace calf::decoder {

// A view's index chunk (SPEC §11.1.3).
using LightfieldViewInfo = lf::ViewIndex;

// One decoded face. colour: face_size^2 * 3 linear floats (row-major); depth: face_size^2 codes;
// material: face_size^2 * 3 codes (reflect, refract, ior) or empty; coverage (a track with a
// coverage stream, SPEC §11.1.11): face_size^2 texels, else empty.
struct LightfieldFace {
  std::vector<float> colour;
  std::vector<uint16_t> depth;
  std::vector<uint8_t> material;
  std::vector<lf::CoverageTexel> coverage;
};

// Whether track `track` of `reader` holds a coverage stream: any chunk of stream 5 (SPEC
// §11.1.11). Then every view's faces carry coverage.
bool track_has_coverage(const container::Reader& reader, uint16_t track);

class LightfieldReference {
 public:
  // `reader` must outlive the decoder. A view whose index chunk is missing, repeated, damaged
  // (its hash fails: CALF-E058) or out of range is dropped, not fatal: view_problem() says why,
  // and the other views decode. Errors: kInvalidArgument (no such track, not lightfield),
  // kLightfieldFormat, and the first view's problem when every view is dropped.
  static Expected<LightfieldReference> open(const container::Reader& reader, uint16_t track);

  const container::LightfieldTrackHeader& header() const { return header_; }
  // The track has a coverage stream (SPEC §11.1.11): decode_face fills LightfieldFace::coverage.
  bool has_coverage() const { return has_coverage_; }
  // A dropped view's info is the default ViewIndex (position 0, no depth, no material).
  const LightfieldViewInfo& view(uint32_t v) const { return views_[v]; }
  // Ok for a usable view; for a dropped one, why its index chunk could not be used.
  const Status& view_problem(uint32_t v) const { return view_problems_[v]; }

  // Decodes view `view`, face `face` (GL order), frame `frame` into `out` (resized).
  // Errors: kInvalidArgument (index out of range), kLightfieldChunk, container errors, and a
  // dropped view's problem; with coverage kCoverageChunk, and kCoverageDepth for a texel whose
  // coverage contradicts its lossless depth (sky with cells farther than it).
  Status decode_face(uint32_t view, uint32_t face, uint32_t frame, LightfieldFace* out) const;

  // The interpolation weights and keyframes of one colour cell (its t chunk), for tests and tools.
  using CellTimeline = lf::CellTimeline;
  Expected<CellTimeline> cell_timeline(uint32_t view, uint32_t face, uint32_t cell) const;
  // The rectangle counts of every frame of one depth region (keyframes included), for tests.
  Expected<std::vector<uint32_t>> depth_rect_counts(uint32_t view, uint32_t face,
                                                    uint32_t tile) const;

 private:
  LightfieldReference() = default;
  Status read_view_index(uint32_t v);

  const container::Reader* reader_ = nullptr;
  uint16_t track_ = 0;
  container::LightfieldTrackHeader header_;
  bool has_coverage_ = false;
  std::vector<LightfieldViewInfo> views_;
  std::vector<Status> view_problems_;
};

}  // namespace calf::decoder
