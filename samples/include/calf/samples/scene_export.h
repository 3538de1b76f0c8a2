// Export of a sample scene as a scene file (format/SCENE.md), so that the builders of the mesh
// representations read the scene calf-capture rendered without linking samples/.
#pragma once

#include <cstdint>
#include <filesystem>

#include "calf/capture/scene_file.h"
#include "calf/format/status.h"
#include "calf/samples/scene.h"

namespace calf::samples {

// Converts `scene` over `frames` frames (frame f at time f / scene.fps): each object becomes one
// object and, unless it places a shared mesh already exported, one mesh (its triangles, spheres,
// UVs and vertex states, no normals: the tracer shades with face normals); a shared mesh is
// stored once, at its first object, named by TriangleMesh::name (else that object's name). An
// object's transform is sampled at every frame and stored once when every sample is the same
// (omitted when it is the identity throughout); lights are sampled likewise. Materials keep
// albedo (as base colour), their base-colour texture, emission and the mirror / glass weights;
// textures keep their sRGB8 pixels and scene-file path (textures/textureN.png when they have
// none), written as PNG by write_scene; the sky, sun and ambient terms go to the environment;
// the view region is the default rig's view volume.
// Errors: E177 when frames is 0 or above 1000000, then those of validate_scene_file (E157 for a
// non-finite transform sample, for instance).
Expected<capture::SceneFile> export_scene(const Scene& scene, uint32_t frames);

// export_scene, then capture::write_scene_file into `directory`.
Status write_scene(const Scene& scene, uint32_t frames, const std::filesystem::path& directory);

}  // namespace calf::samples
