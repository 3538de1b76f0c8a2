// Geometry every layer shares: the one 3-vector (`Vec3`), axis-aligned boxes and convex frusta
// with their intersection test. Points, directions and offsets in scene space are all Vec3
// (double precision: these are the reference computations fast paths are tested against; hot GPU
// paths convert to float after them). The camera model built on them is calf/format/camera.h.
//
// Every operation is written out in a fixed order of floating-point operations (no fused
// multiply-add requested, no reassociation), so a result is the same double on every compiler
// that honours IEEE 754: culling decisions and rendered frames depend on these bits.
//
// Frusta (paper 002, Sec. 6.2): a frustum is a convex truncated pyramid given by its 4 near and 4
// far corners. Two frusta are tested with the separating-axis theorem over both frusta's face
// normals and the cross products of their edge directions: exact for convex polyhedra, up to a
// tiny tolerance that counts touching as intersecting (so culling never drops a cell the viewer
// can see). The view-dependent culling of the light field (calf/decoder/culling.h) builds cell
// frusta from cube-map cells; any builder (tiles, visible sets, camera placement) may build and
// test frusta with the functions here.
#pragma once

#include <array>
#include <cmath>

namespace calf {

// A point, direction or offset in scene units (right-handed; +Y is up by the convention of the
// sample scenes, the formats themselves do not care which axis is up).
struct Vec3 {
  double x = 0, y = 0, z = 0;
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

// Componentwise sum and difference; product and quotient by a scalar (a * s multiplies each
// component by s; a / s divides each by s, which is not always the same double as a * (1 / s)).
inline Vec3 operator+(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 operator-(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 operator-(const Vec3& a) {
  return {-a.x, -a.y, -a.z};
}
inline Vec3 operator*(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline Vec3 operator*(double s, const Vec3& a) {
  return {s * a.x, s * a.y, s * a.z};
}
inline Vec3 operator/(const Vec3& a, double s) {
  return {a.x / s, a.y / s, a.z / s};
}
inline Vec3& operator+=(Vec3& a, const Vec3& b) {
  return a = a + b;
}
inline Vec3& operator-=(Vec3& a, const Vec3& b) {
  return a = a - b;
}

// a.x b.x + a.y b.y + a.z b.z, summed left to right.
inline double dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
// The right-handed cross product a x b.
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// The Euclidean length, sqrt(dot(a, a)).
inline double length(const Vec3& a) {
  return std::sqrt(dot(a, a));
}
// a * (1 / length(a)): unit length for a finite non-zero a. No rescaling: a zero vector, or one
// so small that its squared components underflow (below about 1e-154), gives infinities or NaNs,
// and one beyond about 1e154 overflows (callers check first where that can happen).
inline Vec3 normalize(const Vec3& a) {
  return a * (1.0 / length(a));
}
// The angle between two non-zero vectors in radians, [0, pi]: atan2(|a x b|, a . b), which stays
// accurate near 0 and pi, where acos of a normalised dot product loses half its digits (view
// selection's culling thresholds of a few degrees sit exactly there).
inline double angle_between(const Vec3& a, const Vec3& b) {
  return std::atan2(length(cross(a, b)), dot(a, b));
}
// Whether every component is finite (no NaN, no infinity).
inline bool is_finite(const Vec3& a) {
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
// Component `axis` (0 = x, 1 = y, 2 = z; anything else reads z).
inline double component(const Vec3& a, int axis) {
  return axis == 0 ? a.x : axis == 1 ? a.y : a.z;
}

// An axis-aligned box, min <= max componentwise for a box that holds anything (a point or a flat
// box is allowed). Used for view volumes (format/CAPTURE.md "view_volume") and bounds.
struct Box3 {
  Vec3 min, max;
  // Whether `p` lies inside or on the box.
  bool contains(const Vec3& p) const {
    return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z &&
           p.z <= max.z;
  }
  friend bool operator==(const Box3&, const Box3&) = default;
};
// The smallest box holding both `a` and `b`.
Box3 box_union(const Box3& a, const Box3& b);
// The smallest box holding `box` and the point `p`.
Box3 box_union(const Box3& box, const Vec3& p);

// A convex truncated pyramid given by its 4 near and 4 far corners, each in the same winding
// (corner i of near and far lie on one side edge).
class Frustum {
 public:
  Frustum() = default;
  Frustum(const std::array<Vec3, 4>& near_corners, const std::array<Vec3, 4>& far_corners);

  // Near corners 0..3, then far corners 0..3.
  const std::array<Vec3, 8>& corners() const { return corners_; }
  // Face normals: the 4 sides (side i through near corners i, i + 1 and far corner i), then the
  // near and the far cap, each pointing inward (the separating-axis test ignores the sign).
  const std::array<Vec3, 6>& face_normals() const { return normals_; }
  // The distinct edge directions: 4 side edges and the 2 directions of the cap edges.
  const std::array<Vec3, 6>& edge_directions() const { return edges_; }
  // Whether `p` lies inside or on the frustum (no tolerance: used only to prove intersection).
  bool contains(const Vec3& p) const;

 private:
  std::array<Vec3, 8> corners_{};
  std::array<Vec3, 6> normals_{};    // oriented inward
  std::array<double, 6> offsets_{};  // inside: dot(normal, p) >= offset
  std::array<Vec3, 6> edges_{};
};

// Whether two frusta share any point (touching counts). Exact separating-axis test: face normals
// of both first, then a corner of one inside the other, then the 36 edge-pair axes.
bool frusta_intersect(const Frustum& a, const Frustum& b);

// A perspective viewing frustum, the viewer a culling test needs: apex `position`, looking along
// `forward` (need not be unit length) with `up` re-orthogonalised against it, vertical field of
// view `fov_y` (radians), aspect (width / height), near and far distances along `forward`
// (0 < near < far). A calf::Camera gives one with eye_view() (calf/format/camera.h).
struct EyeView {
  Vec3 position, forward{0, 0, -1}, up{0, 1, 0};
  double fov_y = 1.5707963267948966, aspect = 1, near = 0.01, far = 1000;
};
// Whether `forward` and `up` span a viewing frame: both finite, forward not zero, up not (nearly)
// parallel to it (|cross(normalize(forward), up)| > 1e-12 * max(1, |up|); the threshold grows with
// a long up, whose cross product with a unit forward grows with it). The one test of a viewer's
// axes, behind validate_camera (calf/format/camera.h) and eye_view_problem.
bool view_axes_usable(const Vec3& forward, const Vec3& up);

// Why `eye` cannot be culled against, or nullptr when it can: "position or axes not finite, zero
// or parallel" (position not finite, or !view_axes_usable), "field of view or aspect out of range"
// (fov_y outside (0, pi), aspect not finite and > 0), "needs 0 < near < far < inf".
const char* eye_view_problem(const EyeView& eye);

// The frustum of `eye`: f = forward / |forward|, r = normalize(cross(f, up)), u = cross(r, f);
// corner i at position + d * near (near cap) and position + d * far (far cap) with
// d = f + (r * (sx * tan(fov_y / 2) * aspect) + u * (sy * tan(fov_y / 2))) and
// (sx, sy) = (-1, -1), (1, -1), (1, 1), (-1, 1). `eye` must pass eye_view_problem (the decoder
// checks viewers before building their frusta).
Frustum eye_frustum(const EyeView& eye);

}  // namespace calf
