// The swatch kind's entry in the decoder table (decoder/include/calf/decoder/kind_table.h):
// verify reads the index and every frame's colour, calf-info counts the frames.
#include <fmt/core.h>

#include "calf/decoder/kind_table.h"
#include "calf/format/container_codec.h"
#include "calf/format/track_registry.h"

namespace calf::decoder {
namespace {

// decoded[0]: frames. A hash line per frame: the xxHash64 of its colour chunk's bytes.
TrackVerification verify(const container::Reader& reader, uint16_t track, bool with_hashes,
                         size_t max_problems) {
  TrackVerification out;
  const std::string name = "track " + std::to_string(track);
  container::ChunkQuery q;
  q.track = track;
  q.stream = static_cast<uint16_t>(container::SwatchStream::kIndex);
  const std::vector<uint32_t> index = reader.find_chunks(q);
  if (index.empty()) {
    out.skipped = true;
    return out;
  }
  Expected<std::vector<uint8_t>> raw = reader.read_chunk(index[0]);
  if (raw.ok()) {
    Expected<swatch::IndexChunk> parsed = swatch::parse<swatch::IndexChunk>(*raw, name + " index");
    if (!parsed.ok()) raw = parsed.status();
  }
  if (!raw.ok()) {
    out.problems.push_back(raw.status());
    return out;
  }
  const auto& header = std::get<container::SwatchTrackHeader>(reader.tracks()[track].header);
  std::vector<std::string> lines;
  for (uint32_t f = 0; f < header.frame_count && out.problems.size() < max_problems; ++f) {
    q.stream = static_cast<uint16_t>(container::SwatchStream::kColour);
    q.frame = f;
    const std::vector<uint32_t> ids = reader.find_chunks(q);
    const std::string what = fmt::format("{} frame {} colour", name, f);
    if (ids.size() != 1) {
      out.problems.push_back(Status(ErrorId::kInvalidArgument,
                                    fmt::format("{}: {} chunks, expected 1", what, ids.size())));
      continue;
    }
    Expected<std::vector<uint8_t>> colour = reader.read_chunk(ids[0]);
    if (colour.ok()) {
      Expected<swatch::ColourChunk> c = swatch::parse<swatch::ColourChunk>(*colour, what);
      if (!c.ok()) colour = c.status();
    }
    if (!colour.ok()) {
      out.problems.push_back(colour.status());
      continue;
    }
    ++out.decoded[0];
    lines.push_back(
        fmt::format("track {} swatch frame {} {:016x}", track, f, container::hash64(*colour)));
  }
  if (with_hashes && out.problems.empty()) out.hash_lines = std::move(lines);
  return out;
}

std::string verified_summary(const VerifiedTotals& totals) {
  return totals.tracks ? fmt::format(", {} swatch frames decoded", totals.decoded[0]) : "";
}

std::optional<TrackFigures> figures(const container::Reader& reader,
                                    const container::Track& track) {
  uint64_t chunks = 0;
  for (const auto& c : reader.chunks()) {
    if (c.keys.track == track.id &&
        c.keys.stream == static_cast<uint16_t>(container::SwatchStream::kColour))
      ++chunks;
  }
  return TrackFigures{fmt::format("swatch: {} colour chunks", chunks),
                      fmt::format("\"swatch\":{{\"colour_chunks\":{}}}", chunks)};
}

}  // namespace

extern const DecoderKind kSwatchDecoderKind = {
    .kind = container::TrackKind::kSwatch,
    .verify = verify,
    .verified_summary = verified_summary,
    .figures = figures,
};

}  // namespace calf::decoder
