// The lightfield kind's entry in the player table (kind_table.h).
#include "calf/player/lightfield_representation.h"
#include "kind_table.h"

namespace calf::player {
namespace {

Expected<OpenedRepresentation> open(const container::Reader& reader, uint16_t track,
                                    const PlaybackOptions& options, RenderBackend backend,
                                    const GlFunctions* gl) {
  CALF_ASSIGN_OR_RETURN(
      std::unique_ptr<LightfieldRepresentation> r,
      LightfieldRepresentation::open(reader, track, options.lightfield, backend, gl));
  OpenedRepresentation out;
  out.representation = std::move(r);
  return out;
}

}  // namespace

extern const PlayerKind kLightfieldPlayerKind = {
    .kind = container::TrackKind::kLightfield,
    .claims_tracks = false,
    .open = open,
};

}  // namespace calf::player
