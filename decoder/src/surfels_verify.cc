// Whole-track verification of a surfels track; the rules are in the public header.
#include "calf/decoder/surfels_verify.h"

#include <bit>
#include <cstdio>

#include "calf/decoder/mesh_track.h"
#include "calf/format/container_codec.h"

namespace calf::decoder {
namespace {

void put(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
void put_floats(std::vector<uint8_t>& out, const std::vector<float>& a) {
  for (float f : a) put(out, std::bit_cast<uint32_t>(f));
}

}  // namespace

uint64_t surfels_prototype_hash(const surfels::PrototypeRecord& r, const SurfelBuffer& s) {
  std::vector<uint8_t> b;
  b.reserve(16 + 36 * s.size());
  put(b, r.surfel_count);
  put(b, r.flags);
  put(b, r.prefix_count);
  put(b, std::bit_cast<uint32_t>(r.prefix_radius));
  put_floats(b, s.positions);
  put_floats(b, s.normals);
  put_floats(b, s.colours);
  return container::hash64(b);
}

SurfelsVerifyResult verify_surfels_track(const container::Reader& reader, uint16_t track,
                                         bool with_hashes, size_t max_problems) {
  SurfelsVerifyResult result;
  const std::string name = "track " + std::to_string(track);
  container::ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(container::SurfelsStream::kIndex);
  if (reader.find_chunks(q).empty()) {
    result.skipped = true;
    return result;
  }
  Expected<SurfelsTrack> t = SurfelsTrack::open(reader, track);
  if (!t.ok()) {
    result.problems.push_back(t.status().with_context(name));
    return result;
  }
  // The pairing: the mesh track must hold a representation with as many prototypes.
  Expected<MeshTrack> mesh = MeshTrack::open(reader, t->mesh_track());
  if (!mesh.ok()) {
    result.problems.push_back(
        Status(ErrorId::kSurfelsPairing,
               container::cat("its mesh track ", t->mesh_track(),
                              " cannot be opened: ", mesh.status().to_string()))
            .with_context(name));
  } else if (Status st = t->check_pairing(*mesh); !st.ok()) {
    result.problems.push_back(st.with_context(name));
  }
  SurfelBuffer s;
  for (uint32_t p = 0; p < t->prototype_count() && result.problems.size() < max_problems; ++p) {
    const Status st = t->prototype(p, &s);
    if (!st.ok()) {
      result.problems.push_back(st.with_context(name));
      continue;
    }
    ++result.prototypes_decoded;
    result.surfels_decoded += s.size();
    if (with_hashes) {
      char line[96];
      std::snprintf(line, sizeof line, "track %u surfels %u %016llx", unsigned{track}, p,
                    static_cast<unsigned long long>(surfels_prototype_hash(t->record(p), s)));
      result.hash_lines.push_back(line);
    }
  }
  if (!result.problems.empty()) result.hash_lines.clear();
  return result;
}

}  // namespace calf::decoder
