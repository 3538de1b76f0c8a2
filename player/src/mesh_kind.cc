// The mesh kind's entry in the player table (kind_table.h).
#include "calf/player/mesh_representation.h"
#include "kind_table.h"

namespace calf::player {

extern const PlayerKind kMeshPlayerKind = {
    .kind = container::TrackKind::kMesh,
    .claims_tracks = false,
    .open = open_own_track<MeshRepresentation, MeshOptions>,
};

}  // namespace calf::player
