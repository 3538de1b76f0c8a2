// Tests of the cube-map conventions (format/include/calf/format/cube.h). Each would fail if the
// face order, orientation, pixel-centre rule or seam tie-break changed.
#include "calf/format/cube.h"

#include "calf/format/camera.h"

#include <gtest/gtest.h>

#include <cmath>

namespace calf {
namespace {

// atan2 of |a x b| and a . b stays accurate for tiny angles, where acos(a . b) does not.
double angle(const Vec3& a, const Vec3& b) {
  const double cx = a.y * b.z - a.z * b.y, cy = a.z * b.x - a.x * b.z, cz = a.x * b.y - a.y * b.x;
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot(a, b));
}

// The expected face centres and the directions of increasing s and t, straight from the OpenGL
// specification's table (written out independently of the implementation's table).
struct FaceExpectation {
  CubeFace face;
  Vec3 centre, s_axis, t_axis;
};
const FaceExpectation kExpected[] = {
    {CubeFace::kPosX, {1, 0, 0}, {0, 0, -1}, {0, -1, 0}},
    {CubeFace::kNegX, {-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
    {CubeFace::kPosY, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}},
    {CubeFace::kNegY, {0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
    {CubeFace::kPosZ, {0, 0, 1}, {1, 0, 0}, {0, -1, 0}},
    {CubeFace::kNegZ, {0, 0, -1}, {-1, 0, 0}, {0, -1, 0}},
};

TEST(CubeTest, FaceOrderMatchesOpenGL) {
  for (int i = 0; i < kCubeFaceCount; ++i) {
    EXPECT_EQ(cube_face_index(kExpected[i].face), i);
  }
  EXPECT_STREQ(cube_face_name(CubeFace::kNegY), "-Y");
}

TEST(CubeTest, CentresAndOrientationFollowTheGLTable) {
  for (const auto& e : kExpected) {
    const Vec3 c = direction_from_face_coord({e.face, 0.5, 0.5});
    EXPECT_NEAR(angle(c, e.centre), 0.0, 1e-12) << cube_face_name(e.face);
    // s = 1 leans the direction along s_axis, t = 1 along t_axis.
    const Vec3 s1 = direction_from_face_coord({e.face, 1.0, 0.5});
    const Vec3 t1 = direction_from_face_coord({e.face, 0.5, 1.0});
    EXPECT_NEAR(dot(s1, e.s_axis), std::sqrt(0.5), 1e-12) << cube_face_name(e.face);
    EXPECT_NEAR(dot(t1, e.t_axis), std::sqrt(0.5), 1e-12) << cube_face_name(e.face);
  }
}

TEST(CubeTest, RoundTripsAtCentresEdgesAndCorners) {
  const double coords[] = {0.0, 1e-9, 0.25, 0.5, 0.75, 1.0 - 1e-9};
  for (const auto& e : kExpected) {
    for (double s : coords) {
      for (double t : coords) {
        const Vec3 d = direction_from_face_coord({e.face, s, t});
        EXPECT_NEAR(std::sqrt(dot(d, d)), 1.0, 1e-12);
        const FaceCoord back = face_coord_from_direction(d);
        // Strictly inside a face the round trip is exact; on the s = 0 or t = 0 edge the
        // direction is on a seam and may belong to the neighbour, but it is the same direction.
        const Vec3 again = direction_from_face_coord(back);
        EXPECT_NEAR(angle(d, again), 0.0, 1e-12);
        if (s > 0 && t > 0) {
          EXPECT_EQ(back.face, e.face);
          EXPECT_NEAR(back.s, s, 1e-12);
          EXPECT_NEAR(back.t, t, 1e-12);
        }
      }
    }
  }
}

TEST(CubeTest, TexelCentresAreAtHalfIntegers) {
  const uint32_t n = 8;
  for (const auto& e : kExpected) {
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const Vec3 d = direction_from_texel(e.face, x, y, n);
        const FaceTexelCoord c = texel_coord_from_direction(d, n);
        EXPECT_EQ(c.face, e.face);
        EXPECT_NEAR(c.u, x + 0.5, 1e-9);
        EXPECT_NEAR(c.v, y + 0.5, 1e-9);
        const Texel t = texel_from_direction(d, n);
        EXPECT_EQ(t.face, e.face);
        EXPECT_EQ(t.x, x);
        EXPECT_EQ(t.y, y);
      }
    }
  }
  // Row 0 of +X looks up (toward -t, which is +y), column 0 toward +z.
  const Vec3 corner = direction_from_texel(CubeFace::kPosX, 0, 0, n);
  EXPECT_GT(corner.y, 0.0);
  EXPECT_GT(corner.z, 0.0);
}

TEST(CubeTest, SeamsAndCornersBelongToOneFaceInXYZOrder) {
  // Every seam direction (two equal magnitudes) and corner (three) maps to the first of its
  // axes in X, Y, Z order, for every sign combination.
  for (int sx = -1; sx <= 1; sx += 2) {
    for (int sy = -1; sy <= 1; sy += 2) {
      for (int sz = -1; sz <= 1; sz += 2) {
        const CubeFace x_face = sx > 0 ? CubeFace::kPosX : CubeFace::kNegX;
        const CubeFace y_face = sy > 0 ? CubeFace::kPosY : CubeFace::kNegY;
        EXPECT_EQ(face_coord_from_direction({1.0 * sx, 1.0 * sy, 1.0 * sz}).face, x_face);
        EXPECT_EQ(face_coord_from_direction({1.0 * sx, 1.0 * sy, 0.5 * sz}).face, x_face);
        EXPECT_EQ(face_coord_from_direction({1.0 * sx, 0.5 * sy, 1.0 * sz}).face, x_face);
        EXPECT_EQ(face_coord_from_direction({0.5 * sx, 1.0 * sy, 1.0 * sz}).face, y_face);
      }
    }
  }
  // Repeated lookups of the same seam direction agree (no dependence on anything but the value).
  const Vec3 seam{0.0, -0.7, 0.7};
  EXPECT_EQ(face_coord_from_direction(seam).face, CubeFace::kNegY);
  EXPECT_EQ(face_coord_from_direction(seam).face, face_coord_from_direction(seam).face);
}

// For each face edge texel, stepping one texel outward lands on the neighbouring face in the
// texel whose centre is the closest of all that face's texels (brute force), and that texel is no
// farther in angle than 1.5 in-face texel steps.
TEST(CubeTest, TexelsAcrossSeamsAreNeighboursInDirectionSpace) {
  const uint32_t n = 16;
  int seams_checked = 0;
  for (const auto& e : kExpected) {
    for (uint32_t i = 0; i < n; ++i) {
      const struct {
        uint32_t x, y;
        int du, dv;
      } edges[] = {{0, i, -1, 0}, {n - 1, i, 1, 0}, {i, 0, 0, -1}, {i, n - 1, 0, 1}};
      for (const auto& edge : edges) {
        const Vec3 inside = direction_from_texel(e.face, edge.x, edge.y, n);
        const Vec3 beyond =
            direction_from_texel_coord({e.face, edge.x + 0.5 + edge.du, edge.y + 0.5 + edge.dv}, n);
        const Texel across = texel_from_direction(beyond, n);
        ASSERT_NE(across.face, e.face);
        const Vec3 neighbour = direction_from_texel(across.face, across.x, across.y, n);
        double closest = 10;
        for (uint32_t y = 0; y < n; ++y) {
          for (uint32_t x = 0; x < n; ++x) {
            closest = std::min(closest, angle(inside, direction_from_texel(across.face, x, y, n)));
          }
        }
        EXPECT_NEAR(angle(inside, neighbour), closest, 1e-12)
            << cube_face_name(e.face) << " edge texel (" << edge.x << ", " << edge.y << ")";
        const Vec3 inward =
            direction_from_texel(e.face, static_cast<uint32_t>(static_cast<int>(edge.x) - edge.du),
                                 static_cast<uint32_t>(static_cast<int>(edge.y) - edge.dv), n);
        EXPECT_LT(angle(inside, neighbour), 1.5 * angle(inside, inward));
        ++seams_checked;
      }
    }
  }
  EXPECT_EQ(seams_checked, 6 * 4 * 16);
}

TEST(CubeTest, EveryDirectionOnASphereMapsToATexelThatMapsBack) {
  // A Fibonacci sphere of directions: each lands in a texel whose centre is within half a texel
  // diagonal of it.
  const uint32_t n = 64;
  const int count = 4000;
  for (int i = 0; i < count; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / count;
    const double r = std::sqrt(1.0 - z * z);
    const double phi = i * 2.399963229728653;
    const Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
    const Texel t = texel_from_direction(d, n);
    const Vec3 c = direction_from_texel(t.face, t.x, t.y, n);
    EXPECT_LT(angle(d, c), std::atan(std::sqrt(2.0) / n) + 1e-12);
  }
}

// Upright faces: a 90-degree camera looking along a face's major axis with the face's
// up vector, through the one camera model (camera.h, upright and unmirrored), sees at pixel
// (i, j) exactly what texel (N - 1 - i, j) holds; and the up / right table in cube.h is right.
TEST(CubeUprightFace, CameraPixelIsMirroredTexel) {
  struct Expected {
    Vec3 forward, up, right;
  };
  const Expected kTable[kCubeFaceCount] = {
      {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},   {{-1, 0, 0}, {0, 1, 0}, {0, 0, -1}},
      {{0, 1, 0}, {0, 0, -1}, {-1, 0, 0}}, {{0, -1, 0}, {0, 0, 1}, {-1, 0, 0}},
      {{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}},
  };
  constexpr uint32_t kN = 7;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    const UprightFace u = upright_face(face);
    EXPECT_EQ(u.forward, kTable[f].forward) << cube_face_name(face);
    EXPECT_EQ(u.up, kTable[f].up) << cube_face_name(face);
    EXPECT_EQ(cross(u.forward, u.up), kTable[f].right) << cube_face_name(face);
    Camera cam;
    cam.forward = u.forward;
    cam.up = u.up;
    cam.fov_y = 1.5707963267948966;
    cam.width = cam.height = kN;
    for (uint32_t j = 0; j < kN; ++j) {
      for (uint32_t i = 0; i < kN; ++i) {
        const Texel t = texel_from_upright_pixel(face, i, j, kN);
        EXPECT_EQ(t.face, face);
        EXPECT_LT(length(camera_ray(cam, i, j) - direction_from_texel(face, t.x, t.y, kN)), 1e-12)
            << cube_face_name(face) << " pixel " << i << ", " << j;
      }
    }
  }
}

}  // namespace
}  // namespace calf
