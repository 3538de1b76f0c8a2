// The fixed lighting a mesh track's materials are shown under (docs/PLAYER.md): one definition
// that the player's mesh and surfel renderers shade with (calf/player/mesh_draw_list.h) and that
// calf-export writes into glTF files (calf/export/mesh_export.h), so an engine loading an export
// lights it as calf-play does.
//
// A surface point of colour c (base x texture x vertex colour) with unit normal n facing the eye
// shows c * (kMeshAmbient + (1 - kMeshAmbient) * max(0, n . kMeshKeyLight)) + emission: the
// Lambertian response to a uniform environment of radiance kMeshAmbient plus a directional light
// of illuminance (1 - kMeshAmbient) * pi arriving from kMeshKeyLight.
#pragma once

#include <array>

namespace calf::mesh {

// The fixed key light: a unit direction towards it in world space, (0.3, 0.8, 0.5) normalised.
inline constexpr std::array<float, 3> kMeshKeyLight = {0.30304576f, 0.80812204f, 0.50507627f};
// The ambient share of the shading (the rest is Lambert under the key light).
inline constexpr float kMeshAmbient = 0.3f;

}  // namespace calf::mesh
