// The tiles kind's entry in the player table (kind_table.h).
#include "calf/player/tiles_representation.h"
#include "kind_table.h"

namespace calf::player {

extern const PlayerKind kTilesPlayerKind = {
    .kind = container::TrackKind::kTiles,
    .claims_tracks = false,
    .open = open_own_track<TilesRepresentation, TilesOptions>,
};

}  // namespace calf::player
