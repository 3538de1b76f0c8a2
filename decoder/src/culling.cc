#include "calf/decoder/culling.h"

#include <algorithm>
#include <cmath>

namespace calf {

Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far) {
  const double u0 = rect.x, v0 = rect.y, u1 = rect.x + rect.width, v1 = rect.y + rect.height;
  const double us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
  const Vec3 axis = direction_from_face_coord({face, 0.5, 0.5});
  std::array<Vec3, 4> dirs;
  double min_cos = 1;
  for (int i = 0; i < 4; ++i) {
    dirs[i] = direction_from_texel_coord({face, us[i], vs[i]}, face_size);
    min_cos = std::min(min_cos, dot(dirs[i], axis));
  }
  // The cell point closest to the face centre has the largest cosine.
  const double half = face_size / 2.0;
  const double cu = std::clamp(half, u0, u1), cv = std::clamp(half, v0, v1);
  const double max_cos = dot(direction_from_texel_coord({face, cu, cv}, face_size), axis);
  const double near_axial = z_near * min_cos, far_axial = z_far * max_cos;
  std::array<Vec3, 4> n, f;
  for (int i = 0; i < 4; ++i) {
    const double c = dot(dirs[i], axis);
    n[i] = viewpoint + dirs[i] * (near_axial / c);
    f[i] = viewpoint + dirs[i] * (far_axial / c);
  }
  return Frustum(n, f);
}

namespace {

struct Search {
  const Vec3& viewpoint;
  CubeFace face;
  const FaceGrid& grid;
  double z_near, z_far;
  std::span<const Frustum> eyes;
  CullStats* stats;
  std::vector<uint32_t>* out;

  // The eyes (indices into `eyes`, among `candidates`) whose frustum meets `range`'s frustum.
  std::vector<uint32_t> meeting(const CellRange& range, const std::vector<uint32_t>& candidates) {
    const Frustum f =
        cell_frustum(viewpoint, face, grid.face_size(), grid.rect_of_cells(range), z_near, z_far);
    std::vector<uint32_t> hit;
    for (uint32_t e : candidates) {
      if (stats) ++stats->tests;
      if (frusta_intersect(eyes[e], f)) hit.push_back(e);  // eye planes first: they reject most
    }
    return hit;
  }

  void visit(uint32_t level, uint32_t ix, uint32_t iy, const std::vector<uint32_t>& candidates) {
    const CellRange r = grid.quadtree_node_cells(level, ix, iy);
    if (r.empty()) return;
    const std::vector<uint32_t> hit = meeting(r, candidates);
    if (hit.empty()) return;
    if (r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1) {  // one cell: a leaf, whatever its level
      out->push_back(grid.cell_index(r.x0, r.y0));
      return;
    }
    for (uint32_t c = 0; c < 4; ++c) visit(level + 1, 2 * ix + (c & 1), 2 * iy + (c >> 1), hit);
  }
};

}  // namespace

std::vector<uint32_t> visible_cells_hierarchical(const Vec3& viewpoint, CubeFace face,
                                                 const FaceGrid& grid, double z_near, double z_far,
                                                 std::span<const Frustum> eyes, uint32_t levels,
                                                 CullStats* stats) {
  std::vector<uint32_t> out;
  const uint32_t total = grid.quadtree_levels();
  if (levels == 0 || levels > total) levels = total;
  const uint32_t start = total - levels;
  std::vector<uint32_t> all_eyes(eyes.size());
  for (uint32_t e = 0; e < eyes.size(); ++e) all_eyes[e] = e;
  Search search{viewpoint, face, grid, z_near, z_far, eyes, stats, &out};
  for (uint32_t iy = 0; iy < (1u << start); ++iy) {
    for (uint32_t ix = 0; ix < (1u << start); ++ix) search.visit(start, ix, iy, all_eyes);
  }
  std::sort(out.begin(), out.end());
  if (stats) stats->visible_cells += out.size();
  return out;
}

std::vector<uint32_t> visible_cells_brute_force(const Vec3& viewpoint, CubeFace face,
                                                const FaceGrid& grid, double z_near, double z_far,
                                                std::span<const Frustum> eyes, CullStats* stats) {
  std::vector<uint32_t> out;
  for (uint32_t cy = 0; cy < grid.cells_per_side(); ++cy) {
    for (uint32_t cx = 0; cx < grid.cells_per_side(); ++cx) {
      const Frustum f =
          cell_frustum(viewpoint, face, grid.face_size(), grid.cell_rect(cx, cy), z_near, z_far);
      for (const Frustum& eye : eyes) {
        if (stats) ++stats->tests;
        if (frusta_intersect(eye, f)) {
          out.push_back(grid.cell_index(cx, cy));
          break;
        }
      }
    }
  }
  if (stats) stats->visible_cells += out.size();
  return out;
}

}  // namespace calf
