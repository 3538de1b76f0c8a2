// The surfels kind's entry in the decoder table (kind_table.h).
#include <fmt/core.h>

#include "calf/decoder/kind_table.h"
#include "calf/decoder/surfels_verify.h"
#include "calf/format/surfels_layout.h"

namespace calf::decoder {
namespace {

// decoded[0]: prototypes, decoded[1]: surfels.
TrackVerification verify(const container::Reader& reader, uint16_t track, bool with_hashes,
                         size_t max_problems) {
  SurfelsVerifyResult r = verify_surfels_track(reader, track, with_hashes, max_problems);
  TrackVerification out;
  out.problems = std::move(r.problems);
  out.hash_lines = std::move(r.hash_lines);
  out.decoded[0] = r.prototypes_decoded;
  out.decoded[1] = r.surfels_decoded;
  out.skipped = r.skipped;
  return out;
}

std::string verified_summary(const VerifiedTotals& totals) {
  return totals.decoded[0] ? fmt::format(", {} surfel prototypes ({} surfels) decoded",
                                         totals.decoded[0], totals.decoded[1])
                           : "";
}

// From the header and the directory (SPEC §11.3: the header's prototype and surfel counts; level
// chunks are stream 1, region = prototype).
std::optional<TrackFigures> figures(const container::Reader& reader,
                                    const container::Track& track) {
  const auto* h = std::get_if<container::SurfelsTrackHeader>(&track.header);
  if (!h) return std::nullopt;
  const uint64_t prototypes = h->object_count, surfels = h->surfel_count;
  uint64_t with_surfels = 0, stored = 0;
  for (const auto& c : reader.chunks()) {
    if (c.keys.track != track.id ||
        c.keys.stream != static_cast<uint16_t>(container::SurfelsStream::kSurfels))
      continue;
    stored += c.stored_size;
    if (c.keys.layer == 0) ++with_surfels;
  }
  const double per_surfel =
      surfels ? static_cast<double>(stored) / static_cast<double>(surfels) : 0.0;
  return TrackFigures{
      fmt::format("surfels: {} prototypes ({} with surfels), {} surfels, {} stored bytes, {:.3f} "
                  "bytes per surfel",
                  prototypes, with_surfels, surfels, stored, per_surfel),
      fmt::format("\"surfels\":{{\"prototypes\":{},\"with_surfels\":{},\"surfels\":{},"
                  "\"stored_bytes\":{},\"bytes_per_surfel\":{:.3f}}}",
                  prototypes, with_surfels, surfels, stored, per_surfel)};
}

}  // namespace

extern const DecoderKind kSurfelsDecoderKind = {
    .kind = container::TrackKind::kSurfels,
    .verify = verify,
    .verified_summary = verified_summary,
    .figures = figures,
};

}  // namespace calf::decoder
