// Exporting a tile set (calf/format/tile_set.h: a decoded tiles track, format/SPEC.md §11.2) to
// the formats engines import: glTF 2.0 binary (.glb), glTF 2.0 with its buffer beside it (.gltf)
// and Wavefront OBJ (+ .mtl + the atlas as PNG). Like the mesh export (mesh_export.h), the scene
// is built as an assimp scene, written by tinygltf (glTF) or assimp's exporter (OBJ).
//
// What is written: one node ("calf tiles") with one mesh of all tiles, each tile two triangles
// (0, 1, 2), (0, 2, 3) as the tiles representation draws it (counter-clockwise seen from the view
// region's centre, so an engine's back-face culling keeps the side the tile faces), and one
// material "tiles atlas": the atlas as its base-colour texture (PNG, embedded in a .glb / .gltf,
// <stem>_atlas.png beside an .obj, also its map_d so OBJ importers take the alpha), alphaMode
// BLEND (or MASK: TilesExportOptions::alpha_cutoff), doubleSided false, base colour factor 1,
// metallic 0, unlit (KHR_materials_unlit: the atlas is baked radiance).
//
// Order: the tiles' triangles are written back to front from the view region's centre (farthest
// tile centre first, paper 000's fixed draw order), so an engine drawing the one blended mesh in
// index order, as rasterising engines do, composites the tiles as the tiles representation does
// from the centre.
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
// tile (a tile seen at a grazing angle), the texture shifts inside its triangles. Splitting each
// of a tile's two triangles into n x n (2 n^2 per tile), each new vertex at its exact projective
// coordinate, shrinks the shift roughly by n^2. By default each tile gets the smallest n (1 .. 16)
// whose shift, measured at the sub-triangles' centroids, is within target_texel_error; a fixed n
// applies to every tile. The largest shift written is reported (TilesExportStats).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "calf/export/mesh_export.h"
#include "calf/format/status.h"
#include "calf/format/tile_set.h"

namespace calf::exporter {

struct TilesExportOptions {
  // Each of a tile's two triangles split into subdivide x subdivide triangles: 1 .. 16 for every
  // tile, or 0 (the default) for each tile its own: the smallest n whose affine texture error is
  // at most target_texel_error (16 where none is). CALF-E482 above 16.
  uint32_t subdivide = 0;
  // With subdivide 0: the largest affine texture error a tile may keep, in atlas texels (> 0,
  // else CALF-E482).
  double target_texel_error = 1.0;
  // 0 (the default): alphaMode BLEND, the tiles composited in their back-to-front order. In
  // (0, 1): alphaMode MASK with this alphaCutoff (glTF's alpha test: a texel is drawn opaque
  // where its alpha >= the cutoff, else not at all), which needs no draw order but loses the
  // tiles' soft edges. Outside [0, 1): CALF-E482.
  double alpha_cutoff = 0;
  // How a .glb / .gltf stores the geometry (mesh_export.h; CALF-E480 for OBJ).
  GltfOptions gltf;
};

// A fixed subdivision whose largest affine texture error exceeds this many atlas texels is worth
// a warning: the default per-tile subdivision keeps it within 1.
inline constexpr double kTilesTexelErrorWarning = 2.0;

struct TilesExportStats {
  uint64_t tiles = 0;
  uint64_t triangles = 0;                         // 2 * n^2 for a tile split n x n
  uint32_t min_subdivide = 0, max_subdivide = 0;  // over tiles
  uint64_t vertices = 0;
  uint32_t atlas_width = 0, atlas_height = 0;
  // The largest distance, in atlas texels, between the affine texture coordinate a renderer of
  // the file uses and the exact projective one, at the centroid of every written triangle.
  double max_texel_error = 0;
};

// Exports `set` in `format`; side files are meant to be written as `<stem><suffix>` beside the
// main file (mesh_export.h's ExportedFile). Errors: CALF-E482 (an option out of range), CALF-E483
// (no tile, an empty atlas or one of another size than width * height * 4), CALF-E480 (a stem a
// .gltf / .obj cannot name its side files after), CALF-E481 (the glTF / OBJ writer or PNG
// encoding failed).
Expected<std::vector<ExportedFile>> export_tile_set(const TileSet& set, MeshExportFormat format,
                                                    const std::string& stem,
                                                    const TilesExportOptions& options = {},
                                                    TilesExportStats* stats = nullptr);

}  // namespace calf::exporter
