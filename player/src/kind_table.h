// The player layer's table of track kinds: one entry per kind calf plays, holding how to open
// the kind's representation (representation.h) for a track and which other tracks that
// representation plays too. Playback::open (playback.cc) walks the clip's tracks through it and
// names no kind; a kind the table lacks is not played.
//
// Adding a kind (after its line in format's CALF_TRACK_KINDS): its representation, its entry
// k<Name>PlayerKind in player/src/<kind>_kind.cc, and one line in the table (kind_table.cc).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "calf/format/container.h"
#include "calf/format/status.h"
#include "calf/format/track_kinds.h"
#include "calf/player/gl_context.h"
#include "calf/player/playback.h"
#include "calf/player/representation.h"

namespace calf::player {

// A representation opened for one track, and the other tracks it plays (a surfels track's
// paired mesh track): those are not opened on their own.
struct OpenedRepresentation {
  std::unique_ptr<Representation> representation;
  std::vector<uint16_t> claimed_tracks;
};

struct PlayerKind {
  container::TrackKind kind;
  // Opened in a first pass over the tracks, before every kind without it, so that the tracks it
  // claims are known when the others are opened. Its representations come first in the
  // composite and the first one sets the clip's timeline.
  bool claims_tracks;
  // Opens the representation of track `track` (of this kind) with the kind's options.
  Expected<OpenedRepresentation> (*open)(const container::Reader& reader, uint16_t track,
                                         const PlaybackOptions& options, RenderBackend backend,
                                         const GlFunctions* gl);
};

// The `open` of a kind whose representation R plays its own track only, with its options of
// type O: R::open(reader, track, options.of<O>(), backend, gl).
template <class R, class O>
Expected<OpenedRepresentation> open_own_track(const container::Reader& reader, uint16_t track,
                                              const PlaybackOptions& options, RenderBackend backend,
                                              const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<R> r, R::open(reader, track, options.of<O>(), backend, gl));
  OpenedRepresentation out;
  out.representation = std::move(r);
  return out;
}

// Every kind the player plays, in table order.
std::span<const PlayerKind* const> player_kinds();
// The entry of kind number `kind`, or nullptr for a kind the player does not play.
const PlayerKind* find_player_kind(uint16_t kind);

// Every registered kind's entry, k<Name>PlayerKind (defined in player/src/<kind>_kind.cc).
#define CALF_PLAYER_KIND_ENTRY(Name, number, name, section) \
  extern const PlayerKind k##Name##PlayerKind;
CALF_TRACK_KINDS(CALF_PLAYER_KIND_ENTRY)
#undef CALF_PLAYER_KIND_ENTRY

}  // namespace calf::player
