// The mesh kind's entry in the player table (kind_table.h).
#include "calf/player/mesh_representation.h"
#include "kind_table.h"

namespace calf::player {
namespace {

Expected<OpenedRepresentation> open(const container::Reader& reader, uint16_t track,
                                    const PlaybackOptions& options, RenderBackend backend,
                                    const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<MeshRepresentation> r,
                        MeshRepresentation::open(reader, track, options.mesh, backend, gl));
  OpenedRepresentation out;
  out.representation = std::move(r);
  return out;
}

}  // namespace

extern const PlayerKind kMeshPlayerKind = {
    .kind = container::TrackKind::kMesh,
    .claims_tracks = false,
    .open = open,
};

}  // namespace calf::player
