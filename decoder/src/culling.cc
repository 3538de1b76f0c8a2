#include "calf/decoder/culling.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace calf {
namespace {

Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
Vec3 add(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
Vec3 scale(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 from_direction(const Direction& d) {
  return {d.x, d.y, d.z};
}

// Whether the projections of both corner sets onto `axis` are disjoint by more than a tolerance
// relative to their extent (so touching or rounding-level gaps count as intersecting).
bool separated_on(const Vec3& axis, const Frustum& a, const Frustum& b) {
  double a_min = INFINITY, a_max = -INFINITY, b_min = INFINITY, b_max = -INFINITY;
  for (const Vec3& p : a.corners()) {
    const double d = dot(axis, p);
    a_min = std::min(a_min, d);
    a_max = std::max(a_max, d);
  }
  for (const Vec3& p : b.corners()) {
    const double d = dot(axis, p);
    b_min = std::min(b_min, d);
    b_max = std::max(b_max, d);
  }
  const double extent =
      std::max({std::fabs(a_min), std::fabs(a_max), std::fabs(b_min), std::fabs(b_max)});
  const double tolerance = 1e-12 * extent;
  return a_max < b_min - tolerance || b_max < a_min - tolerance;
}

}  // namespace

Frustum::Frustum(const std::array<Vec3, 4>& n, const std::array<Vec3, 4>& f) {
  for (int i = 0; i < 4; ++i) {
    corners_[i] = n[i];
    corners_[4 + i] = f[i];
  }
  // Side faces i: near i, near i+1, far i. Caps: near plane and far plane.
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    normals_[i] = cross(sub(n[j], n[i]), sub(f[i], n[i]));
    edges_[i] = sub(f[i], n[i]);
  }
  normals_[4] = cross(sub(n[1], n[0]), sub(n[3], n[0]));
  normals_[5] = cross(sub(f[1], f[0]), sub(f[3], f[0]));
  edges_[4] = sub(n[1], n[0]);
  edges_[5] = sub(n[3], n[0]);
  // Orient every normal inward (toward the centroid) and keep the plane offsets, for the cheap
  // "a corner of one lies inside the other" proof of intersection.
  Vec3 centroid;
  for (const Vec3& c : corners_) centroid = add(centroid, scale(c, 1.0 / 8));
  const Vec3 on_face[6] = {n[0], n[1], n[2], n[3], n[0], f[0]};
  for (int i = 0; i < 6; ++i) {
    if (dot(normals_[i], sub(centroid, on_face[i])) < 0) normals_[i] = scale(normals_[i], -1);
    offsets_[i] = dot(normals_[i], on_face[i]);
  }
}

bool Frustum::contains(const Vec3& p) const {
  for (int i = 0; i < 6; ++i) {
    if (dot(normals_[i], p) < offsets_[i]) return false;
  }
  return true;
}

bool frusta_intersect(const Frustum& a, const Frustum& b) {
  for (const Vec3& axis : a.face_normals()) {
    if (separated_on(axis, a, b)) return false;
  }
  for (const Vec3& axis : b.face_normals()) {
    if (separated_on(axis, a, b)) return false;
  }
  // A shared point settles it without the 36 edge-pair axes (the costly part for visible cells).
  for (const Vec3& p : a.corners()) {
    if (b.contains(p)) return true;
  }
  for (const Vec3& p : b.corners()) {
    if (a.contains(p)) return true;
  }
  for (const Vec3& ea : a.edge_directions()) {
    for (const Vec3& eb : b.edge_directions()) {
      const Vec3 axis = cross(ea, eb);
      // Parallel edges give no new axis; the face normals already cover that case.
      if (dot(axis, axis) <= 1e-24 * dot(ea, ea) * dot(eb, eb)) continue;
      if (separated_on(axis, a, b)) return false;
    }
  }
  return true;
}

Frustum eye_frustum(const EyeView& eye) {
  const double fl = std::sqrt(dot(eye.forward, eye.forward));
  const Vec3 f = scale(eye.forward, 1.0 / fl);
  Vec3 r = cross(f, eye.up);
  r = scale(r, 1.0 / std::sqrt(dot(r, r)));
  const Vec3 u = cross(r, f);
  const double ty = std::tan(eye.fov_y / 2), tx = ty * eye.aspect;
  std::array<Vec3, 4> n, fa;
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    const Vec3 dir = add(f, add(scale(r, sx[i] * tx), scale(u, sy[i] * ty)));
    n[i] = add(eye.position, scale(dir, eye.near));
    fa[i] = add(eye.position, scale(dir, eye.far));
  }
  return Frustum(n, fa);
}

Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far) {
  const double u0 = rect.x, v0 = rect.y, u1 = rect.x + rect.width, v1 = rect.y + rect.height;
  const double us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
  const Vec3 axis = from_direction(direction_from_face_coord({face, 0.5, 0.5}));
  std::array<Vec3, 4> dirs;
  double min_cos = 1;
  for (int i = 0; i < 4; ++i) {
    dirs[i] = from_direction(direction_from_texel_coord({face, us[i], vs[i]}, face_size));
    min_cos = std::min(min_cos, dot(dirs[i], axis));
  }
  // The cell point closest to the face centre has the largest cosine.
  const double half = face_size / 2.0;
  const double cu = std::clamp(half, u0, u1), cv = std::clamp(half, v0, v1);
  const double max_cos =
      dot(from_direction(direction_from_texel_coord({face, cu, cv}, face_size)), axis);
  const double near_axial = z_near * min_cos, far_axial = z_far * max_cos;
  std::array<Vec3, 4> n, f;
  for (int i = 0; i < 4; ++i) {
    const double c = dot(dirs[i], axis);
    n[i] = add(viewpoint, scale(dirs[i], near_axial / c));
    f[i] = add(viewpoint, scale(dirs[i], far_axial / c));
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
