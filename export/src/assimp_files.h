// What every calf exporter shares (private to export/): an RGBA8 image as PNG bytes, and an
// assimp scene written into the files of an export (DESIGN.md: no hand-written glTF): glTF 2.0 by
// tinygltf (gltf_files.h), OBJ by assimp's exporter, the side files named after the output's stem.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <assimp/scene.h>

#include "calf/export/mesh_export.h"
#include "calf/format/status.h"

namespace calf::exporter {

// `rgba` (width * height * 4 bytes, row 0 at the top, unassociated alpha, sRGB) as PNG bytes.
// `what` names the image in errors (CALF-E481).
Expected<std::vector<uint8_t>> png_bytes(const uint8_t* rgba, uint32_t width, uint32_t height,
                                         const std::string& what);

// Appends `png` to `scene` as an embedded texture (assimp's "*<n>" path names it) and returns
// that path.
std::string embed_png(aiScene* scene, const std::vector<uint8_t>& png);

// Writes `scene` in `format` (glTF: write_gltf with `gltf`; OBJ: assimp's exporter): the main
// file first (suffix ""), then its side files (".bin", ".mtl"), each named after `stem` in the
// main file. CALF-E481 when the writer fails (assimp's message quoted), CALF-E480 for an OBJ with
// a glTF option set.
Expected<std::vector<ExportedFile>> write_scene(const aiScene& scene, MeshExportFormat format,
                                                const std::string& stem,
                                                const GltfOptions& gltf = {});

// CALF-E480 unless `stem` holds only A-Z a-z 0-9 _ - . (a .gltf / .obj names its side files
// after it; a .glb has none, so any stem passes).
Status check_stem(const std::string& stem, MeshExportFormat format);

}  // namespace calf::exporter
