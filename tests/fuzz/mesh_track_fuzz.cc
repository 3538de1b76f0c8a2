// Fuzz target: the mesh track reader (decoder/include/calf/decoder/mesh_track.h, SPEC §11.4) on
// arbitrary bytes. Opens them as a .calf file from memory, opens every mesh track and decodes
// every prototype and object it claims, then the states at a few times and every transform. Any
// crash, sanitizer report or hang is a bug; errors are expected. Seeded with the mesh conformance
// clips (tests/conformance/mesh/) and copies whose chunks are stored uncompressed, so that
// mutations reach the track's parsers rather than only the container's hashes.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/format/container.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf;
  auto r = container::Reader::open(container::memory_source(std::span<const uint8_t>(data, size)));
  if (!r.ok()) return 0;
  for (uint16_t t = 0; t < r->tracks().size(); ++t) {
    auto track = decoder::MeshTrack::open(*r, t);
    if (!track.ok()) continue;
    decoder::MeshPrototype p;
    std::vector<float> at;
    // Chunk sizes bound every count (<= 1 GiB raw per chunk); cap the work per input anyway.
    for (uint32_t i = 0; i < track->prototype_count() && i < 64; ++i) {
      if (!track->prototype(i, &p).ok()) continue;
      for (double time : {-1.0, 0.0, 0.03, 1e9}) decoder::positions_at(p, time, &at);
    }
    decoder::MeshObject o;
    for (uint32_t i = 0; i < track->object_count() && i < 256; ++i) {
      if (!track->object(i, &o).ok()) continue;
      for (uint32_t f = 0; f < 4; ++f) (void)decoder::transform_at(o, f);
    }
    (void)track->object(track->object_count(), &o).ok();
    (void)track->prototype(track->prototype_count(), &p).ok();
  }
  return 0;
}
