// The registry's per-kind tables, each generated from CALF_TRACK_KINDS (track_kinds.h).
#include "calf/format/track_registry.h"

#include <iterator>

namespace calf::container {

namespace {

// One row per registered kind: what the name, section and stream look-ups answer.
struct KindRow {
  uint16_t number;
  const char* name;
  const char* section;
  const char* const* streams;  // the header type's kStreamNames
  uint16_t stream_count;
};

constexpr KindRow kRows[] = {
#define CALF_TRACK_KIND_ROW(Name, number, name, section)   \
  {number, name, section, Name##TrackHeader::kStreamNames, \
   static_cast<uint16_t>(std::size(Name##TrackHeader::kStreamNames))},
    CALF_TRACK_KINDS(CALF_TRACK_KIND_ROW)
#undef CALF_TRACK_KIND_ROW
};

const KindRow* row(uint16_t kind) {
  for (const KindRow& r : kRows) {
    if (r.number == kind) return &r;
  }
  return nullptr;
}

}  // namespace

const char* track_kind_name(uint16_t kind) {
  const KindRow* r = row(kind);
  return r ? r->name : "unknown";
}

const char* track_kind_section(uint16_t kind) {
  const KindRow* r = row(kind);
  return r ? r->section : "";
}

uint16_t stream_count(uint16_t kind) {
  const KindRow* r = row(kind);
  return r ? r->stream_count : 0;
}

const char* stream_name(uint16_t kind, uint16_t stream) {
  const KindRow* r = row(kind);
  return r && stream < r->stream_count ? r->streams[stream] : "";
}

Expected<TrackHeader> read_track_header(uint16_t kind, std::span<const uint8_t> blob,
                                        const std::string& context) {
  switch (kind) {
#define CALF_TRACK_KIND_CASE(Name, number, name, section)                         \
  case number: {                                                                  \
    CALF_ASSIGN_OR_RETURN(Name##TrackHeader h,                                    \
                          decode_track_header<Name##TrackHeader>(blob, context)); \
    return TrackHeader(h);                                                        \
  }
    CALF_TRACK_KINDS(CALF_TRACK_KIND_CASE)
#undef CALF_TRACK_KIND_CASE
  }
  return TrackHeader();
}

Expected<std::vector<uint8_t>> write_track_header(const TrackHeader& header) {
  return std::visit(
      [](const auto& h) -> Expected<std::vector<uint8_t>> {
        if constexpr (std::is_same_v<std::decay_t<decltype(h)>, std::monostate>)
          return Status(ErrorId::kContainerWriterMisuse, "a track header of no known kind");
        else
          return encode_track_header(h);
      },
      header);
}

uint16_t track_header_kind(const TrackHeader& header) {
  return std::visit(
      [](const auto& h) -> uint16_t {
        if constexpr (std::is_same_v<std::decay_t<decltype(h)>, std::monostate>)
          return 0;
        else
          return static_cast<uint16_t>(std::decay_t<decltype(h)>::kKind);
      },
      header);
}

std::vector<FieldPrinter::Entry> print_track_header(const TrackHeader& header) {
  return std::visit(
      [](const auto& h) -> std::vector<FieldPrinter::Entry> {
        if constexpr (std::is_same_v<std::decay_t<decltype(h)>, std::monostate>)
          return {};
        else
          return print_fields(h);
      },
      header);
}

}  // namespace calf::container
