// The tiles kind's entry in the player table (kind_table.h).
#include "calf/player/tiles_representation.h"
#include "kind_table.h"

namespace calf::player {
namespace {

Expected<OpenedRepresentation> open(const container::Reader& reader, uint16_t track,
                                    const PlaybackOptions& options, RenderBackend backend,
                                    const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<TilesRepresentation> r,
                        TilesRepresentation::open(reader, track, options.tiles, backend, gl));
  OpenedRepresentation out;
  out.representation = std::move(r);
  return out;
}

}  // namespace

extern const PlayerKind kTilesPlayerKind = {
    .kind = container::TrackKind::kTiles,
    .claims_tracks = false,
    .open = open,
};

}  // namespace calf::player
