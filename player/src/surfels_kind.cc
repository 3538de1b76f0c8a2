// The surfels kind's entry in the player table (kind_table.h).
#include "calf/player/surfel_representation.h"
#include "kind_table.h"

namespace calf::player {
namespace {

Expected<OpenedRepresentation> open(const container::Reader& reader, uint16_t track,
                                    const PlaybackOptions& options, RenderBackend backend,
                                    const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(
      std::unique_ptr<SurfelRepresentation> r,
      SurfelRepresentation::open(reader, track, options.of<SurfelOptions>(), backend, gl));
  OpenedRepresentation out;
  // It plays its paired mesh track too (near objects as meshes).
  out.claimed_tracks.push_back(r->mesh_track());
  out.representation = std::move(r);
  return out;
}

}  // namespace

extern const PlayerKind kSurfelsPlayerKind = {
    .kind = container::TrackKind::kSurfels,
    .claims_tracks = true,
    .open = open,
};

}  // namespace calf::player
