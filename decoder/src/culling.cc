#include "calf/decoder/culling.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

namespace calf {

CellDirections cell_directions(CubeFace face, uint32_t face_size, const PixelRect& rect,
                               double grow_texels) {
  const double u0 = rect.x - grow_texels, v0 = rect.y - grow_texels;
  const double u1 = rect.x + rect.width + grow_texels, v1 = rect.y + rect.height + grow_texels;
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
                     const PixelRect& rect, double z_near, double z_far, double grow_texels) {
  return frustum_of(cell_frustum_corners(cell_directions(face, face_size, rect, grow_texels),
                                         viewpoint, z_near, z_far));
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
    const Frustum f = cell_frustum(viewpoint, face, grid.face_size(), grid.rect_of_cells(range),
                                   z_near, z_far, kRenderReachTexels);
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
      const Frustum f = cell_frustum(viewpoint, face, grid.face_size(), grid.cell_rect(cx, cy),
                                     z_near, z_far, kRenderReachTexels);
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
  const std::array<Vec3, 8>& q = eye.corners();
  e.origin = (q[0] + q[1] + q[2] + q[3]) * 0.25;
  for (int k = 0; k < 6; ++k) {
    e.inv_len[k] = 1 / length(e.normals[k]);
    e.unit[k] = e.normals[k] * e.inv_len[k];
    e.offset[k] = e.lo[k] * e.inv_len[k] - dot(e.unit[k], e.origin);
    e.offset[6 + k] = dot(e.unit[k], e.origin) - e.hi[k] * e.inv_len[k];
  }
  return e;
}

GridCuller::GridCuller(const FaceGrid& grid) : grid_(grid) {
  const uint32_t levels = grid.quadtree_levels();
  uint32_t count = 0;
  for (uint32_t l = 0; l < levels; ++l) {
    level_start_.push_back(count);
    count += (1u << l) * (1u << l);
  }
  shape_.resize(count);
  for (uint32_t l = 0; l < levels; ++l) {
    for (uint32_t iy = 0; iy < (1u << l); ++iy) {
      for (uint32_t ix = 0; ix < (1u << l); ++ix) {
        const CellRange r = grid.quadtree_node_cells(l, ix, iy);
        shape_[level_start_[l] + iy * (1u << l) + ix] = r.empty() ? 1
                                                        : (r.x1 - r.x0 == 1 && r.y1 - r.y0 == 1)
                                                            ? 2
                                                            : 0;
      }
    }
  }
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    axis_[f] = direction_from_face_coord({face, 0.5, 0.5});
    nodes_[f].resize(count);
    for (uint32_t l = 0; l < levels; ++l) {
      for (uint32_t iy = 0; iy < (1u << l); ++iy) {
        for (uint32_t ix = 0; ix < (1u << l); ++ix) {
          Node& n = nodes_[f][level_start_[l] + iy * (1u << l) + ix];
          n.range = grid.quadtree_node_cells(l, ix, iy);
          if (n.range.empty()) continue;
          n.cell = cell_directions(face, grid.face_size(), grid.rect_of_cells(n.range),
                                   kRenderReachTexels);
          const Vec3 centre = n.cell.dirs[0] + n.cell.dirs[1] + n.cell.dirs[2] + n.cell.dirs[3];
          for (int i = 0; i < 4; ++i) {
            n.side[i] = cross(n.cell.dirs[i], n.cell.dirs[(i + 1) % 4]);
            if (dot(n.side[i], centre) < 0) n.side[i] = -n.side[i];
            n.side_len[i] = length(n.side[i]);
            n.axial[i] = n.cell.dirs[i] * (1 / n.cell.cos[i]);
            max_axial_ = std::max(max_axial_, length(n.axial[i]));
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
  // visible_reusing(): the memory, and the margin every kept decision must still hold by.
  CullMemory* memory = nullptr;
  double keep_margin = 0;

  enum class Verdict { kOutside, kUndecided, kTouches, kInside };
  enum class Outcome { kReject, kAccept, kUndecided };
  using Kind = CullMemory::Kind;
  // dot(normals[k], corner j) for every plane k and corner j.
  using Projections = std::array<std::array<double, 8>, 6>;

  // The slack of a decision: over the (point, half-space) pairs it rests on, the smallest
  // distance d by which the point lies on the deciding side, and the smallest d / L, L the
  // point's distance from the eye's origin. The half-space moves at a point by at most
  // turn * L + travel (its unit normal turning by `turn`, its offset, origin and the point
  // travelling by `travel` in all), so the decision holds while
  // turn / angle + (travel + margin) / distance < 1.
  struct Slack {
    double angle = INFINITY, distance = INFINITY;
    void take(double d, double l) {
      distance = std::min(distance, d);
      angle = std::min(angle, d / l);
    }
    // Something taken, all of it on the deciding side (false for NaN too).
    bool usable() const { return distance > 0 && distance < INFINITY && angle > 0; }
  };
  struct Certificate {
    Kind kind = Kind::kNone;
    Slack slack;
    double depth = 0;
  };

  // Node corners against one eye's planes. kOutside: separated on one of the eye's face normals,
  // exactly as frusta_intersect() decides that axis. kInside: every corner inside every plane by
  // the margin (so is every frustum inside this one). kTouches: some corner inside by the margin
  // (the frusta share a point with room to spare). Otherwise undecided. With `d`, every
  // projection is computed and kept (the verdict is the same).
  static Verdict classify(const std::array<Vec3, 8>& p, const PreparedEye& e, Projections* d) {
    bool all_in = true, outside = false;
    unsigned in = 0xff;  // bit j: corner j inside every plane so far
    for (int k = 0; k < 6; ++k) {
      const Vec3& n = e.normals[k];
      double lo = INFINITY, hi = -INFINITY;
      for (int j = 0; j < 8; ++j) {
        const double dj = dot(n, p[j]);
        if (d != nullptr) (*d)[k][j] = dj;
        lo = std::min(lo, dj);
        hi = std::max(hi, dj);
        in &= ~(unsigned{!(dj - e.lo[k] > e.margin[k])} << j);
      }
      const double extent =
          std::max({std::fabs(e.lo[k]), std::fabs(e.hi[k]), std::fabs(lo), std::fabs(hi)});
      const double tolerance = 1e-12 * extent;
      if (e.hi[k] < lo - tolerance || hi < e.lo[k] - tolerance) {
        if (d == nullptr) return Verdict::kOutside;
        outside = true;
      }
      if (!(lo - e.lo[k] > e.margin[k])) all_in = false;
    }
    if (outside) return Verdict::kOutside;
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
  static bool segment_inside(const Vec3& a, const Vec3& b, const PreparedEye& e, Vec3* found) {
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
    if (found != nullptr) *found = a + ab * (0.5 * (t0 + t1));
    return true;
  }

  // A point of the node's frustum inside the eye by the margin, looked for on the segments from
  // the near cap to the far cap: the 4 side edges and the centre line. `found`: the middle of
  // the stretch inside.
  static bool node_reaches_into(const std::array<Vec3, 8>& p, const PreparedEye& e, Vec3* found) {
    const Vec3 near_centre = (p[0] + p[1] + p[2] + p[3]) * 0.25;
    const Vec3 far_centre = (p[4] + p[5] + p[6] + p[7]) * 0.25;
    if (segment_inside(near_centre, far_centre, e, found)) return true;
    for (int i = 0; i < 4; ++i) {
      if (segment_inside(p[i], p[4 + i], e, found)) return true;
    }
    return false;
  }

  // Whether the node's cross-section at some axial depth in [*t0, *t1] lies inside every plane
  // of `e` by its margin: 4 corners moving linearly with the depth, clipped plane by plane. The
  // interval is narrowed to the depths whose section does.
  bool section_inside(const Node& node, const PreparedEye& e, double* t0, double* t1) const {
    for (int k = 0; k < 6; ++k) {
      const Vec3& n = e.normals[k];
      const double g0 = dot(n, viewpoint) - e.lo[k] - e.margin[k];
      for (int i = 0; i < 4; ++i) {
        // g0 + t slope > 0 for every corner.
        if (!keep_positive(g0, dot(n, node.axial[i]), t0, t1)) return false;
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

  // The tests of one node against one eye short of the exact test, as the class comment lists
  // them. With `cert`, the slack of a rejection or acceptance by the eye's planes is kept, and
  // for an inner node left undecided the slack of "no eye plane rejects it".
  Outcome test_eye(const Node& node, const std::array<Vec3, 8>& p, bool leaf, const PreparedEye& e,
                   Certificate* cert) const {
    Projections d;
    const Verdict v = classify(p, e, cert != nullptr ? &d : nullptr);
    if (v == Verdict::kInside || (leaf && v == Verdict::kTouches)) {
      if (cert != nullptr) {
        certify_corners(p, e, d, v == Verdict::kInside, cert);
        // A leaf's corner is where it meets the eye's planes first as the eye turns: the middle
        // of its centre line's stretch inside the eye, where there is one, usually keeps longer.
        Vec3 found;
        Certificate centre;
        if (leaf && segment_inside((p[0] + p[1] + p[2] + p[3]) * 0.25,
                                   (p[4] + p[5] + p[6] + p[7]) * 0.25, e, &found)) {
          certify_point(found, e, &centre);
          if (centre.slack.usable() && !(centre.slack.angle <= cert->slack.angle)) *cert = centre;
        }
      }
      return Outcome::kAccept;
    }
    if (v == Verdict::kOutside) {
      if (cert != nullptr) certify_rejection(p, e, d, cert);
      return Outcome::kReject;
    }
    if (!leaf) {
      // Every cell below spans the axial depths [z_near, z_far * min_cos] (its own near cap is
      // at most z_near, its far cap at least z_far times its largest cosine).
      double t0 = z_near, t1 = z_far * node.cell.min_cos;
      if (section_inside(node, e, &t0, &t1)) {
        // The depth as a float, as the memory keeps it (one beyond a float's range is not kept).
        const double depth = 0.5 * (t0 + t1);
        if (cert != nullptr && depth < 1e30) {
          certify_section(node, e, static_cast<float>(depth), cert);
        }
        return Outcome::kAccept;
      }
      if (cert != nullptr) certify_not_rejected(p, e, d, cert);
      return Outcome::kUndecided;
    }
    // A leaf neither rejected nor accepted by the eye's planes: a stretch of one of its segments
    // inside the eye (the common case) first, then the eye against its own planes.
    if (v == Verdict::kUndecided) {
      Vec3 found;
      if (node_reaches_into(p, e, &found)) {
        if (cert != nullptr) certify_point(found, e, cert);
        return Outcome::kAccept;
      }
      const Verdict w = eye_in_node(node, p, e);
      if (w == Verdict::kOutside) return Outcome::kReject;
      if (w == Verdict::kTouches || eye_reaches_into(node, p, e)) return Outcome::kAccept;
    }
    return Outcome::kUndecided;
  }

  // Signed distance of corner j from half-space c (inside positive): c < 6 the eye's side of
  // plane c, c >= 6 the far end of its interval on normal c - 6.
  static double inside_by(const PreparedEye& e, const Projections& d, int c, int j) {
    return c < 6 ? (d[c][j] - e.lo[c]) * e.inv_len[c]
                 : (e.hi[c - 6] - d[c - 6][j]) * e.inv_len[c - 6];
  }
  static std::array<double, 8> levers(const std::array<Vec3, 8>& p, const PreparedEye& e) {
    std::array<double, 8> l;
    for (int j = 0; j < 8; ++j) l[j] = length(p[j] - e.origin);
    return l;
  }

  // Rejected by an eye plane: all corners outside the half-space that leaves them farthest out.
  static void certify_rejection(const std::array<Vec3, 8>& p, const PreparedEye& e,
                                const Projections& d, Certificate* cert) {
    const std::array<double, 8> l = levers(p, e);
    for (int c = 0; c < 12; ++c) {
      Slack s;
      for (int j = 0; j < 8; ++j) s.take(-inside_by(e, d, c, j), l[j]);
      if (s.usable() && !(s.angle <= cert->slack.angle && cert->slack.usable())) cert->slack = s;
    }
    cert->kind = Kind::kReject;
  }

  // Accepted by corners inside every plane: all of them (`all`), else the one with the most room
  // for turning.
  static void certify_corners(const std::array<Vec3, 8>& p, const PreparedEye& e,
                              const Projections& d, bool all, Certificate* cert) {
    const std::array<double, 8> l = levers(p, e);
    for (int j = 0; j < 8; ++j) {
      Slack s;
      for (int k = 0; k < 6; ++k) s.take(inside_by(e, d, k, j), l[j]);
      if (all) {
        cert->slack.take(s.distance, 1);
        cert->slack.angle = std::min(cert->slack.angle, s.angle);
      } else if (s.usable() && !(s.angle <= cert->slack.angle && cert->slack.usable())) {
        cert->slack = s;
      }
    }
    cert->kind = Kind::kAccept;
  }

  // An inner node accepted by its cross-section at `depth`: those 4 points inside every plane.
  void certify_section(const Node& node, const PreparedEye& e, double depth,
                       Certificate* cert) const {
    for (int i = 0; i < 4; ++i) {
      const Vec3 x = viewpoint + node.axial[i] * depth;
      const double l = length(x - e.origin);
      for (int k = 0; k < 6; ++k) {
        const double g = dot(e.normals[k], viewpoint) + depth * dot(e.normals[k], node.axial[i]);
        cert->slack.take((g - e.lo[k]) * e.inv_len[k], l);
      }
    }
    cert->kind = Kind::kAccept;
    cert->depth = depth;
  }

  // A leaf accepted by a point of it inside every plane.
  static void certify_point(const Vec3& x, const PreparedEye& e, Certificate* cert) {
    const double l = length(x - e.origin);
    for (int k = 0; k < 6; ++k) {
      cert->slack.take((dot(e.normals[k], x) - e.lo[k]) * e.inv_len[k], l);
    }
    cert->kind = Kind::kAccept;
  }

  // An inner node no eye plane rejects: in every half-space some corner (the one with the most
  // room for turning) lies inside.
  static void certify_not_rejected(const std::array<Vec3, 8>& p, const PreparedEye& e,
                                   const Projections& d, Certificate* cert) {
    const std::array<double, 8> l = levers(p, e);
    for (int c = 0; c < 12; ++c) {
      int best = -1;
      for (int j = 0; j < 8; ++j) {
        const double in = inside_by(e, d, c, j);
        if (in > 0 && (best < 0 || in * l[best] > inside_by(e, d, c, best) * l[j])) best = j;
      }
      if (best < 0) return;  // nothing to keep
      cert->slack.take(inside_by(e, d, c, best), l[best]);
    }
    cert->kind = Kind::kDescend;
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
      const Outcome o = test_eye(node, p, leaf, eyes[e], nullptr);
      if (o == Outcome::kAccept) {
        emit_all(r);
        return;
      }
      if (o == Outcome::kUndecided) undecided |= uint64_t{1} << e;
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

  // The axes of frusta_intersect(eye, node frustum) (calf/format/geometry.h), as the Frustum
  // class computes them from the corners: axis a < 6 is the eye's face normal a, a < 12 the
  // node's face normal a - 6, and 12 + 6 i + j the cross product of the eye's edge direction i
  // and the node's edge direction j.
  static Vec3 node_edge(int j, const std::array<Vec3, 8>& p) {
    return j < 4 ? p[4 + j] - p[j] : j == 4 ? p[1] - p[0] : p[3] - p[0];
  }
  static Vec3 exact_axis(int a, const Frustum& eye, const std::array<Vec3, 8>& p) {
    if (a < 6) return eye.face_normals()[a];
    if (a < 10) {
      const int i = a - 6, j = (i + 1) % 4;
      return cross(p[j] - p[i], p[4 + i] - p[i]);
    }
    if (a == 10) return cross(p[1] - p[0], p[3] - p[0]);
    if (a == 11) return cross(p[5] - p[4], p[7] - p[4]);
    return cross(eye.edge_directions()[(a - 12) / 6], node_edge((a - 12) % 6, p));
  }

  // The gap between the projections of the eye's corners `q` and the node's `p` on axis `a`, over
  // |axis|, where it exceeds 100 times frusta_intersect()'s tolerance (so that the exact test,
  // which tries that axis too, certainly finds them separated); otherwise a negative number. An
  // edge axis from (nearly) parallel edges, which frusta_intersect() skips, does not count.
  static double separation(int a, const Frustum& eye, const std::array<Vec3, 8>& p) {
    const Vec3 axis = exact_axis(a, eye, p);
    const double len2 = dot(axis, axis);
    if (a >= 12) {
      const Vec3 ea = eye.edge_directions()[(a - 12) / 6], eb = node_edge((a - 12) % 6, p);
      if (!(len2 > 1e-20 * dot(ea, ea) * dot(eb, eb))) return -1;
    }
    double q_lo = INFINITY, q_hi = -INFINITY, p_lo = INFINITY, p_hi = -INFINITY;
    for (int j = 0; j < 8; ++j) {
      const double dq = dot(axis, eye.corners()[j]), dp = dot(axis, p[j]);
      q_lo = std::min(q_lo, dq);
      q_hi = std::max(q_hi, dq);
      p_lo = std::min(p_lo, dp);
      p_hi = std::max(p_hi, dp);
    }
    const double extent =
        std::max({std::fabs(q_lo), std::fabs(q_hi), std::fabs(p_lo), std::fabs(p_hi)});
    const double gap = std::max(p_lo - q_hi, q_lo - p_hi);
    if (!(gap > 1e-10 * extent && len2 > 0)) return -1;
    return gap / std::sqrt(len2);
  }

  // The exact test's axis that separates the eye from a leaf by the widest gap, or -1.
  static int widest_separation(const Frustum& eye, const std::array<Vec3, 8>& p) {
    int best = -1;
    double widest = 0;
    for (int a = 0; a < 48; ++a) {
      const double g = separation(a, eye, p);
      if (g > widest) {
        widest = g;
        best = a;
      }
    }
    return best;
  }

  // Whether decision `m` of node `index` still holds (see Slack).
  bool holds(const CullMemory::Decision& m, uint32_t index) const {
    if (m.kind == Kind::kNone) return false;
    const double lhs = memory->turn_ * double{m.inv_angle} +
                       (memory->travel_ + keep_margin) * double{m.inv_distance};
    if (!(lhs < m.budget)) return false;
    // A section must still lie within the depths every cell below spans.
    return m.depth == 0 || (z_near < m.depth && m.depth < z_far * nodes[index].cell.min_cos);
  }

  // `x` as a float no smaller.
  static float float_up(double x) {
    float f = static_cast<float>(x);
    if (double{f} < x) f = std::nextafter(f, INFINITY);
    return f;
  }

  // Keeps `cert` in `m` where it is worth it: a slack of at least 1e-6 radians and 100 margins
  // (a smaller one would not outlast the smallest motion), which also keeps the products in the
  // budget small enough for its rounding not to matter.
  void keep(const Certificate& cert, CullMemory::Decision* m) const {
    if (cert.kind == Kind::kNone || !cert.slack.usable() || !(cert.slack.angle >= 1e-6) ||
        !(cert.slack.distance >= 100 * keep_margin)) {
      return;
    }
    m->kind = cert.kind;
    m->inv_angle = float_up(1 / cert.slack.angle);
    m->inv_distance = float_up(1 / cert.slack.distance);
    m->budget =
        0.999 + memory->turn_ * double{m->inv_angle} + memory->travel_ * double{m->inv_distance};
    m->depth = static_cast<float>(cert.depth);
  }

  // visit() for one eye (eyes[0]) with the memory: a node's kept decision where it holds, else
  // the tests of visit(), whose decision and slack are kept.
  void visit_reusing(uint32_t level, uint32_t ix, uint32_t iy) {
    const uint32_t index = culler.level_start_[level] + iy * (1u << level) + ix;
    const uint8_t shape = culler.shape_[index];
    if (shape & 1) return;  // no cells
    const bool leaf = (shape & 2) != 0;
    CullMemory::Decision& m = memory->nodes_[index];
    Kind kind;
    if (holds(m, index)) {
      if (stats) ++stats->reused;
      kind = m.kind;
    } else if (leaf && m.axis >= 0 &&
               separation(m.axis, *eyes[0].frustum,
                          cell_frustum_corners(nodes[index].cell, viewpoint, z_near, z_far)) > 0) {
      // A leaf the exact test separated on this axis before, separated on it still: the exact
      // test would reject it, and so would the cheap tests ahead of it (they only ever accept
      // what meets the eye with room to spare, or reject on the exact test's own axes).
      if (stats) ++stats->tests;
      kind = Kind::kReject;
    } else {
      if (stats) ++stats->tests;
      const Node& node = nodes[index];
      const std::array<Vec3, 8> p = cell_frustum_corners(node.cell, viewpoint, z_near, z_far);
      Certificate cert;
      Outcome o = test_eye(node, p, leaf, eyes[0], &cert);
      if (o == Outcome::kUndecided && leaf) {
        if (stats) ++stats->exact_tests;
        o = frusta_intersect(*eyes[0].frustum, frustum_of(p)) ? Outcome::kAccept : Outcome::kReject;
        cert = Certificate{};  // the exact test leaves no slack to keep
      }
      kind = o == Outcome::kAccept   ? Kind::kAccept
             : o == Outcome::kReject ? Kind::kReject
                                     : Kind::kDescend;
      m = CullMemory::Decision{};
      // A leaf rejected without a slack to keep: the axis to try first next time.
      if (leaf && o == Outcome::kReject && cert.kind == Kind::kNone) {
        m.axis = static_cast<int8_t>(widest_separation(*eyes[0].frustum, p));
      }
      keep(cert, &m);
    }
    if (kind == Kind::kAccept) {
      emit_all(nodes[index].range);
    } else if (kind == Kind::kDescend) {
      for (uint32_t c = 0; c < 4; ++c)
        visit_reusing(level + 1, 2 * ix + (c & 1), 2 * iy + (c >> 1));
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
  const Vec3& axis = axis_[cube_face_index(face)];
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

void GridCuller::visible_reusing(const Vec3& viewpoint, CubeFace face, double z_near, double z_far,
                                 const PreparedEye& eye, uint32_t levels, CullMemory* memory,
                                 CullStats* stats, std::vector<uint32_t>* out) const {
  out->clear();
  const int f = cube_face_index(face);
  CullMemory& m = *memory;
  if (m.culler_ != this || m.face_ != f || m.nodes_.size() != nodes_[f].size()) {
    m = CullMemory{};
    m.culler_ = this;
    m.face_ = f;
    m.nodes_.resize(nodes_[f].size());
  }
  // The scale of every coordinate involved (eye and node corners), and the margin a kept
  // decision must still hold by: 100 times the tests' own (1e-9 of it), far above rounding.
  const double node_reach =
      std::max({std::fabs(viewpoint.x), std::fabs(viewpoint.y), std::fabs(viewpoint.z)}) +
      max_axial_ * z_far;
  const double scale = 1 + eye.reach + node_reach;
  if (m.has_last_) {
    // How far the half-spaces and the node frusta moved since the last call: the unit normals
    // turned by at most `turn`; offsets, the eye's origin and every node point (the viewpoint,
    // and the caps along axial[i] with the depth range) travelled by at most `travel`.
    double turn = 0, travel = 0;
    for (int k = 0; k < 6; ++k) turn = std::max(turn, length(eye.unit[k] - m.unit_[k]));
    for (int c = 0; c < 12; ++c) travel = std::max(travel, std::fabs(eye.offset[c] - m.offset_[c]));
    travel += length(eye.origin - m.origin_) + length(viewpoint - m.apex_) +
              max_axial_ * std::max(std::fabs(z_near - m.z_near_), std::fabs(z_far - m.z_far_));
    // Summed rounding upward, so that the sums never fall short of the motion.
    m.turn_ = std::nextafter(m.turn_ + turn * (1 + 1e-12), INFINITY);
    m.travel_ = std::nextafter(m.travel_ + travel * (1 + 1e-12), INFINITY);
    // Sums kept small, so that differences of them lose nothing that matters; a NaN or an
    // infinity forgets everything too.
    if (!(m.turn_ < 1 && m.travel_ < 10 * scale)) {
      std::fill(m.nodes_.begin(), m.nodes_.end(), CullMemory::Decision{});
      m.turn_ = m.travel_ = 0;
    }
  }
  m.has_last_ = true;
  m.unit_ = eye.unit;
  m.offset_ = eye.offset;
  m.origin_ = eye.origin;
  m.apex_ = viewpoint;
  m.z_near_ = z_near;
  m.z_far_ = z_far;

  const uint32_t total = grid_.quadtree_levels();
  if (levels == 0 || levels > total) levels = total;
  const uint32_t start = total - levels;
  const Vec3& axis = axis_[f];
  Search search{
      *this, nodes_[f], viewpoint, z_near,       z_far, std::span<const PreparedEye>(&eye, 1),
      stats, out,       axis,      length(axis), &m,    1e-7 * scale};
  for (uint32_t iy = 0; iy < (1u << start); ++iy) {
    for (uint32_t ix = 0; ix < (1u << start); ++ix) search.visit_reusing(start, ix, iy);
  }
  std::sort(out->begin(), out->end());
  if (stats) stats->visible_cells += out->size();
}

void CullMemory::clear() {
  *this = CullMemory{};
}

}  // namespace calf
