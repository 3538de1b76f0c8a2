// The lightfield kind's entry in the decoder table (kind_table.h).
#include <fmt/core.h>

#include "calf/decoder/kind_table.h"
#include "calf/decoder/lightfield_verify.h"

namespace calf::decoder {
namespace {

// decoded[0]: faces.
TrackVerification verify(const container::Reader& reader, uint16_t track, bool with_hashes,
                         size_t max_problems) {
  LightfieldVerifyResult r = verify_lightfield_track(reader, track, with_hashes, max_problems);
  TrackVerification out;
  out.problems = std::move(r.problems);
  for (const FaceHash& h : r.hashes) out.hash_lines.push_back(face_hash_line(track, h));
  out.decoded[0] = r.faces_decoded;
  return out;
}

// Named when a lightfield track was decoded, even one of no faces.
std::string verified_summary(const VerifiedTotals& totals) {
  return totals.tracks ? fmt::format(", {} faces decoded", totals.decoded[0]) : "";
}

}  // namespace

extern const DecoderKind kLightfieldDecoderKind = {
    .kind = container::TrackKind::kLightfield,
    .verify = verify,
    .verified_summary = verified_summary,
    .figures = nullptr,  // calf-info's header fields say it all
};

}  // namespace calf::decoder
