// The mesh kind's entry in the decoder table (kind_table.h).
#include <fmt/core.h>

#include "calf/decoder/kind_table.h"
#include "calf/decoder/mesh_verify.h"
#include "calf/format/mesh_layout.h"

namespace calf::decoder {
namespace {

// decoded[0]: prototypes, decoded[1]: objects.
TrackVerification verify(const container::Reader& reader, uint16_t track, bool with_hashes,
                         size_t max_problems) {
  MeshVerifyResult r = verify_mesh_track(reader, track, with_hashes, max_problems);
  TrackVerification out;
  out.problems = std::move(r.problems);
  out.hash_lines = std::move(r.hash_lines);
  out.decoded[0] = r.prototypes_decoded;
  out.decoded[1] = r.objects_decoded;
  out.skipped = r.skipped;
  return out;
}

std::string verified_summary(const VerifiedTotals& totals) {
  const uint64_t parts = totals.decoded[0] + totals.decoded[1];
  return parts ? fmt::format(", {} mesh prototypes and objects decoded", parts) : "";
}

// From the header and the directory (SPEC §11.4: one vertices chunk per prototype, one
// visibility chunk per object).
std::optional<TrackFigures> figures(const container::Reader& reader,
                                    const container::Track& track) {
  const auto* h = std::get_if<container::MeshTrackHeader>(&track.header);
  if (!h) return std::nullopt;
  uint64_t objects = 0, prototypes = 0;
  for (const auto& c : reader.chunks()) {
    if (c.keys.track != track.id) continue;
    if (c.keys.stream == static_cast<uint16_t>(container::MeshStream::kVisibility)) ++objects;
    if (c.keys.stream == static_cast<uint16_t>(container::MeshStream::kVertices)) ++prototypes;
  }
  const uint64_t triangles = h->triangle_count, vertices = h->vertex_count;
  return TrackFigures{
      fmt::format("mesh: {} objects, {} prototypes, {} triangles drawn, {} vertices stored",
                  objects, prototypes, triangles, vertices),
      fmt::format("\"mesh\":{{\"objects\":{},\"prototypes\":{},\"triangles\":{},\"vertices\":{}}}",
                  objects, prototypes, triangles, vertices)};
}

}  // namespace

extern const DecoderKind kMeshDecoderKind = {
    .kind = container::TrackKind::kMesh,
    .verify = verify,
    .verified_summary = verified_summary,
    .figures = figures,
};

}  // namespace calf::decoder
