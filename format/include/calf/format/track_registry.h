// The per-kind tables of the track registry (track_kinds.h holds the list): each kind's header
// type and stream names, header coding and printing by kind number, instead of a switch per kind.
//   CALF_ASSIGN_OR_RETURN(TrackHeader h, read_track_header(record.kind, record.header, "track 2"));
//   if (const auto* lf = std::get_if<LightfieldTrackHeader>(&h)) ...
//   for (const auto& e : print_track_header(h)) ...   // calf-info's lines
#ifdef CALF_EXTRA_TRACK_LAYOUT  // a build's own kind's layout (docs/ARCHITECTURE.md)
#include CALF_EXTRA_TRACK_LAYOUT
#endif
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/container_types.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/mesh_layout.h"
#include "calf/format/status.h"
#include "calf/format/surfels_layout.h"
#include "calf/format/tiles_layout.h"
#include "calf/format/track_kinds.h"

namespace calf::container {

// A decoded track header of any registered kind; std::monostate for a kind the list lacks.
#define CALF_TRACK_HEADER_TYPE(Name, number, name, section) , Name##TrackHeader
using TrackHeader = std::variant<std::monostate CALF_TRACK_KINDS(CALF_TRACK_HEADER_TYPE)>;
#undef CALF_TRACK_HEADER_TYPE

// The name of a stream tag within a track kind ("colour", "depth", ...), or "" if unnamed.
const char* stream_name(uint16_t kind, uint16_t stream);
// The number of named stream tags of a kind (tags 0 ... count - 1); 0 for an unknown kind.
uint16_t stream_count(uint16_t kind);

// Decodes the header blob of a track of kind `kind` (decode_track_header of its type): too
// short or a value below its minimum is kContainerTrackHeader, above its maximum kContainerLimit,
// each message starting with `context`. A kind the list lacks gives std::monostate (the caller
// decides whether that is allowed: the reader refuses it for a must-understand track).
Expected<TrackHeader> read_track_header(uint16_t kind, std::span<const uint8_t> blob,
                                        const std::string& context);
// Encodes a header (kContainerWriterMisuse for a value out of range or for std::monostate).
Expected<std::vector<uint8_t>> write_track_header(const TrackHeader& header);
// The kind number of a header; 0 for std::monostate.
uint16_t track_header_kind(const TrackHeader& header);
// The header's fields as (name, value) pairs, in declaration order (none for std::monostate):
// what calf-info prints for a track.
std::vector<FieldPrinter::Entry> print_track_header(const TrackHeader& header);

}  // namespace calf::container
