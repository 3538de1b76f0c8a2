// Tests of the shared geometry (format/include/calf/format/geometry.h): Vec3 operations, boxes,
// frusta and their intersection test. Expected values are worked out by hand in the comments.
#include "calf/format/geometry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace calf {
namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 v(double x, double y, double z) {
  return {x, y, z};
}

void expect_near_vec(const Vec3& got, const Vec3& want) {
  EXPECT_NEAR(got.x, want.x, 1e-15);
  EXPECT_NEAR(got.y, want.y, 1e-15);
  EXPECT_NEAR(got.z, want.z, 1e-15);
}

TEST(GeometryTest, VectorArithmetic) {
  const Vec3 a = v(1, 2, 3), b = v(4, -5, 6);
  EXPECT_EQ(a + b, v(5, -3, 9));
  EXPECT_EQ(a - b, v(-3, 7, -3));
  EXPECT_EQ(-a, v(-1, -2, -3));
  EXPECT_EQ(a * 2.0, v(2, 4, 6));
  EXPECT_EQ(0.5 * b, v(2, -2.5, 3));
  EXPECT_EQ(b / 2.0, v(2, -2.5, 3));
  Vec3 c = a;
  c += b;
  EXPECT_EQ(c, v(5, -3, 9));
  c -= b;
  EXPECT_EQ(c, a);
  // 1*4 + 2*(-5) + 3*6 = 4 - 10 + 18 = 12.
  EXPECT_EQ(dot(a, b), 12);
  // (2*6 - 3*(-5), 3*4 - 1*6, 1*(-5) - 2*4) = (27, 6, -13).
  EXPECT_EQ(cross(a, b), v(27, 6, -13));
  EXPECT_EQ(cross(v(1, 0, 0), v(0, 1, 0)), v(0, 0, 1));  // right-handed
  EXPECT_EQ(cross(v(0, 1, 0), v(1, 0, 0)), v(0, 0, -1));
  EXPECT_EQ(component(a, 0), 1);
  EXPECT_EQ(component(a, 1), 2);
  EXPECT_EQ(component(a, 2), 3);
}

TEST(GeometryTest, LengthNormalizeAngle) {
  EXPECT_EQ(length(v(3, 4, 12)), 13);  // 9 + 16 + 144 = 169
  EXPECT_EQ(length(v(0, 0, 0)), 0);
  // normalize multiplies by the reciprocal: (0, 3, 4) * 0.2 = (0, 0.6000000000000001, 0.8).
  const Vec3 n = normalize(v(0, 3, 4));
  EXPECT_EQ(n.x, 0);
  EXPECT_EQ(n.y, 3 * 0.2);
  EXPECT_EQ(n.z, 4 * 0.2);
  // Small but representable squares: (-1, 2, 2) * 1e-100 has length 3e-100.
  expect_near_vec(normalize(v(-1e-100, 2e-100, 2e-100)), v(-1.0 / 3, 2.0 / 3, 2.0 / 3));
  // No rescaling: components whose squares underflow (about 1e-162 and below) give no unit.
  EXPECT_FALSE(is_finite(normalize(v(1e-200, 0, 0))));
  EXPECT_DOUBLE_EQ(angle_between(v(1, 0, 0), v(0, 2, 0)), kPi / 2);
  EXPECT_DOUBLE_EQ(angle_between(v(1, 1, 0), v(1, 0, 0)), kPi / 4);
  EXPECT_EQ(angle_between(v(1, 0, 0), v(3, 0, 0)), 0);
  EXPECT_DOUBLE_EQ(angle_between(v(1, 0, 0), v(-1, 0, 0)), kPi);
  // A tiny angle stays accurate: atan2(1e-9, 1) = 1e-9 to 1e-25.
  EXPECT_NEAR(angle_between(v(1, 0, 0), v(1, 1e-9, 0)), 1e-9, 1e-24);
}

TEST(GeometryTest, Finiteness) {
  EXPECT_TRUE(is_finite(v(1e308, -1e308, 0)));
  EXPECT_FALSE(is_finite(v(0, std::numeric_limits<double>::infinity(), 0)));
  EXPECT_FALSE(is_finite(v(0, 0, std::nan(""))));
  EXPECT_FALSE(is_finite(v(-std::numeric_limits<double>::infinity(), 0, 0)));
}

TEST(GeometryTest, Boxes) {
  const Box3 b{v(0, 0, 0), v(1, 2, 3)};
  EXPECT_TRUE(b.contains(v(0.5, 1, 1.5)));
  EXPECT_TRUE(b.contains(v(0, 0, 0)));  // on the boundary
  EXPECT_TRUE(b.contains(v(1, 2, 3)));
  EXPECT_FALSE(b.contains(v(1.0000001, 1, 1)));
  EXPECT_FALSE(b.contains(v(0.5, -0.1, 1)));
  EXPECT_FALSE(b.contains(v(0.5, 1, 3.5)));
  EXPECT_FALSE(b.contains(v(0.5, 1, std::nan(""))));
  const Box3 point{v(5, 5, 5), v(5, 5, 5)};  // a point is a box
  EXPECT_TRUE(point.contains(v(5, 5, 5)));
  EXPECT_EQ(box_union(b, Box3{v(-1, 1, 4), v(0.5, 5, 6)}), (Box3{v(-1, 0, 0), v(1, 5, 6)}));
  EXPECT_EQ(box_union(b, v(2, -1, 1)), (Box3{v(0, -1, 0), v(2, 2, 3)}));
  EXPECT_EQ(box_union(b, v(0.5, 0.5, 0.5)), b);  // a point inside changes nothing
  // Growing an inverted (empty) box from nothing: the first point becomes the box.
  const double inf = std::numeric_limits<double>::infinity();
  const Box3 empty{v(inf, inf, inf), v(-inf, -inf, -inf)};
  EXPECT_EQ(box_union(empty, v(1, 2, 3)), (Box3{v(1, 2, 3), v(1, 2, 3)}));
}

// An axis-aligned box as a frustum (near cap at z0, far cap at z1).
Frustum box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return Frustum({v(x0, y0, z0), v(x1, y0, z0), v(x1, y1, z0), v(x0, y1, z0)},
                 {v(x0, y0, z1), v(x1, y0, z1), v(x1, y1, z1), v(x0, y1, z1)});
}

TEST(GeometryTest, FrustumCornersNormalsEdges) {
  const Frustum f = box(0, 0, 0, 1, 2, 3);
  EXPECT_EQ(f.corners()[0], v(0, 0, 0));
  EXPECT_EQ(f.corners()[2], v(1, 2, 0));
  EXPECT_EQ(f.corners()[6], v(1, 2, 3));
  // Side 0 through near 0, near 1, far 0: cross((1,0,0), (0,0,3)) = (0, -3, 0), which points out
  // of the box (y < 0 side); oriented inward it is (0, 3, 0).
  EXPECT_EQ(f.face_normals()[0], v(0, 3, 0));
  // Near cap: cross(n1 - n0, n3 - n0) = cross((1,0,0), (0,2,0)) = (0, 0, 2), already inward.
  EXPECT_EQ(f.face_normals()[4], v(0, 0, 2));
  // Far cap: the same (0, 0, 2), flipped inward to (0, 0, -2).
  EXPECT_EQ(f.face_normals()[5], v(0, 0, -2));
  EXPECT_EQ(f.edge_directions()[0], v(0, 0, 3));  // side edge
  EXPECT_EQ(f.edge_directions()[4], v(1, 0, 0));  // cap edges
  EXPECT_EQ(f.edge_directions()[5], v(0, 2, 0));
  EXPECT_TRUE(f.contains(v(0.5, 1, 1.5)));
  EXPECT_TRUE(f.contains(v(1, 2, 3)));  // a corner
  EXPECT_FALSE(f.contains(v(0.5, 1, 3.01)));
  EXPECT_FALSE(f.contains(v(-0.01, 1, 1)));
}

TEST(GeometryTest, SeparatingAxisBasics) {
  const Frustum a = box(0, 0, 0, 1, 1, 1);
  EXPECT_TRUE(frusta_intersect(a, a));
  EXPECT_TRUE(frusta_intersect(a, box(0.25, 0.25, 0.25, 0.5, 0.5, 0.5)));  // inside
  EXPECT_TRUE(frusta_intersect(a, box(1, 0, 0, 2, 1, 1)));                 // touching face
  EXPECT_FALSE(frusta_intersect(a, box(1.001, 0, 0, 2, 1, 1)));
  EXPECT_FALSE(frusta_intersect(a, box(2, 2, 2, 3, 3, 3)));
  // A square prism rotated 45 degrees about z beside the box's (1, 1) edge: only its own face
  // normal along x + y separates it when it is far enough out.
  const auto diamond = [](double c) {
    const double r = 0.75;
    return Frustum({v(c + r, c, -1), v(c, c + r, -1), v(c - r, c, -1), v(c, c - r, -1)},
                   {v(c + r, c, 2), v(c, c + r, 2), v(c - r, c, 2), v(c, c - r, 2)});
  };
  EXPECT_TRUE(frusta_intersect(a, diamond(1.3)));   // x + y edge at 1.85 < 2
  EXPECT_FALSE(frusta_intersect(a, diamond(1.4)));  // x + y edge at 2.05 > 2
  EXPECT_FALSE(frusta_intersect(diamond(1.4), a));  // symmetric
}

// Two diamond prisms whose ridges cross at right angles: A runs along z with cross-section
// |x| + |y| <= 0.5 (ridge at x = 0.5, y = 0), B runs along y with |x - c| + |z| <= 0.5 (ridge at
// x = c - 0.5, z = 0). The only separating axis is x = cross(A's side edge z, B's side edge y):
// every face normal overlaps (A's x +- y: A reaches 0.5, B down to c - 1.5; B's x +- z: B from
// c - 0.5, A up to 1.5; the caps +-z and +-y cover each other), so the edge-pair axes decide.
TEST(GeometryTest, SeparatedOnlyByAnEdgePairAxis) {
  const double r = 0.5;
  const Frustum a({v(r, 0, -1), v(0, r, -1), v(-r, 0, -1), v(0, -r, -1)},
                  {v(r, 0, 1), v(0, r, 1), v(-r, 0, 1), v(0, -r, 1)});
  const auto b = [&](double c) {
    return Frustum({v(c - r, -1, 0), v(c, -1, r), v(c + r, -1, 0), v(c, -1, -r)},
                   {v(c - r, 1, 0), v(c, 1, r), v(c + r, 1, 0), v(c, 1, -r)});
  };
  // c = 1.05: A's ridge at x = 0.5, B's at 0.55, a gap of 0.05 along x.
  EXPECT_FALSE(frusta_intersect(a, b(1.05)));
  EXPECT_FALSE(frusta_intersect(b(1.05), a));
  // c = 0.9: (0.45, 0, 0) lies in both (A: 0.45 <= 0.5; B: |0.45 - 0.9| = 0.45 <= 0.5), and no
  // corner of either is inside the other, so only the full test proves it.
  EXPECT_TRUE(frusta_intersect(a, b(0.9)));
  EXPECT_TRUE(frusta_intersect(b(0.9), a));
  const Frustum near_b = b(0.9);
  for (const Vec3& p : near_b.corners()) EXPECT_FALSE(a.contains(p));
  for (const Vec3& p : a.corners()) EXPECT_FALSE(near_b.contains(p));
  // c = 1: the ridges touch at (0.5, 0, 0): touching counts.
  EXPECT_TRUE(frusta_intersect(a, b(1.0)));
}

// The axes test of geometry.h: finite, forward not zero, up not within 1e-12 * max(1, |up|) of
// parallel to the unit forward.
TEST(GeometryTest, ViewAxesUsable) {
  EXPECT_TRUE(view_axes_usable(v(0, 0, -1), v(0, 1, 0)));
  EXPECT_TRUE(view_axes_usable(v(0, 0, -1e-3), v(0, 5, 0)));  // lengths need not be 1
  EXPECT_FALSE(view_axes_usable(v(0, 0, 0), v(0, 1, 0)));
  EXPECT_FALSE(view_axes_usable(v(0, 0, -1), v(0, 0, 3)));       // parallel
  EXPECT_FALSE(view_axes_usable(v(0, 0, -1), v(0, 1e-13, 1)));   // |cross| 1e-13 <= 1e-12
  EXPECT_TRUE(view_axes_usable(v(0, 0, -1), v(0, 1e-11, 1)));    // 1e-11 > 1e-12
  EXPECT_FALSE(view_axes_usable(v(0, 0, -1), v(0, 1e-9, 1e4)));  // threshold grows with |up|
  EXPECT_FALSE(view_axes_usable(v(std::nan(""), 0, -1), v(0, 1, 0)));
  EXPECT_FALSE(view_axes_usable(v(0, 0, -1), v(0, HUGE_VAL, 0)));
}

TEST(GeometryTest, EyeViewProblem) {
  EXPECT_EQ(eye_view_problem(EyeView{}), nullptr);
  EyeView e;
  e.position.y = HUGE_VAL;
  EXPECT_STREQ(eye_view_problem(e), "position or axes not finite, zero or parallel");
  e = EyeView{};
  e.up = e.forward;
  EXPECT_STREQ(eye_view_problem(e), "position or axes not finite, zero or parallel");
  e = EyeView{};
  e.fov_y = kPi;
  EXPECT_STREQ(eye_view_problem(e), "field of view or aspect out of range");
  e = EyeView{};
  e.aspect = 0;
  EXPECT_STREQ(eye_view_problem(e), "field of view or aspect out of range");
  e = EyeView{};
  e.near = 0;
  EXPECT_STREQ(eye_view_problem(e), "needs 0 < near < far < inf");
  e = EyeView{};
  e.far = HUGE_VAL;
  EXPECT_STREQ(eye_view_problem(e), "needs 0 < near < far < inf");
}

// eye_frustum's corners from the formula in geometry.h: position at the origin, looking down -Z
// with +Y up: f = (0, 0, -1), r = cross(f, up) = (1, 0, 0), u = cross(r, f) = (0, 1, 0). With a
// 90 degree fov, tan(fov / 2) = 1 (0.9999999999999999 in doubles), aspect 2 gives tx = 2: near
// corner 0 (sx = sy = -1) at distance 1 is (-2, -1, -1), far corner 2 at 10 is (20, 10, -10).
TEST(GeometryTest, EyeFrustumCorners) {
  EyeView eye;
  eye.position = v(0, 0, 0);
  eye.forward = v(0, 0, -3);  // need not be unit
  eye.up = v(0, 2, 0.5);      // re-orthogonalised
  eye.fov_y = kPi / 2;
  eye.aspect = 2;
  eye.near = 1;
  eye.far = 10;
  const Frustum f = eye_frustum(eye);
  const Vec3 expected[8] = {v(-2, -1, -1),    v(2, -1, -1),    v(2, 1, -1),    v(-2, 1, -1),
                            v(-20, -10, -10), v(20, -10, -10), v(20, 10, -10), v(-20, 10, -10)};
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(f.corners()[i].x, expected[i].x, 1e-14) << i;
    EXPECT_NEAR(f.corners()[i].y, expected[i].y, 1e-14) << i;
    EXPECT_NEAR(f.corners()[i].z, expected[i].z, 1e-14) << i;
  }
  // Shifted eye: every corner moves with it.
  eye.position = v(1, 2, 3);
  EXPECT_NEAR(eye_frustum(eye).corners()[6].x, 21, 1e-13);
  EXPECT_NEAR(eye_frustum(eye).corners()[6].z, -7, 1e-13);
  // The frustum holds the points straight ahead and rejects those behind or beside it.
  eye.position = v(0, 0, 0);
  const Frustum g = eye_frustum(eye);
  EXPECT_TRUE(g.contains(v(0, 0, -5)));
  EXPECT_TRUE(g.contains(v(3.9, 1.9, -2)));  // inside x <= 2 z, y <= z at z = 2
  EXPECT_FALSE(g.contains(v(4.1, 0, -2)));
  EXPECT_FALSE(g.contains(v(0, 0, 5)));
  EXPECT_FALSE(g.contains(v(0, 0, -0.5)));   // before the near plane
  EXPECT_FALSE(g.contains(v(0, 0, -10.5)));  // beyond the far plane
  // A box in front meets it, a box behind does not.
  EXPECT_TRUE(frusta_intersect(g, box(-0.5, -0.5, -6, 0.5, 0.5, -5)));
  EXPECT_FALSE(frusta_intersect(g, box(-0.5, -0.5, 5, 0.5, 0.5, 6)));
  EXPECT_FALSE(frusta_intersect(g, box(30, -0.5, -6, 31, 0.5, -5)));  // beside: x > 2 |z|
}

}  // namespace
}  // namespace calf
