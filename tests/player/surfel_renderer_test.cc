// The surfel splatters (calf/player/surfel_renderer.h): the CPU reference against discs and
// ellipses computed by hand, prefixes, ties, near clipping and validation; the GL splatter
// against the CPU one (headless OSMesa, small images).
#include "calf/player/surfel_renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "../gl_test_context.h"
#include "calf/player/gl_context.h"
#include "calf/player/image_compare.h"

namespace calf::player {
namespace {

using ::calf::test::gl_context;

// A camera at the origin looking down -z, 90 degrees vertical field of view.
Camera front_camera(uint32_t w, uint32_t h) {
  Camera c;
  c.position = {0, 0, 0};
  c.forward = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fov_y = 1.5707963267948966;
  c.width = w;
  c.height = h;
  return c;
}

// One prototype of the given surfels (position, normal, colour) and one object drawing them all.
SurfelDrawList one_object(const std::vector<std::array<float, 9>>& surfels, float radius) {
  SurfelDrawList list;
  SurfelDrawPrototype p;
  for (const auto& s : surfels) {
    p.positions.insert(p.positions.end(), s.begin(), s.begin() + 3);
    p.normals.insert(p.normals.end(), s.begin() + 3, s.begin() + 6);
    p.colours.insert(p.colours.end(), s.begin() + 6, s.end());
  }
  list.prototypes.push_back(p);
  SurfelDrawObject o;
  o.count = static_cast<uint32_t>(surfels.size());
  o.radius = radius;
  list.objects.push_back(o);
  return list;
}

RenderedImage cpu(const SurfelDrawList& list, const Camera& cam, SurfelRenderOptions o = {}) {
  RenderedImage out;
  const Status s = render_surfels_cpu(list, cam, o, &out);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

// The ray through pixel (i, j) of front_camera(w, h): (a, b, -1).
void ray(uint32_t w, uint32_t h, uint32_t i, uint32_t j, double* a, double* b) {
  *a = (2 * (i + 0.5) / w - 1) * w / h;
  *b = 1 - 2 * (j + 0.5) / h;
}

// A disc facing the camera at distance 5 (centre (0.5, -0.3, -5), radius 2): a pixel is covered
// exactly when its ray meets z = -5 within 2 of the centre, at radial depth 5 |d|; the shade is
// the colour times 0.3 + 0.7 L_z. Pixels within 1e-6 of the rim are not judged.
TEST(SurfelCpuRenderer, DiscFacingTheCameraCoversItsCircleAtRadialDepth) {
  const uint32_t w = 40, h = 30;
  const RenderedImage im =
      cpu(one_object({{0.5f, -0.3f, -5, 0, 0, 1, 0.8f, 0.4f, 0.2f}}, 2), front_camera(w, h));
  const double lit = 0.3 + 0.7 * 0.50507627;
  size_t inside = 0;
  for (uint32_t j = 0; j < h; ++j) {
    for (uint32_t i = 0; i < w; ++i) {
      double a, b;
      ray(w, h, i, j, &a, &b);
      const double x = 5 * a - 0.5, y = 5 * b + 0.3;
      const double r2 = x * x + y * y;
      const size_t k = size_t{j} * w + i;
      if (std::abs(r2 - 4) < 1e-6) continue;
      if (r2 < 4) {
        ++inside;
        const double expected = 5 * std::sqrt(a * a + b * b + 1);
        EXPECT_NEAR(im.depth[k], expected, 2e-6 * expected) << i << "," << j;
        EXPECT_NEAR(im.color[3 * k], 0.8 * lit, 1e-5);
        EXPECT_NEAR(im.color[3 * k + 2], 0.2 * lit, 1e-5);
      } else {
        EXPECT_TRUE(std::isinf(im.depth[k])) << i << "," << j;
        EXPECT_EQ(im.color[3 * k], 0.0f);
      }
    }
  }
  EXPECT_GT(inside, 40u);  // the disc is not a speck at this size
}

// A transform scaling x by 3 and moving by (0, 1, -6) makes the unit disc an ellipse with
// semi-axes 3 r and r; seen from behind (normal -z) it is drawn and shaded from its visible side.
TEST(SurfelCpuRenderer, ScaledTransformMakesAnEllipseSeenFromEitherSide) {
  const uint32_t w = 48, h = 32;
  SurfelDrawList list = one_object({{0, 0, 0, 0, 0, -1, 1, 1, 1}}, 0.5f);
  list.objects[0].transform = {3, 0, 0, 0, 0, 1, 0, 1, 0, 0, 1, -6};
  const RenderedImage im = cpu(list, front_camera(w, h));
  size_t judged = 0;
  for (uint32_t j = 0; j < h; ++j) {
    for (uint32_t i = 0; i < w; ++i) {
      double a, b;
      ray(w, h, i, j, &a, &b);
      const double x = 6 * a / 1.5, y = (6 * b - 1) / 0.5;
      const double e = x * x + y * y;
      if (std::abs(e - 1) < 1e-6) continue;
      ++judged;
      EXPECT_EQ(std::isfinite(im.depth[size_t{j} * w + i]), e < 1) << i << "," << j;
    }
  }
  EXPECT_EQ(judged, size_t{w} * h);
  const size_t centre = size_t{h / 2 - 3} * w + w / 2;              // (0, ~1, -6) region
  EXPECT_NEAR(im.color[3 * centre], 0.3 + 0.7 * 0.50507627, 1e-5);  // the side facing +z
}

TEST(SurfelCpuRenderer, EdgeOnDiscsAndEmptyPrefixesDrawNothing) {
  const Camera cam = front_camera(32, 32);
  // Normal +x, centred on the axis: the camera's rays through pixel centres never lie in its plane
  // except x = 0, which no pixel centre of an even width has.
  const RenderedImage edge_on = cpu(one_object({{0, 0, -4, 1, 0, 0, 1, 1, 1}}, 1), cam);
  for (float d : edge_on.depth) EXPECT_TRUE(std::isinf(d));
  SurfelDrawList list = one_object({{0, 0, -4, 0, 0, 1, 1, 1, 1}}, 1);
  list.objects[0].count = 0;
  for (float d : cpu(list, cam).depth) EXPECT_TRUE(std::isinf(d));
}

// A prefix draws only its surfels; of two coincident discs the first drawn keeps the pixel.
TEST(SurfelCpuRenderer, PrefixesAndTiesFollowBufferOrder) {
  const Camera cam = front_camera(24, 24);
  SurfelDrawList list = one_object(
      {{-1, 0, -3, 0, 0, 1, 1, 0, 0}, {-1, 0, -3, 0, 0, 1, 0, 1, 0}, {1, 0, -3, 0, 0, 1, 0, 0, 1}},
      0.5f);
  const RenderedImage all = cpu(list, cam);
  const size_t left = size_t{12} * 24 + 6, right = size_t{12} * 24 + 17;
  ASSERT_TRUE(std::isfinite(all.depth[left]));
  EXPECT_GT(all.color[3 * left], 0.0f);       // red: the first of the tie
  EXPECT_EQ(all.color[3 * left + 1], 0.0f);   // not green
  EXPECT_GT(all.color[3 * right + 2], 0.0f);  // blue
  list.objects[0].count = 2;
  const RenderedImage two = cpu(list, cam);
  EXPECT_TRUE(std::isfinite(two.depth[left]));
  EXPECT_TRUE(std::isinf(two.depth[right]));
}

// A disc lying along the view axis (normal +y, centre 2 ahead, radius 3) crosses the near plane:
// only hits beyond `near` along forward are drawn.
TEST(SurfelCpuRenderer, NearPlaneClips) {
  const uint32_t w = 32, h = 32;
  const SurfelDrawList list = one_object({{0, -1, -2, 0, 1, 0, 1, 1, 1}}, 3);
  SurfelRenderOptions o;
  o.near = 1.5;
  const RenderedImage im = cpu(list, front_camera(w, h), o);
  size_t drawn = 0;
  for (uint32_t j = 0; j < h; ++j) {
    for (uint32_t i = 0; i < w; ++i) {
      double a, b;
      ray(w, h, i, j, &a, &b);
      const size_t k = size_t{j} * w + i;
      if (!(b < 0)) {
        EXPECT_TRUE(std::isinf(im.depth[k]));
        continue;
      }
      const double t = 1 / -b;  // the ray meets y = -1 at forward distance t
      const double x = a * t, z = -t + 2;
      const double r2 = x * x + z * z;
      if (std::abs(r2 - 9) < 1e-6 || std::abs(t - 1.5) < 1e-6) continue;
      const bool expected = r2 < 9 && t > 1.5;
      EXPECT_EQ(std::isfinite(im.depth[k]), expected) << i << "," << j;
      drawn += expected ? 1 : 0;
    }
  }
  EXPECT_GT(drawn, 20u);
}

TEST(SurfelDrawList, InvalidListsAndOptionsAreNamed) {
  const Camera cam = front_camera(8, 8);
  RenderedImage out;
  const auto error_of = [&](const SurfelDrawList& l, SurfelRenderOptions o = {}) {
    return render_surfels_cpu(l, cam, o, &out);
  };
  const SurfelDrawList good = one_object({{0, 0, -3, 0, 0, 1, 1, 1, 1}}, 1);
  EXPECT_TRUE(error_of(good).ok());
  SurfelDrawList bad = good;
  bad.prototypes[0].normals[2] = 0.5f;
  Status s = error_of(bad);
  EXPECT_EQ(s.id(), ErrorId::kSurfelDrawList);
  EXPECT_NE(s.message().find("surfel 0"), std::string::npos) << s.message();
  bad = good;
  bad.objects[0].count = 2;
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  bad = good;
  bad.objects[0].radius = 0;
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  bad.objects[0].count = 0;  // a radius matters only when something is drawn
  EXPECT_TRUE(error_of(bad).ok());
  bad = good;
  bad.objects[0].transform[0] = 0;
  bad.objects[0].transform[5] = 0;
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  bad = good;
  bad.prototypes[0].colours[1] = -1;
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  bad = good;
  bad.prototypes[0].positions.push_back(1);
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  bad = good;
  bad.objects[0].prototype = 1;
  EXPECT_EQ(error_of(bad).id(), ErrorId::kSurfelDrawList);
  SurfelRenderOptions o;
  o.near = 0;
  EXPECT_EQ(error_of(good, o).id(), ErrorId::kSurfelRenderOptions);
  o.near = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(error_of(good, o).id(), ErrorId::kSurfelRenderOptions);
}

// Surfels on a sphere of radius 1 at (-0.8, 0, -2.2) (a Fibonacci lattice, colour from the normal),
// two objects: the sphere and a scaled, rotated copy.
SurfelDrawList sphere_scene(uint32_t n) {
  std::vector<std::array<float, 9>> s;
  const double golden = 2.399963229728653;
  for (uint32_t i = 0; i < n; ++i) {
    const double y = 1 - 2 * (i + 0.5) / n, r = std::sqrt(1 - y * y), phi = golden * i;
    const float x = static_cast<float>(r * std::cos(phi)),
                z = static_cast<float>(r * std::sin(phi));
    const float yy = static_cast<float>(y);
    const float len = std::sqrt(x * x + yy * yy + z * z);
    s.push_back(
        {x, yy, z, x / len, yy / len, z / len, 0.5f + 0.4f * x, 0.5f + 0.4f * yy, 0.5f + 0.4f * z});
  }
  SurfelDrawList list = one_object(s, 0.09f);
  list.objects[0].transform = {1, 0, 0, -0.8f, 0, 1, 0, 0, 0, 0, 1, -2.2f};
  SurfelDrawObject copy = list.objects[0];
  copy.transform = {0, 0, 1.2f, 1.0f, 0, 0.7f, 0, 0.3f, -1, 0, 0, -3};
  copy.count = n / 2;
  copy.radius = 0.12f;
  list.objects.push_back(copy);
  return list;
}

TEST(SurfelGlRenderer, AgreesWithCpuReference) {
  CALF_REQUIRE_GL();
  const SurfelDrawList list = sphere_scene(1500);
  auto gl = GlSurfelRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().message();
  ASSERT_TRUE((*gl)->upload(list).ok());
  Camera poses[2] = {front_camera(96, 80), front_camera(96, 80)};
  poses[1].position = {0.5, 1.5, 0.5};
  poses[1].forward = {-0.1, -0.35, -1};
  for (const Camera& cam : poses) {
    RenderedImage g;
    const Status s = (*gl)->render(list, cam, {}, &g);
    ASSERT_TRUE(s.ok()) << s.message();
    const RenderedImage c = cpu(list, cam);
    size_t covered = 0, differing = 0;
    RenderedImage same_surface = g;
    for (size_t k = 0; k < g.depth.size(); ++k) {
      covered += std::isfinite(c.depth[k]) ? 1 : 0;
      const float x = g.depth[k], y = c.depth[k];
      if ((std::isinf(x) && std::isinf(y)) || std::abs(x - y) <= 1e-4f * std::min(x, y)) continue;
      ++differing;
      for (int ch = 0; ch < 3; ++ch) same_surface.color[3 * k + ch] = c.color[3 * k + ch];
    }
    const double p = *psnr(rgb_ref(g), rgb_ref(c)),
                 p_same = *psnr(rgb_ref(same_surface), rgb_ref(c));
    std::printf(
        "GL vs CPU: %zu of %zu pixels covered, %zu depths differ, PSNR %.2f dB (%.2f dB where both "
        "show the same disc)\n",
        covered, g.depth.size(), differing, p, p_same);
    EXPECT_GT(covered, g.depth.size() / 10);
    // Where discs overlap at a rim, float rounding may pick the other disc: a few pixels.
    EXPECT_LE(differing, g.depth.size() / 100);
    EXPECT_GE(p_same, 50.0);
  }
}

TEST(SurfelGlRenderer, StructureChecks) {
  CALF_REQUIRE_GL();
  SurfelDrawList list = sphere_scene(64);
  auto gl = GlSurfelRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok());
  ASSERT_TRUE((*gl)->upload(list).ok());
  RenderedImage out;
  list.objects[0].count = 10;  // prefixes may change between renders
  EXPECT_TRUE((*gl)->render(list, front_camera(16, 16), {}, &out).ok());
  list.prototypes.push_back(list.prototypes[0]);
  EXPECT_EQ((*gl)->render(list, front_camera(16, 16), {}, &out).id(), ErrorId::kSurfelGlStructure);
}

}  // namespace
}  // namespace calf::player
