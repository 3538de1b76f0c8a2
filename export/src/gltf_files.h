// An assimp scene written as glTF 2.0 by tinygltf (private to export/): assimp 5.2's own glTF
// exporter declares extensions it does not use and writes none calf needs (KHR_materials_unlit),
// so the exporters build one assimp scene and hand it to assimp for OBJ and to this writer for
// .glb / .gltf.
#pragma once

#include <string>
#include <vector>

#include <assimp/scene.h>

#include "calf/export/mesh_export.h"
#include "calf/format/status.h"

namespace calf::exporter {

// What the writer reads of `scene`:
//   - nodes: the root node and its children (one level), each with its matrix (identity omitted)
//     and its meshes, which become one glTF mesh of one primitive per aiMesh; nodes drawing the
//     same list of meshes share that glTF mesh;
//   - meshes: triangles (indices as unsigned 32-bit), positions, normals, the first colour set
//     (RGB), the first UV set (assimp's v up, written as glTF's v down: 1 - v);
//   - materials, written only when a mesh uses them: AI_MATKEY_NAME, AI_MATKEY_BASE_COLOR,
//     AI_MATKEY_COLOR_EMISSIVE (written when not black), the diffuse texture "*<n>" (the n-th
//     embedded texture, a PNG, stored in the binary buffer) with its sampler (wrap modes from
//     AI_MATKEY_MAPPINGMODE_U / _V: clamp or glTF's default repeat; filters from
//     AI_MATKEY_GLTF_MAPPINGFILTER_MAG / _MIN, else none), AI_MATKEY_GLTF_ALPHAMODE,
//     AI_MATKEY_TWOSIDED, AI_MATKEY_SHADING_MODEL aiShadingMode_Unlit as KHR_materials_unlit,
//     AI_MATKEY_SPECULAR_FACTOR (when not 1) as KHR_materials_specular's specularFactor;
//     metallic 0;
//   - lights: a directional light as a KHR_lights_punctual light (intensity: the largest
//     channel of its diffuse colour, in lux; colour: the diffuse colour over it) on a node of its
//     own among the scene's root nodes, rotated so that its -Z is the light's direction; an
//     ambient light as the scene's extras "calf_ambient_radiance": [r, g, b] (its ambient colour:
//     the radiance of a uniform environment; glTF has no ambient light); other lights are left out;
//   - extensionsUsed lists exactly the extensions the file uses.
// A .glb is one file; a .gltf is its JSON and the buffer as the side file "<stem>.bin" (suffix
// ".bin"). With options.meshopt, EXT_meshopt_compression (required): vertex attributes
// (mode ATTRIBUTES) and indices (mode TRIANGLES) compressed by meshoptimizer into buffer 0 (the
// GLB's binary chunk / <stem>.bin) beside the images, their views' own buffer being buffer 1, a
// fallback buffer without data. CALF-E481 when tinygltf or meshoptimizer fails.
Expected<std::vector<ExportedFile>> write_gltf(const aiScene& scene, MeshExportFormat format,
                                               const std::string& stem, const GltfOptions& options);

}  // namespace calf::exporter
