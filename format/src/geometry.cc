#include "calf/format/geometry.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace calf {
namespace {

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

Box3 box_union(const Box3& a, const Box3& b) {
  return {{std::min(a.min.x, b.min.x), std::min(a.min.y, b.min.y), std::min(a.min.z, b.min.z)},
          {std::max(a.max.x, b.max.x), std::max(a.max.y, b.max.y), std::max(a.max.z, b.max.z)}};
}

Box3 box_union(const Box3& box, const Vec3& p) {
  return box_union(box, Box3{p, p});
}

Frustum::Frustum(const std::array<Vec3, 4>& n, const std::array<Vec3, 4>& f) {
  for (int i = 0; i < 4; ++i) {
    corners_[i] = n[i];
    corners_[4 + i] = f[i];
  }
  // Side faces i: near i, near i+1, far i. Caps: near plane and far plane.
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    normals_[i] = cross(n[j] - n[i], f[i] - n[i]);
    edges_[i] = f[i] - n[i];
  }
  normals_[4] = cross(n[1] - n[0], n[3] - n[0]);
  normals_[5] = cross(f[1] - f[0], f[3] - f[0]);
  edges_[4] = n[1] - n[0];
  edges_[5] = n[3] - n[0];
  // Orient every normal inward (toward the centroid) and keep the plane offsets, for the cheap
  // "a corner of one lies inside the other" proof of intersection.
  Vec3 centroid;
  for (const Vec3& c : corners_) centroid = centroid + c * (1.0 / 8);
  const Vec3 on_face[6] = {n[0], n[1], n[2], n[3], n[0], f[0]};
  for (int i = 0; i < 6; ++i) {
    if (dot(normals_[i], centroid - on_face[i]) < 0) normals_[i] = normals_[i] * -1.0;
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

bool view_axes_usable(const Vec3& forward, const Vec3& up) {
  if (!is_finite(forward) || !is_finite(up) || length(forward) == 0) return false;
  return length(cross(normalize(forward), up)) > 1e-12 * std::max(1.0, length(up));
}

const char* eye_view_problem(const EyeView& e) {
  if (!is_finite(e.position) || !view_axes_usable(e.forward, e.up)) {
    return "position or axes not finite, zero or parallel";
  }
  if (!(e.fov_y > 0 && e.fov_y < std::numbers::pi) || !(e.aspect > 0) || !std::isfinite(e.aspect)) {
    return "field of view or aspect out of range";
  }
  if (!(e.near > 0) || !(e.far > e.near) || !std::isfinite(e.far))
    return "needs 0 < near < far < inf";
  return nullptr;
}

Frustum eye_frustum(const EyeView& eye) {
  // The same frame as camera_frame() (calf/format/camera.h), so a camera's frustum and its rays
  // agree to the bit on where the image edges are.
  const Vec3 f = normalize(eye.forward);
  const Vec3 r = normalize(cross(f, eye.up));
  const Vec3 u = cross(r, f);
  const double ty = std::tan(eye.fov_y / 2), tx = ty * eye.aspect;
  std::array<Vec3, 4> n, fa;
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    const Vec3 dir = f + (r * (sx[i] * tx) + u * (sy[i] * ty));
    n[i] = eye.position + dir * eye.near;
    fa[i] = eye.position + dir * eye.far;
  }
  return Frustum(n, fa);
}

}  // namespace calf
