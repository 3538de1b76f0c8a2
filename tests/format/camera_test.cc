// Tests of the one camera model (format/include/calf/format/camera.h): pixel rays worked out by
// hand for small images at known poses, the exact operation order of the documented formula,
// validation messages and the frustum of a camera.
#include "calf/format/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace calf {
namespace {

constexpr double kPi = 3.14159265358979323846;

void expect_near(const Vec3& got, const Vec3& want, double tolerance = 1e-15) {
  EXPECT_NEAR(got.x, want.x, tolerance);
  EXPECT_NEAR(got.y, want.y, tolerance);
  EXPECT_NEAR(got.z, want.z, tolerance);
}

// A 2 x 2 camera at the origin looking down -Z, +Y up, 90 degrees: h = tan(45 deg) = 1, the
// pixel centres at a, b = -+0.5, so pixel (0, 0) (top left) looks along (-0.5, 0.5, -1) and
// pixel (1, 1) (bottom right) along (0.5, -0.5, -1), each divided by sqrt(1.5).
TEST(CameraTest, TwoByTwoRaysLookingDownMinusZ) {
  Camera c;
  c.fov_y = kPi / 2;
  c.width = c.height = 2;
  ASSERT_TRUE(validate_camera(c).ok());
  const double s = 1 / std::sqrt(1.5);
  expect_near(camera_ray(c, 0, 0), {-0.5 * s, 0.5 * s, -s});
  expect_near(camera_ray(c, 1, 0), {0.5 * s, 0.5 * s, -s});
  expect_near(camera_ray(c, 0, 1), {-0.5 * s, -0.5 * s, -s});
  expect_near(camera_ray(c, 1, 1), {0.5 * s, -0.5 * s, -s});
  // The position does not change directions.
  c.position = {10, -20, 30};
  expect_near(camera_ray(c, 1, 0), {0.5 * s, 0.5 * s, -s});
}

// A pose that exercises the frame: forward (2, 0, 0) (not unit), up (0, 0, 5) (not unit):
// f = (1, 0, 0), r = normalize(cross(f, up)) = normalize((0, -5, 0)) = (0, -1, 0),
// u = cross(r, f) = (0, 0, 1). A 4 x 2 image (aspect 2) at 90 degrees: pixel (3, 0) has
// a = 2 * 3.5 / 4 - 1 = 0.75, b = 1 - 2 * 0.5 / 2 = 0.5, so
// d = f + r * (0.75 * 1 * 2) + u * 0.5 = (1, -1.5, 0.5), over sqrt(3.5); pixel (0, 1) has
// a = -0.75, b = -0.5: (1, 1.5, -0.5) / sqrt(3.5).
TEST(CameraTest, FourByTwoRaysAtATurnedPose) {
  Camera c;
  c.position = {1, 2, 3};
  c.forward = {2, 0, 0};
  c.up = {0, 0, 5};
  c.fov_y = kPi / 2;
  c.width = 4;
  c.height = 2;
  ASSERT_TRUE(validate_camera(c).ok());
  const CameraFrame f = camera_frame(c);
  EXPECT_EQ(f.forward, (Vec3{1, 0, 0}));
  EXPECT_EQ(f.right, (Vec3{0, -1, 0}));
  EXPECT_EQ(f.up, (Vec3{0, 0, 1}));
  const double s = 1 / std::sqrt(3.5);
  expect_near(camera_ray(c, 3, 0), {s, -1.5 * s, 0.5 * s});
  expect_near(camera_ray(c, 0, 1), {s, 1.5 * s, -0.5 * s});
  // Pixel (1, 0): a = -0.25, b = 0.5: (1, 0.5, 0.5) / sqrt(1.5).
  const double t = 1 / std::sqrt(1.5);
  expect_near(camera_ray(c, 1, 0), {t, 0.5 * t, 0.5 * t});
}

// A 1 x 1 image at 60 degrees looks straight ahead; a 3 x 1 image's outer pixels sit at
// a = -+2/3 with h = tan(30 deg) = 1/sqrt(3) and aspect 3: d = f -+ r * (2/3 * 3 / sqrt(3))
// = f -+ r * (2 / sqrt(3)), i.e. at atan(2 / sqrt(3)) = 49.1066 degrees off axis.
TEST(CameraTest, SinglePixelAndWideStrip) {
  Camera c;
  c.forward = {0, 0, -1};
  c.fov_y = kPi / 3;
  c.width = c.height = 1;
  expect_near(camera_ray(c, 0, 0), {0, 0, -1});
  c.width = 3;
  const Vec3 d = camera_ray(c, 2, 0);
  EXPECT_NEAR(std::atan2(d.x, -d.z), std::atan(2 / std::sqrt(3.0)), 1e-15);
  EXPECT_NEAR(d.y, 0, 1e-15);
  expect_near(camera_ray(c, 0, 0), {-d.x, d.y, d.z});  // mirror image
  expect_near(camera_ray(c, 1, 0), {0, 0, -1});
}

// The formula of camera.h written out again in its documented order: camera_ray must give the
// very same doubles (the renderers' frames and the ground truth depend on these bits).
Vec3 documented_ray(const Camera& c, uint32_t i, uint32_t j) {
  const auto unit = [](double x, double y, double z) {
    const double inv = 1.0 / std::sqrt(x * x + y * y + z * z);
    return Vec3{x * inv, y * inv, z * inv};
  };
  const Vec3 f = unit(c.forward.x, c.forward.y, c.forward.z);
  const Vec3 rr{f.y * c.up.z - f.z * c.up.y, f.z * c.up.x - f.x * c.up.z,
                f.x * c.up.y - f.y * c.up.x};
  const Vec3 r = unit(rr.x, rr.y, rr.z);
  const Vec3 u{r.y * f.z - r.z * f.y, r.z * f.x - r.x * f.z, r.x * f.y - r.y * f.x};
  const double h = std::tan(c.fov_y / 2);
  const double a = 2.0 * (i + 0.5) / c.width - 1.0;
  const double b = 1.0 - 2.0 * (j + 0.5) / c.height;
  const double w = static_cast<double>(c.width) / c.height;
  const double sa = a * h * w, sb = b * h;
  return unit(f.x + r.x * sa + u.x * sb, f.y + r.y * sa + u.y * sb, f.z + r.z * sa + u.z * sb);
}

TEST(CameraTest, RayIsBitExactToTheDocumentedOrder) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> any(-3, 3), fov(0.1, 3.0);
  std::uniform_int_distribution<uint32_t> size(1, 40);
  for (int k = 0; k < 200; ++k) {
    Camera c;
    c.position = {any(rng), any(rng), any(rng)};
    c.forward = {any(rng), any(rng), any(rng)};
    c.up = {any(rng), any(rng), any(rng)};
    c.fov_y = fov(rng);
    c.width = size(rng);
    c.height = size(rng);
    if (!validate_camera(c).ok()) continue;
    const CameraFrame frame = camera_frame(c);
    for (uint32_t j = 0; j < c.height; j += 3) {
      for (uint32_t i = 0; i < c.width; i += 3) {
        const Vec3 want = documented_ray(c, i, j);
        EXPECT_EQ(camera_ray(c, i, j), want) << k << " " << i << " " << j;
        EXPECT_EQ(camera_ray(c, frame, i, j), want);
      }
    }
  }
}

void expect_refused(const Camera& c, const std::string& message) {
  const Status s = validate_camera(c);
  EXPECT_EQ(s.id(), ErrorId::kPlayerOptions);
  EXPECT_NE(s.to_string().find("CALF-E403"), std::string::npos) << s.to_string();
  EXPECT_NE(s.to_string().find(message), std::string::npos) << s.to_string();
}

TEST(CameraTest, Validation) {
  const std::string degenerate = "camera position, forward or up is not finite, zero or parallel";
  const double inf = std::numeric_limits<double>::infinity();
  Camera c;
  EXPECT_TRUE(validate_camera(c).ok());  // the defaults are valid
  c.position.y = std::nan("");
  expect_refused(c, degenerate);
  c = Camera{};
  c.up.x = inf;
  expect_refused(c, degenerate);
  c = Camera{};
  c.forward = {0, 0, 0};
  expect_refused(c, degenerate);
  c = Camera{};
  c.forward = {0, 3, 0};  // parallel to up
  expect_refused(c, degenerate);
  c.up = {0, 0, 0};  // zero up
  expect_refused(c, degenerate);
  // Nearly parallel: forward +Y, up (1e-13, 1, 0): |cross(f, up)| = 1e-13 <= 1e-12 * max(1, |up|)
  // is refused; 1e-11 is not.
  c = Camera{};
  c.forward = {0, 1, 0};
  c.up = {1e-13, 1, 0};
  expect_refused(c, degenerate);
  c.up = {1e-11, 1, 0};
  EXPECT_TRUE(validate_camera(c).ok());
  c = Camera{};
  c.fov_y = 0;
  expect_refused(c, "camera fov_y 0.000000 is outside (0, pi)");
  c.fov_y = kPi;
  expect_refused(c, "is outside (0, pi)");
  c.fov_y = std::nan("");
  expect_refused(c, "is outside (0, pi)");
  c.fov_y = 3.1415926;
  EXPECT_TRUE(validate_camera(c).ok());
  c = Camera{};
  c.width = 0;
  expect_refused(c, "image size 0 x 64 is outside 1..16384");
  c.width = 16384;
  c.height = 16384;
  EXPECT_TRUE(validate_camera(c).ok());
  c.height = 16385;
  expect_refused(c, "image size 16384 x 16385 is outside 1..16384");
  // The first reason found wins: a bad frame before a bad size.
  c.forward = {0, 0, 0};
  expect_refused(c, degenerate);
}

// The frustum of a camera: a 4 x 2, 90 degree camera at (1, 0, 0) looking down -Z, from distance
// 1 to 4; the rays through every pixel centre stay inside.
TEST(CameraTest, FrustumOfACamera) {
  Camera c;
  c.position = {1, 0, 0};
  c.fov_y = kPi / 2;
  c.width = 4;
  c.height = 2;
  const EyeView e = eye_view(c, 1, 4);
  EXPECT_EQ(e.position, c.position);
  EXPECT_EQ(e.forward, c.forward);
  EXPECT_EQ(e.up, c.up);
  EXPECT_EQ(e.fov_y, c.fov_y);
  EXPECT_EQ(e.aspect, 2);
  EXPECT_EQ(e.near, 1);
  EXPECT_EQ(e.far, 4);
  const Frustum f = camera_frustum(c, 1, 4);
  // aspect 2: near corners at x = 1 -+ 2, y = -+1, z = -1; far at x = 1 -+ 8, y = -+4, z = -4.
  expect_near(f.corners()[0], {-1, -1, -1}, 1e-14);
  expect_near(f.corners()[2], {3, 1, -1}, 1e-14);
  expect_near(f.corners()[4], {-7, -4, -4}, 1e-14);
  expect_near(f.corners()[6], {9, 4, -4}, 1e-14);
  for (uint32_t j = 0; j < c.height; ++j) {
    for (uint32_t i = 0; i < c.width; ++i) {
      const Vec3 d = camera_ray(c, i, j);
      // A point on the ray at axial distance 2 (between near 1 and far 4).
      const Vec3 p = c.position + d * (2 / -d.z);
      EXPECT_TRUE(f.contains(p)) << i << " " << j;
    }
  }
}

}  // namespace
}  // namespace calf
