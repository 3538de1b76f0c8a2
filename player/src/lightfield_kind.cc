// The lightfield kind's entry in the player table (kind_table.h).
#include "calf/player/lightfield_representation.h"
#include "kind_table.h"

namespace calf::player {

extern const PlayerKind kLightfieldPlayerKind = {
    .kind = container::TrackKind::kLightfield,
    .claims_tracks = false,
    .open = open_own_track<LightfieldRepresentation, LightfieldOptions>,
};

}  // namespace calf::player
