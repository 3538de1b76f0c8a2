// Fuzz target: the surfels track reader (decoder/include/calf/decoder/surfels_track.h, SPEC
// §11.3) on arbitrary bytes. Opens them as a .calf file from memory, opens every surfels track,
// checks its pairing against the mesh track it names, decodes every prototype's whole buffer and
// a few prefixes, and computes prefix sizes for a few radii. Any crash, sanitizer report or hang
// is a bug; errors are expected. Seeded with a small surfels clip and damaged copies whose chunks
// are stored uncompressed (written by tests/integration/surfels_track_test.cc's generator), so
// that mutations reach the track's parsers rather than only the container's hashes.
#include <cstddef>
#include <cstdint>
#include <span>

#include "calf/decoder/mesh_track.h"
#include "calf/decoder/surfels_track.h"
#include "calf/format/container.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf;
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  for (uint16_t t = 0; t < r->tracks().size(); ++t) {
    auto track = decoder::SurfelsTrack::open(*r, t);
    if (!track.ok()) continue;
    auto mesh = decoder::MeshTrack::open(*r, track->mesh_track());
    if (mesh.ok()) (void)track->check_pairing(*mesh).ok();
    decoder::SurfelBuffer b;
    // Chunk sizes bound every count (13 bytes a surfel, <= 1 GiB raw per chunk); cap the work per
    // input anyway.
    for (uint32_t p = 0; p < track->prototype_count() && p < 64; ++p) {
      const auto& rec = track->record(p);
      for (double radius : {-1.0, 0.0, 1e-30, 0.01, 1.0, 1e30})
        (void)surfels::prefix_for_radius(rec, radius);
      if (rec.surfel_count > (1u << 20)) continue;
      (void)track->prototype(p, &b).ok();
      (void)track->prefix(p, rec.surfel_count / 2, &b).ok();
      (void)track->prefix(p, rec.surfel_count + 1, &b).ok();
    }
    (void)track->prototype(track->prototype_count(), &b).ok();
  }
  return 0;
}
