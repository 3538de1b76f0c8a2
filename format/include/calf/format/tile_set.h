// A tile set: layered quad tiles with an RGBA atlas (paper 000, Seurat), in memory. It is what the
// tiles builder produces (calf/encoder/tiles_build.h), what the tiles track stores (SPEC.md §11.2,
// calf/format/tiles_layout.h) and decodes back to (calf/decoder/tiles_track.h), what the tiles
// representation draws (calf/player/tiles_representation.h) and what calf-export writes.
//
// Geometry: each tile is one planar quad in scene space, drawn as the two triangles (0, 1, 2) and
// (0, 2, 3). Seurat's tiles are cells of a cube face's quadtree seen from the view region's centre,
// projected onto a plane, so a tile's texture is mapped projectively: corner i carries the
// homogeneous texture coordinate uvw[i] = (u_i w_i, v_i w_i, w_i) with w_i > 0, the texture
// coordinate at a point of the quad is (U / W, V / W) of the perspective-correct interpolation of
// (U, V, W) (in GL: pass the three as a varying and divide per fragment). With every w_i = 1 this
// is ordinary affine texturing. (u, v) are in [0, 1] over the whole atlas, u to the right, v down
// (v = 0 at the atlas's top row, row 0 of `atlas_rgba`), and stay inside the tile's own atlas
// rectangle, so bilinear filtering at its border must clamp to that rectangle (the builder pads
// each rectangle by one texel to make that unnecessary for nearest and bilinear filtering).
//
// Colour: the atlas is RGBA8, RGB sRGB-encoded, alpha linear coverage, RGB premultiplied by alpha
// after sRGB encoding (what the premultiplied blend `out = src + (1 - src.a) dst` expects of an
// 8-bit atlas; the decoder of a renderer converts to linear after the blend inputs are read, see
// the tiles representation). Radiance above 1 is clamped (an 8-bit atlas, like Seurat's).
//
// Order: tiles carry no order; a renderer sorts them back to front for the eye each frame
// (by distance from the eye to the tile's centre), or draws them in any order with a depth test
// and alpha to coverage.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "calf/format/geometry.h"

namespace calf {

struct TileCorner {
  std::array<float, 3> position;  // scene space
  std::array<float, 3> uvw;       // (u w, v w, w), w > 0; see above
};

struct Tile {
  // Counter-clockwise seen from the view region's centre (the side the tile faces).
  std::array<TileCorner, 4> corners;
};

struct TileSet {
  // The view region the set was built for (the capture set's view volume): outside it the tiles
  // show holes and stretched texels.
  Box3 view_volume;
  std::vector<Tile> tiles;
  uint32_t atlas_width = 0, atlas_height = 0;
  // atlas_width * atlas_height * 4 bytes, row-major from the top row, RGBA (see above).
  std::vector<uint8_t> atlas_rgba;
};

}  // namespace calf
