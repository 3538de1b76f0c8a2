// View-dependent culling (paper 002, Sec. 6.2): which cells of a viewpoint's cube map can be seen
// by any viewer, tested hierarchically on a per-face quadtree.
//
// A cell's frustum is the truncated pyramid with its apex at the viewpoint, its sides through the
// cell's corner directions, cut by planes parallel to the face at the nearest and farthest axial
// distances any texel of the cell can have given the view's radial depth range [z_near, z_far]:
// near = z_near * (smallest cosine between a cell direction and the face axis, at a corner),
// far = z_far * (largest cosine, at the cell point closest to the face centre). It therefore
// contains every point the cell's texels can stand for (the paper places the caps at z_near and
// z_far, which clips the corners of wide cells). Cells holding sky need a finite far: pass the
// distance beyond which nothing matters to the viewer (e.g. its far plane plus the distance
// between eye and viewpoint).
//
// Frusta and their intersection test are calf/format/geometry.h (shared with the encoder's
// builders). A quadtree node's frustum contains its children's, so a node separated from every
// viewer has no visible cell below it, and the hierarchical search returns exactly the
// brute-force set.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/grid.h"

namespace calf {

// The frustum of texel rectangle `rect` of `face` on a cube map of `face_size` texels centred at
// `viewpoint`, for radial depths [z_near, z_far] (0 < z_near < z_far, finite).
Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far);

// Counts of frustum-frustum tests, for Table 4 of the paper.
struct CullStats {
  uint64_t tests = 0;
  uint64_t visible_cells = 0;
};

// The cells of `face` (indices in `grid`, increasing) whose frustum meets at least one eye
// frustum, by descending the face quadtree from the root down to `levels` levels (1 = test every
// cell directly; 0 or more than grid.quadtree_levels() = all levels). Adds to `stats`.
std::vector<uint32_t> visible_cells_hierarchical(const Vec3& viewpoint, CubeFace face,
                                                 const FaceGrid& grid, double z_near, double z_far,
                                                 std::span<const Frustum> eyes, uint32_t levels,
                                                 CullStats* stats);

// The same set by testing every cell against every eye: the reference the hierarchical search is
// tested against.
std::vector<uint32_t> visible_cells_brute_force(const Vec3& viewpoint, CubeFace face,
                                                const FaceGrid& grid, double z_near, double z_far,
                                                std::span<const Frustum> eyes, CullStats* stats);

}  // namespace calf
