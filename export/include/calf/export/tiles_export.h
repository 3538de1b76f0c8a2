// Exporting a tile set (calf/format/tile_set.h: a decoded tiles track, format/SPEC.md §11.2) to
// the formats engines import: glTF 2.0 binary (.glb), glTF 2.0 with its buffer beside it (.gltf)
// and Wavefront OBJ (+ .mtl + the atlas as PNG). Like the mesh export (mesh_export.h), the scene
// is built as an assimp scene and written by assimp's own exporters, not by hand.
//
// What is written: one node ("calf tiles") with one mesh of all tiles, each tile two triangles
// (0, 1, 2), (0, 2, 3) as the tiles representation draws it (counter-clockwise seen from the view
// region's centre, so an engine's back-face culling keeps the side the tile faces), and one
// material "tiles atlas": the atlas as its base-colour texture (PNG, embedded in a .glb / .gltf,
// <stem>_atlas.png beside an .obj), alphaMode BLEND, doubleSided false, base colour factor 1,
// metallic 0 (unlit shading is requested, but assimp 5.2.5 does not write KHR_materials_unlit:
// docs/EXPORT.md).
//
// Colour: the atlas is premultiplied (tile_set.h); glTF's BLEND and PNG expect straight alpha, so
// each texel's colour is divided by its alpha (round(c * 255 / a), at most 255; colour 0 where a is
// 0), in the sRGB-encoded bytes the atlas premultiplied in. An engine drawing the file blends
// `src.a * src.rgb + (1 - src.a) * dst`, which is the tiles representation's blend up to that
// rounding.
//
// Texture mapping: a tile carries projective coordinates (U, V, W) per corner; glTF (and OBJ)
// have only 2-D texture coordinates, interpolated affinely over each triangle. The export writes
// (U / W, V / W) per vertex, exact at the vertices, affine inside: where W differs across a
// tile (a tile seen at a grazing angle), the texture shifts by up to a few texels inside its
// triangles. `subdivide` n splits each of a tile's two triangles into n x n triangles (2 n^2 per
// tile), each new vertex at its exact projective coordinate, which bounds the shift; the largest
// shift measured at the sub-triangles' centroids is reported (TilesExportStats). Engines then
// draw each tile in any order: sorting back to front is the engine's transparent-queue's job.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calf/export/mesh_export.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"

namespace calf::exporter {

struct TilesExportOptions {
  // Each of a tile's two triangles split into subdivide x subdivide triangles: 1 .. 16
  // (CALF-E482 otherwise).
  uint32_t subdivide = 1;
};

struct TilesExportStats {
  uint64_t tiles = 0;
  uint64_t triangles = 0;  // 2 * subdivide^2 per tile
  uint64_t vertices = 0;
  uint32_t atlas_width = 0, atlas_height = 0;
  // The largest distance, in atlas texels, between the affine texture coordinate a renderer of
  // the file uses and the exact projective one, at the centroid of every written triangle.
  double max_texel_error = 0;
};

// Exports `set` in `format`; side files are meant to be written as `<stem><suffix>` beside the
// main file (mesh_export.h's ExportedFile). Errors: CALF-E482 (subdivide out of range), CALF-E483
// (no tile, an empty atlas or one of another size than width * height * 4), CALF-E480 (a stem a
// .gltf / .obj cannot name its side files after), CALF-E481 (assimp's exporter or PNG encoding
// failed).
Expected<std::vector<ExportedFile>> export_tile_set(const TileSet& set, MeshExportFormat format,
                                                    const std::string& stem,
                                                    const TilesExportOptions& options = {},
                                                    TilesExportStats* stats = nullptr);

}  // namespace calf::exporter
