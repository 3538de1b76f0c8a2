#include "calf/decoder/culling.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace calf {

CellDirections cell_directions(CubeFace face, uint32_t face_size, const PixelRect& rect) {
  const double u0 = rect.x, v0 = rect.y, u1 = rect.x + rect.width, v1 = rect.y + rect.height;
  const double us[4] = {u0, u1, u1, u0}, vs[4] = {v0, v0, v1, v1};
  const Vec3 axis = direction_from_face_coord({face, 0.5, 0.5});
  CellDirections c;
  for (int i = 0; i < 4; ++i) {
    c.dirs[i] = direction_from_texel_coord({face, us[i], vs[i]}, face_size);
    c.cos[i] = dot(c.dirs[i], axis);
    c.min_cos = std::min(c.min_cos, c.cos[i]);
  }
  // The cell point closest to the face centre has the largest cosine.
  const double half = face_size / 2.0;
  const double cu = std::clamp(half, u0, u1), cv = std::clamp(half, v0, v1);
  c.max_cos = dot(direction_from_texel_coord({face, cu, cv}, face_size), axis);
  return c;
}

std::array<Vec3, 8> cell_frustum_corners(const CellDirections& cell, const Vec3& viewpoint,
                                         double z_near, double z_far) {
  const double near_axial = z_near * cell.min_cos, far_axial = z_far * cell.max_cos;
  std::array<Vec3, 8> p;
  for (int i = 0; i < 4; ++i) {
    p[i] = viewpoint + cell.dirs[i] * (near_axial / cell.cos[i]);
    p[4 + i] = viewpoint + cell.dirs[i] * (far_axial / cell.cos[i]);
  }
  return p;
}

namespace {

Frustum frustum_of(const std::array<Vec3, 8>& p) {
  return Frustum({p[0], p[1], p[2], p[3]}, {p[4], p[5], p[6], p[7]});
}

}  // namespace

Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far) {
  return frustum_of(
      cell_frustum_corners(cell_directions(face, face_size, rect), viewpoint, z_near, z_far));
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

PreparedEye prepare_eye(const Frustum& eye) {
  PreparedEye e;
  e.frustum = &eye;
  e.normals = eye.face_normals();
  double reach = 0;  // the largest coordinate of a corner: the scale rounding works at
  for (const Vec3& c : eye.corners()) {
    reach = std::max({reach, std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
  }
  for (int k = 0; k < 6; ++k) {
    // The projections frusta_intersect()'s separated_on() computes for this axis, in its order.
    double lo = INFINITY, hi = -INFINITY;
    for (const Vec3& c : eye.corners()) {
      const double d = dot(e.normals[k], c);
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
    e.lo[k] = lo;
    e.hi[k] = hi;
    e.margin[k] = 1e-9 * length(e.normals[k]) * (1 + reach);
  }
  e.reach = reach;
  return e;
}

GridCuller::GridCuller(const FaceGrid& grid) : grid_(grid) {
  const uint32_t levels = grid.quadtree_levels();
  uint32_t count = 0;
  for (uint32_t l = 0; l < levels; ++l) {
    level_start_.push_back(count);
    count += (1u << l) * (1u << l);
  }
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    nodes_[f].resize(count);
    for (uint32_t l = 0; l < levels; ++l) {
      for (uint32_t iy = 0; iy < (1u << l); ++iy) {
        for (uint32_t ix = 0; ix < (1u << l); ++ix) {
          Node& n = nodes_[f][level_start_[l] + iy * (1u << l) + ix];
          n.range = grid.quadtree_node_cells(l, ix, iy);
          if (n.range.empty()) continue;
          n.cell = cell_directions(face, grid.face_size(), grid.rect_of_cells(n.range));
          const Vec3 centre = n.cell.dirs[0] + n.cell.dirs[1] + n.cell.dirs[2] + n.cell.dirs[3];
          for (int i = 0; i < 4; ++i) {
            n.side[i] = cross(n.cell.dirs[i], n.cell.dirs[(i + 1) % 4]);
            if (dot(n.side[i], centre) < 0) n.side[i] = -n.side[i];
            n.side_len[i] = length(n.side[i]);
            n.axial[i] = n.cell.dirs[i] * (1 / n.cell.cos[i]);
          }
        }
      }
    }
  }
}

namespace {

// Narrows the interval [*t0, *t1] of a segment's parameter to where g0 + t slope > 0 (one
// half-space); false once the interval is empty.
bool keep_positive(double g0, double slope, double* t0, double* t1) {
  if (slope == 0) return g0 > 0;
  const double t = -g0 / slope;
  if (slope > 0) {
    *t0 = std::max(*t0, t);
  } else {
    *t1 = std::min(*t1, t);
  }
  return *t0 < *t1;
}

}  // namespace

struct GridCuller::Search {
  const GridCuller& culler;
  const std::vector<Node>& nodes;
  const Vec3& viewpoint;
  double z_near, z_far;
  std::span<const PreparedEye> eyes;
  CullStats* stats;
  std::vector<uint32_t>* out;
  Vec3 axis;  // the face axis: the caps are perpendicular to it
  double axis_len;

  enum class Verdict { kOutside, kUndecided, kTouches, kInside };

  // Node corners against one eye's planes. kOutside: separated on one of the eye's face normals,
  // exactly as frusta_intersect() decides that axis. kInside: every corner inside every plane by
  // the margin (so is every frustum inside this one). kTouches: some corner inside by the margin
  // (the frusta share a point with room to spare). Otherwise undecided.
  static Verdict classify(const std::array<Vec3, 8>& p, const PreparedEye& e) {
    bool all_in = true;
    unsigned in = 0xff;  // bit j: corner j inside every plane so far
    for (int k = 0; k < 6; ++k) {
      const Vec3& n = e.normals[k];
      double lo = INFINITY, hi = -INFINITY;
      for (int j = 0; j < 8; ++j) {
        const double d = dot(n, p[j]);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
        in &= ~(unsigned{!(d - e.lo[k] > e.margin[k])} << j);
      }
      const double extent =
          std::max({std::fabs(e.lo[k]), std::fabs(e.hi[k]), std::fabs(lo), std::fabs(hi)});
      const double tolerance = 1e-12 * extent;
      if (e.hi[k] < lo - tolerance || hi < e.lo[k] - tolerance) return Verdict::kOutside;
      if (!(lo - e.lo[k] > e.margin[k])) all_in = false;
    }
    if (all_in) return Verdict::kInside;
    return in != 0 ? Verdict::kTouches : Verdict::kUndecided;
  }

  // The eye's corners against the node's own planes (see the class comment). kOutside: all of
  // them outside one plane by the margin. kTouches: one inside every plane by the margin.
  Verdict eye_in_node(const Node& node, const std::array<Vec3, 8>& p, const PreparedEye& e) const {
    const std::array<Vec3, 8>& q = e.frustum->corners();
    double reach = e.reach;
    for (const Vec3& c : p)
      reach = std::max({reach, std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
    const double margin = 1e-9 * (1 + reach);
    std::array<bool, 8> in;
    in.fill(true);
    // Signed distances (times |normal|) of the eye's corners from each plane, inside positive.
    auto plane = [&](const Vec3& n, double n_len, double offset, double sign) {
      const double m = margin * n_len;
      bool all_out = true;
      for (int j = 0; j < 8; ++j) {
        const double d = sign * (dot(n, q[j]) - offset);
        if (!(d > m)) in[j] = false;
        if (!(d < -m)) all_out = false;
      }
      return all_out;
    };
    for (int i = 0; i < 4; ++i) {
      if (plane(node.side[i], node.side_len[i], dot(node.side[i], viewpoint), 1)) {
        return Verdict::kOutside;
      }
    }
    // The caps: the axial distances of the near and far corners (corner 0's, as
    // cell_frustum_corners places every corner of a cap at the same axial distance).
    const Vec3& a = axis;
    if (plane(a, axis_len, dot(a, p[0]), 1) || plane(a, axis_len, dot(a, p[4]), -1)) {
      return Verdict::kOutside;
    }
    for (bool b : in) {
      if (b) return Verdict::kTouches;
    }
    return Verdict::kUndecided;
  }

  // Whether some point of segment a -> b lies inside every plane of `e` by its margin: the
  // parametric interval of the segment left by each plane (Liang-Barsky clipping), kept only
  // while it is not empty.
  static bool segment_inside(const Vec3& a, const Vec3& b, const PreparedEye& e) {
    double t0 = 0, t1 = 1;
    const Vec3 ab = b - a;
    for (int k = 0; k < 6; ++k) {
      // g(t) = dot(n, a) - lo - margin + t dot(n, ab) must be > 0.
      const double g0 = dot(e.normals[k], a) - e.lo[k] - e.margin[k];
      const double slope = dot(e.normals[k], ab);
      if (slope == 0) {
        if (!(g0 > 0)) return false;
        continue;
      }
      const double t = -g0 / slope;
      if (slope > 0) {
        t0 = std::max(t0, t);
      } else {
        t1 = std::min(t1, t);
      }
      if (!(t0 < t1)) return false;
    }
    return true;
  }

  // A point of the node's frustum inside the eye by the margin, looked for on the segments from
  // the near cap to the far cap: the 4 side edges and the centre line.
  static bool node_reaches_into(const std::array<Vec3, 8>& p, const PreparedEye& e) {
    const Vec3 near_centre = (p[0] + p[1] + p[2] + p[3]) * 0.25;
    const Vec3 far_centre = (p[4] + p[5] + p[6] + p[7]) * 0.25;
    if (segment_inside(near_centre, far_centre, e)) return true;
    for (int i = 0; i < 4; ++i) {
      if (segment_inside(p[i], p[4 + i], e)) return true;
    }
    return false;
  }

  // Whether the node's cross-section at some axial depth in [t0, t1] lies inside every plane of
  // `e` by its margin: 4 corners moving linearly with the depth, clipped plane by plane.
  bool section_inside(const Node& node, const PreparedEye& e, double t0, double t1) const {
    for (int k = 0; k < 6; ++k) {
      const Vec3& n = e.normals[k];
      const double g0 = dot(n, viewpoint) - e.lo[k] - e.margin[k];
      for (int i = 0; i < 4; ++i) {
        // g0 + t slope > 0 for every corner.
        if (!keep_positive(g0, dot(n, node.axial[i]), &t0, &t1)) return false;
      }
    }
    return true;
  }

  // A point of the eye's frustum inside the node's planes by the margin, looked for on the eye's
  // 4 side edges and its centre line (an eye passing through a wide cell).
  bool eye_reaches_into(const Node& node, const std::array<Vec3, 8>& p,
                        const PreparedEye& e) const {
    const std::array<Vec3, 8>& q = e.frustum->corners();
    double reach = e.reach;
    for (const Vec3& c : p) {
      reach = std::max({reach, std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
    }
    const double margin = 1e-9 * (1 + reach);
    // Planes as n.x >= offset + margin |n|: 4 sides, the near cap, the far cap (flipped).
    std::array<Vec3, 6> n;
    std::array<double, 6> offset;
    for (int i = 0; i < 4; ++i) {
      n[i] = node.side[i];
      offset[i] = dot(node.side[i], viewpoint) + margin * node.side_len[i];
    }
    n[4] = axis;
    offset[4] = dot(axis, p[0]) + margin * axis_len;
    n[5] = -axis;
    offset[5] = -dot(axis, p[4]) + margin * axis_len;
    auto segment = [&](const Vec3& a, const Vec3& b) {
      double t0 = 0, t1 = 1;
      const Vec3 ab = b - a;
      for (int k = 0; k < 6; ++k) {
        if (!keep_positive(dot(n[k], a) - offset[k], dot(n[k], ab), &t0, &t1)) return false;
      }
      return true;
    };
    if (segment((q[0] + q[1] + q[2] + q[3]) * 0.25, (q[4] + q[5] + q[6] + q[7]) * 0.25)) {
      return true;
    }
    for (int i = 0; i < 4; ++i) {
      if (segment(q[i], q[4 + i])) return true;
    }
    return false;
  }

  void emit_all(const CellRange& r) {
    for (uint32_t y = r.y0; y < r.y1; ++y) {
      for (uint32_t x = r.x0; x < r.x1; ++x) out->push_back(culler.grid_.cell_index(x, y));
    }
  }

  // `candidates`: bit e set for each eye (of at most 64) not yet separated from an ancestor.
  void visit(uint32_t level, uint32_t ix, uint32_t iy, uint64_t candidates) {
    const Node& node = nodes[culler.level_start_[level] + iy * (1u << level) + ix];
    const CellRange& r = node.range;
    if (r.empty()) return;
    const std::array<Vec3, 8> p = cell_frustum_corners(node.cell, viewpoint, z_near, z_far);
    const bool leaf = r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1;  // one cell, whatever its level
    uint64_t undecided = 0;
    for (uint64_t left = candidates; left != 0; left &= left - 1) {
      const int e = std::countr_zero(left);
      if (stats) ++stats->tests;
      const Verdict v = classify(p, eyes[e]);
      if (v == Verdict::kInside || (leaf && v == Verdict::kTouches)) {
        emit_all(r);
        return;
      }
      if (v == Verdict::kOutside) continue;
      // Every cell below spans the axial depths [z_near, z_far * min_cos] (its own near cap is
      // at most z_near, its far cap at least z_far times its largest cosine).
      if (!leaf && section_inside(node, eyes[e], z_near, z_far * node.cell.min_cos)) {
        emit_all(r);
        return;
      }
      // A leaf neither rejected nor accepted by the eye's planes: a stretch of one of its segments
      // inside the eye (the common case) first, then the eye against its own planes.
      if (leaf && v == Verdict::kUndecided) {
        if (node_reaches_into(p, eyes[e])) {
          emit_all(r);
          return;
        }
        const Verdict w = eye_in_node(node, p, eyes[e]);
        if (w == Verdict::kOutside) continue;
        if (w == Verdict::kTouches || eye_reaches_into(node, p, eyes[e])) {
          emit_all(r);
          return;
        }
      }
      undecided |= uint64_t{1} << e;
    }
    if (undecided == 0) return;
    if (!leaf) {
      for (uint32_t c = 0; c < 4; ++c) {
        visit(level + 1, 2 * ix + (c & 1), 2 * iy + (c >> 1), undecided);
      }
      return;
    }
    // The exact test settles what the planes could not, on the frustum cell_frustum() builds.
    const Frustum f = frustum_of(p);
    for (uint64_t left = undecided; left != 0; left &= left - 1) {
      if (stats) ++stats->exact_tests;
      if (frusta_intersect(*eyes[std::countr_zero(left)].frustum, f)) {
        out->push_back(culler.grid_.cell_index(r.x0, r.y0));
        return;
      }
    }
  }
};

void GridCuller::visible(const Vec3& viewpoint, CubeFace face, double z_near, double z_far,
                         std::span<const PreparedEye> eyes, uint32_t levels, CullStats* stats,
                         std::vector<uint32_t>* out) const {
  out->clear();
  const uint32_t total = grid_.quadtree_levels();
  if (levels == 0 || levels > total) levels = total;
  const uint32_t start = total - levels;
  const Vec3 axis = direction_from_face_coord({face, 0.5, 0.5});
  // Eyes in groups of 64 (one bit each); a cell seen by several groups is listed once.
  for (size_t first = 0; first < eyes.size(); first += 64) {
    const std::span<const PreparedEye> group =
        eyes.subspan(first, std::min<size_t>(64, eyes.size() - first));
    const uint64_t all = group.size() == 64 ? ~uint64_t{0} : (uint64_t{1} << group.size()) - 1;
    Search search{*this,     nodes_[cube_face_index(face)],
                  viewpoint, z_near,
                  z_far,     group,
                  stats,     out,
                  axis,      length(axis)};
    for (uint32_t iy = 0; iy < (1u << start); ++iy) {
      for (uint32_t ix = 0; ix < (1u << start); ++ix) search.visit(start, ix, iy, all);
    }
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
  if (stats) stats->visible_cells += out->size();
}

}  // namespace calf
