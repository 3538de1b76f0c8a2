// Reading a surfels track (kind 3, format/SPEC.md §11.3): per prototype of the clip's mesh track
// an ordered surfel buffer in object space, every prefix of which is a level of detail (paper
// 001). Instances share their prototype's surfels: a player draws mesh object o as a prefix of
// the buffer of o's prototype, placed by o's transform (decoder/mesh_track.h).
//
// The track is readable per prototype and per prefix: open() reads the index chunk only (and
// checks that every level chunk exists with its exact size); prototype() decodes a whole buffer,
// prefix() only the level chunks the first `count` surfels lie in (a far object's few hundred
// surfels cost one chunk of 13 bytes per surfel, not the whole buffer).
//
// Pairing (§11.3.5): the index names the mesh track it belongs to; open() checks that the track
// exists and is a mesh track, check_pairing() that it has as many prototypes (CALF-E232).
// The encoder side is encoder/surfels_encode.h; the conformance hashes surfels_verify.h.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/surfels_layout.h"

namespace calf::decoder {

class MeshTrack;

// Decoded surfels of one prototype: 3 floats each per surfel (object-space position, unit
// normal, linear RGB colour in [0, 1]), in prefix order. size() surfels.
using SurfelBuffer = surfels::SurfelArrays;

class SurfelsTrack {
 public:
  // Reads track `track`'s header and index chunk (stream 0) and checks the chunk index (SPEC
  // §11.3.5). `reader` must outlive the result. Errors: kInvalidArgument (no such track, not a
  // surfels track), the container's read errors, CALF-E230 - E234.
  static Expected<SurfelsTrack> open(const container::Reader& reader, uint16_t track);

  const container::SurfelsTrackHeader& header() const { return header_; }
  uint16_t track() const { return track_; }
  // The mesh track whose prototypes these surfels approximate (the index chunk's mesh_track).
  uint16_t mesh_track() const;
  uint32_t prototype_count() const;
  // Prototype p's record: surfel count N, flags (kColourIsBase), p_m, r_m and the quantisation
  // box, for figures and prefix sizes without decoding. p < prototype_count().
  const surfels::PrototypeRecord& record(uint32_t p) const;
  // The index chunk as read (format/surfels_layout.h).
  const surfels::IndexChunk& index() const;

  // CALF-E232 unless `mesh` is the track mesh_track() names and has prototype_count()
  // prototypes.
  Status check_pairing(const MeshTrack& mesh) const;

  // Decodes prototype p's whole buffer (empty for a prototype without surfels). Errors name the
  // chunk: the container's read errors, CALF-E230; kInvalidArgument for p out of range.
  Status prototype(uint32_t p, SurfelBuffer* out) const;
  // Decodes the first `count` surfels of prototype p (count <= N, else kInvalidArgument),
  // reading only the level chunks they lie in (surfels::level_count(count) of them).
  Status prefix(uint32_t p, uint32_t count, SurfelBuffer* out) const;

 private:
  SurfelsTrack() = default;
  const container::Reader* reader_ = nullptr;
  uint16_t track_ = 0;
  container::SurfelsTrackHeader header_;
  // The index chunk and the chunk id of every level of every prototype (owned by the
  // implementation).
  struct Index;
  std::shared_ptr<const Index> index_;
};

}  // namespace calf::decoder
