// Exporting a mesh track (format/SPEC.md §11.4) to the formats engines import: glTF 2.0 binary
// (.glb), glTF 2.0 with its buffer beside it (.gltf + .bin) and Wavefront OBJ (+ .mtl). The scene
// is built as an assimp scene and written by a library (DESIGN.md: no hand-written glTF): glTF by
// tinygltf, OBJ by assimp's exporter, so a visible set computed by calf drops into Unity, Unreal,
// Blender or three.js.
//
// What is exported, at one frame of the track:
//   - one node per object, named "object <i>" (or "object <i>: <prototype i>"), carrying the
//     object's transform at that frame as its node matrix;
//   - one mesh per prototype that an object draws whole (objects sharing it share the mesh: glTF
//     instancing), and one mesh per object drawing a subset, holding only the vertices its
//     triangles use; positions at the frame's time when the prototype has vertex states;
//   - normals (the prototype's, or none: the importer computes flat ones), vertex colours
//     (linear, as COLOR_0), UVs (TEXCOORD_0 / vt) and materials (base colour, emission and the
//     base-colour texture as PNG: embedded in the glTF's binary buffer as its baseColorTexture, a
//     side file <stem>_texture<n>.png named by map_Kd beside an .obj; textures no material uses are
//     left out; a prototype without UVs placed with a textured material gets an untextured copy of
//     it, "material <i> untextured", as the renderers draw it untextured and glTF needs TEXCOORD_0
//     for a texture); triangles with a per-triangle material are split into one mesh per material,
//     as glTF primitives carry one material each. Only materials a mesh uses are written, and only
//     the extensions the file uses are declared;
//   - the renderers' lighting (calf/format/mesh_lighting.h), in a glTF: materials double-sided
//     and diffuse only (KHR_materials_specular, specularFactor 0), the key light as a
//     KHR_lights_punctual directional light of (1 - kMeshAmbient) * pi lux on a node of its own
//     (its -Z along -kMeshKeyLight), and the ambient share as the scene's extras
//     "calf_ambient_radiance": [kMeshAmbient x 3] (glTF has no ambient light).
// Triangle counts are preserved exactly: the export of a track whose objects draw T triangles in
// all holds T triangles; vertices are written as counted (MeshExportStats), never welded.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/format/status.h"

namespace calf::exporter {

enum class MeshExportFormat : uint8_t {
  kGlb,   // glTF 2.0 binary, one file (tinygltf)
  kGltf,  // glTF 2.0 JSON plus its binary buffer <stem>.bin (tinygltf): two files
  kObj,   // Wavefront OBJ plus its .mtl (assimp "obj"): two files
};

// The format named by a file extension (".glb", ".gltf", ".obj", any case), or an error
// (CALF-E480) naming the extension.
Expected<MeshExportFormat> mesh_export_format_from_path(const std::string& path);

// One file of an export: its name suffix ("" for the main file, ".bin" for a .gltf's buffer,
// ".mtl" for OBJ's material library, "_texture<n>.png" for an OBJ's textures) and its bytes.
struct ExportedFile {
  std::string suffix;
  std::vector<uint8_t> bytes;
};

// How a glTF export (.glb / .gltf) stores its geometry.
struct GltfOptions {
  // EXT_meshopt_compression (a required extension: loaders need a meshoptimizer decoder, e.g.
  // three.js's GLTFLoader.setMeshoptDecoder): vertex attributes and indices compressed
  // losslessly by meshoptimizer; images are stored as they are. CALF-E480 for OBJ.
  bool meshopt = false;
};

struct MeshExportStats {
  uint64_t objects = 0;    // nodes written
  uint64_t meshes = 0;     // meshes written (after splitting by material)
  uint64_t vertices = 0;   // over meshes
  uint64_t triangles = 0;  // over objects (instances counted each time)
  uint64_t textures = 0;   // textures written
};

// Exports `track` at `frame` (< frame_count, else CALF-E480) in `format`. The side files are
// meant to be written as `<stem><suffix>` beside the main file (stem: the main file's name
// without its extension), and the main file refers to them by those names. Errors: the track's
// decoding errors (naming the object or prototype), CALF-E480 for a frame out of range, an empty
// track or a stem of other characters than A-Z a-z 0-9 _ - . (for .gltf / .obj), CALF-E481 when
// the glTF or OBJ writer fails (assimp's message quoted), CALF-E480 for a glTF option with OBJ.
Expected<std::vector<ExportedFile>> export_mesh_track(const decoder::MeshTrack& track,
                                                      uint32_t frame, MeshExportFormat format,
                                                      const std::string& stem,
                                                      MeshExportStats* stats = nullptr,
                                                      const GltfOptions& gltf = {});

}  // namespace calf::exporter
