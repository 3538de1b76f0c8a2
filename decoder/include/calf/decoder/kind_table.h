// The decoder layer's table of track kinds: one entry per kind calf decodes, holding what the
// commands over this layer do with a track of that kind. calf-verify checks each track through
// its kind's entry (and prints the --decode conformance lines it returns), calf-info prints the
// entry's summary figures; neither names a kind. A kind the table lacks is skipped by both.
//
//   for (const auto& t : reader.tracks())
//     if (const DecoderKind* k = find_decoder_kind(t.record.kind)) k->verify(reader, t.id, ...);
//
// Adding a kind (after its line in format's CALF_TRACK_KINDS): its entry k<Name>DecoderKind in
// decoder/src/<kind>_kind.cc, built from the kind's <kind>_verify.h and layout header, and one
// line in the table (decoder/src/kind_table.cc), which sets where calf-verify's summary names it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/track_kinds.h"

namespace calf::decoder {

// A track checked by decoding all of it (the kind's verify_<kind>_track, <kind>_verify.h).
struct TrackVerification {
  // Layout problems, at most the max_problems asked for; an unopenable track is one problem.
  std::vector<Status> problems;
  // The conformance lines of what was decoded ("track T ... <16 hex digits>"), only when asked
  // for and only while no problem was found.
  std::vector<std::string> hash_lines;
  // What was decoded, counted as the kind's summary counts it (DecoderKind::verified_summary):
  // e.g. a lightfield track's faces, a surfels track's prototypes and surfels.
  uint64_t decoded[2] = {0, 0};
  // The track holds nothing to decode (no index chunk, SPEC §11): not a problem.
  bool skipped = false;
};

// One kind's decoded counts summed over the tracks of a file.
struct VerifiedTotals {
  uint64_t decoded[2] = {0, 0};
  uint64_t tracks = 0;  // tracks of the kind decoded (not skipped)
};

// A track's summary figures from the header and the directory alone (no chunk is read).
struct TrackFigures {
  std::string text;  // calf-info's line, without indentation or newline: "mesh: 3 objects, ..."
  std::string json;  // the same as one JSON object member: "\"mesh\":{...}"
};

struct DecoderKind {
  container::TrackKind kind;
  // Decodes track `track` of `reader` (of this kind) completely. Never fails as a call.
  // `max_problems` >= 1.
  TrackVerification (*verify)(const container::Reader& reader, uint16_t track, bool with_hashes,
                              size_t max_problems);
  // This kind's part of calf-verify's "ok" line for a file, from its totals: ", 12 faces
  // decoded"; "" when there is nothing to say.
  std::string (*verified_summary)(const VerifiedTotals& totals);
  // calf-info's figures of track `track` (of this kind); std::nullopt when the kind has none.
  std::optional<TrackFigures> (*figures)(const container::Reader& reader,
                                         const container::Track& track);
};

// Every kind the decoder layer knows, in the order calf-verify's "ok" line names them.
std::span<const DecoderKind* const> decoder_kinds();
// The entry of kind number `kind`, or nullptr for a kind the table lacks.
const DecoderKind* find_decoder_kind(uint16_t kind);

// Every registered kind's entry, k<Name>DecoderKind (defined in decoder/src/<kind>_kind.cc).
#define CALF_DECODER_KIND_ENTRY(Name, number, name, section) \
  extern const DecoderKind k##Name##DecoderKind;
CALF_TRACK_KINDS(CALF_DECODER_KIND_ENTRY)
#undef CALF_DECODER_KIND_ENTRY

}  // namespace calf::decoder
