// Converged, anti-aliased rendering in calf-capture (calf/samples/render.h, pixel_samples.h;
// docs/RENDERING.md "Converged capture"): stratified sample positions, box-filtered edge pixels,
// the centre-ray depth rule, agreement between seeds, and spp = 1 as calf rendered before.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "calf/format/colour.h"
#include "calf/format/cube.h"
#include "calf/samples/pixel_samples.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace calf::samples {
namespace {

// Every prefix of 2^m points is a (0, m, 2)-net: one point in each cell of every 2^a x 2^b grid.
TEST(PixelSamples, EveryPowerOfTwoPrefixIsStratified) {
  for (uint32_t scramble : {0u, 0x9E3779B9u, 0xFFFFFFFFu, 0x12345678u}) {
    const uint32_t sx = scramble, sy = scramble * 2654435761u + 7;
    for (uint32_t m = 0; m <= 8; ++m) {
      const uint32_t count = 1u << m;
      for (uint32_t a = 0; a <= m; ++a) {
        const uint32_t cols = 1u << a, rows = 1u << (m - a);
        std::vector<int> cells(count, 0);
        for (uint32_t i = 0; i < count; ++i) {
          const SamplePoint p = scrambled_sequence_point(i, sx, sy);
          ASSERT_GE(p.x, 0.0f);
          ASSERT_LT(p.x, 1.0f);
          ASSERT_GE(p.y, 0.0f);
          ASSERT_LT(p.y, 1.0f);
          ++cells[static_cast<uint32_t>(p.y * rows) * cols + static_cast<uint32_t>(p.x * cols)];
        }
        for (int c : cells) ASSERT_EQ(c, 1) << count << " points, " << cols << " x " << rows;
      }
    }
  }
  // Different scrambles give different points (the pixels' patterns are independent).
  EXPECT_NE(scrambled_sequence_point(3, 0x10000000u, 2).x,
            scrambled_sequence_point(3, 0x50000000u, 2).x);
}

// A black, unlit world: colour comes from emitters alone.
Scene dark_scene() {
  Scene s;
  s.name = "edge";
  Material light;
  light.albedo = glm::vec3(0);
  light.emission = glm::vec3(1);
  s.materials = {light};
  s.sky.zenith = s.sky.horizon = s.sky.ground = glm::vec3(0);
  s.ambient = glm::vec3(0);
  return s;
}

// A triangle of emitter through the three points.
Object emitter(const Vec3& a, const Vec3& b, const Vec3& c) {
  Object o;
  o.name = "emitter";
  for (const Vec3& p : {a, b, c}) {
    o.mesh.positions.emplace_back(static_cast<float>(p.x), static_cast<float>(p.y),
                                  static_cast<float>(p.z));
  }
  o.mesh.triangles.emplace_back(0, 1, 2);
  return o;
}

// The point of face +X's plane x = 1 at texel-space position (u, v) of a face of n texels.
Vec3 on_pos_x(double u, double v, uint32_t n) {
  const Vec3 d = direction_from_texel_coord({CubeFace::kPosX, u, v}, n);
  return d * (1.0 / d.x);
}

LightfieldRenderOptions fixed_spp(uint32_t spp) {
  LightfieldRenderOptions o;
  o.threads = 1;
  o.spp = spp;
  o.min_spp = spp;
  o.tolerance = 0;
  o.ao_samples = 0;
  return o;
}

// Texel (0, 0) of a 2 x 2 face +X, covered on the side u < edge by an emitter (radiance 1) on the
// plane x = 1: its colour must be the covered share of its square, its depth the centre ray's.
struct EdgeTexel {
  float color = 0, depth = 0;
};
EdgeTexel render_edge(double edge, uint32_t spp) {
  Scene s = dark_scene();
  const uint32_t n = 2;
  s.objects.push_back(emitter(on_pos_x(-9, -9, n), on_pos_x(-9, 9, n), on_pos_x(edge, -9, n)));
  s.objects.push_back(emitter(on_pos_x(edge, -9, n), on_pos_x(-9, 9, n), on_pos_x(edge, 9, n)));
  auto tracer = FrameTracer::create(s, 0, fixed_spp(spp));
  EXPECT_TRUE(tracer.ok()) << tracer.status().to_string();
  if (!tracer.ok()) return {};
  capture::ViewFrame f;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, n, false, &f);
  const size_t i = static_cast<size_t>(cube_face_index(CubeFace::kPosX)) * n * n;  // (0, 0)
  return {f.color[3 * i], f.depth[i]};
}

TEST(Antialias, AnEdgeTexelIsTheMeanOfItsCoverage) {
  // 64 samples are one per 1/8 x 1/8 cell and one per 1/64 column: an edge at half the texel
  // splits the cells exactly; at 0.4 or 0.6 one column of 1/64 is uncertain.
  EXPECT_EQ(render_edge(0.5, 64).color, 0.5f);
  EXPECT_NEAR(render_edge(0.4, 64).color, 0.4f, 1.0 / 64 + 1e-6);
  EXPECT_NEAR(render_edge(0.6, 64).color, 0.6f, 1.0 / 64 + 1e-6);
  EXPECT_NEAR(render_edge(0.25, 16).color, 0.25f, 1.0 / 16 + 1e-6);
  // One sample is the centre: all or nothing.
  EXPECT_EQ(render_edge(0.4, 1).color, 0.0f);
  EXPECT_EQ(render_edge(0.6, 1).color, 1.0f);
}

// Coverage of texel (32, 32) of face +X (64 texels; near the face centre, where the plane x = 1
// is one surface within the tolerance across a texel), covered on the side u < 32 + edge by an
// emitter: the 4 x 4 cells' centres lie at 0.125, 0.375, 0.625, 0.875 of the texel, so the
// edge's position decides each column.
struct EdgeCoverage {
  float near = -1, far = -1, mask = -1;
};
EdgeCoverage render_edge_coverage(double edge, uint32_t spp) {
  Scene s = dark_scene();
  const uint32_t n = 64;
  const double e = 32 + edge;
  s.objects.push_back(
      emitter(on_pos_x(-100, -100, n), on_pos_x(-100, 200, n), on_pos_x(e, -100, n)));
  s.objects.push_back(emitter(on_pos_x(e, -100, n), on_pos_x(-100, 200, n), on_pos_x(e, 200, n)));
  auto tracer = FrameTracer::create(s, 0, fixed_spp(spp));
  EXPECT_TRUE(tracer.ok()) << tracer.status().to_string();
  if (!tracer.ok()) return {};
  capture::ViewFrame f;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, n, false, &f, /*with_coverage=*/true);
  EXPECT_TRUE(f.has_coverage);
  if (f.coverage.size() != 3 * f.texel_count()) return {};
  const size_t i = f.texel_index(CubeFace::kPosX, 32, 32);
  return {f.coverage[3 * i], f.coverage[3 * i + 1], f.coverage[3 * i + 2]};
}

TEST(Coverage, TheCellsOfAnEdgeTexel) {
  // Centre covered (edge at 0.6 and 0.7 of the texel): the cells beyond the edge see sky, farther
  // than the texel's depth. Columns 0-1 (0.6) or 0-2 (0.7) are the texel's own surface.
  for (uint32_t spp : {1u, 16u}) {  // coverage does not depend on the colour's samples
    EdgeCoverage c = render_edge_coverage(0.6, spp);
    EXPECT_EQ(c.near, 0.0f);
    EXPECT_EQ(c.far, 0.5f);
    EXPECT_EQ(c.mask, float{0x3333});
    c = render_edge_coverage(0.7, spp);
    EXPECT_EQ(c.near, 0.0f);
    EXPECT_EQ(c.far, 0.25f);
    EXPECT_EQ(c.mask, float{0x7777});
  }
  // Centre uncovered (edge at 0.4): the texel is sky; the emitter in columns 0-1 is nearer.
  EdgeCoverage c = render_edge_coverage(0.4, 16);
  EXPECT_EQ(c.near, 0.5f);
  EXPECT_EQ(c.far, 0.0f);
  EXPECT_EQ(c.mask, float{0xCCCC});
  // A texel the emitter covers wholly: its own surface in every cell.
  c = render_edge_coverage(1.9, 16);
  EXPECT_EQ(c.near, 0.0f);
  EXPECT_EQ(c.far, 0.0f);
  EXPECT_EQ(c.mask, float{0xFFFF});
}

TEST(Antialias, DepthIsTheCentreRaysAtAnEdge) {
  // Centre (0.5, 0.5) uncovered: sky (+inf) though 40 % of the texel shows the emitter.
  EXPECT_TRUE(std::isinf(render_edge(0.4, 64).depth));
  // Centre covered: the plane's exact distance along the centre ray, not a mean or a minimum.
  const Vec3 centre = direction_from_texel(CubeFace::kPosX, 0, 0, 2);
  EXPECT_NEAR(render_edge(0.6, 64).depth, 1.0 / centre.x, 1e-5);
  // The same depth and material whatever spp, on a scene with every kind of surface.
  auto scene = make_builtin_scene("mirror-box");
  ASSERT_TRUE(scene.ok());
  capture::ViewFrame one, many;
  auto t1 = FrameTracer::create(*scene, 0, fixed_spp(1));
  auto t16 = FrameTracer::create(*scene, 0, fixed_spp(16));
  ASSERT_TRUE(t1.ok() && t16.ok());
  const Vec3 p = scene->default_rig.viewpoints[0].position;
  (*t1)->render_cube(p, 0, 0, 12, true, &one);
  (*t16)->render_cube(p, 0, 0, 12, true, &many);
  EXPECT_EQ(one.depth, many.depth);
  EXPECT_EQ(one.material, many.material);
  EXPECT_NE(one.color, many.color);
}

// Pixel (0, 0) of a 2 x 2 image with a 90 degree field of view looking down -Z: its square is
// x in [-1, 0], y in [0, 1] on the plane z = -1 (format/CAPTURE.md's camera model). An emitter
// covering x < -0.5 there covers half of it.
TEST(Antialias, AHalfCoveredGroundTruthPixelIsHalfAndHalf) {
  Scene s = dark_scene();
  s.objects.push_back(emitter({-9, -9, -1}, {-0.5, -9, -1}, {-9, 9, -1}));
  s.objects.push_back(emitter({-0.5, -9, -1}, {-0.5, 9, -1}, {-9, 9, -1}));
  capture::EyePose pose;
  pose.position = {0, 0, 0};
  pose.forward = {0, 0, -1};
  pose.fov_y_degrees = 90;
  capture::PerspectiveImage image;
  for (uint32_t spp : {1u, 4u, 64u}) {
    auto tracer = FrameTracer::create(s, 0, fixed_spp(spp));
    ASSERT_TRUE(tracer.ok());
    (*tracer)->render_perspective(pose, 2, 2, 0, &image);
    // spp 1: the centre (x = -0.5 exactly) lies on the edge; more samples: exactly half.
    if (spp > 1) {
      EXPECT_EQ(image.color[0], 0.5f) << spp;
    }
    EXPECT_EQ(image.color[3], 0.0f) << spp;  // pixel (1, 0): x in [0, 1], nothing
    EXPECT_TRUE(std::isinf(image.depth[3]));
  }
}

double srgb_psnr(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = srgb_from_linear(a[i]) - srgb_from_linear(b[i]);
    se += d * d;
  }
  return 10 * std::log10(a.size() / std::max(se, 1e-30));
}

// The criterion at the defaults: two seeds agree to 45 dB or more (sRGB PSNR). Two
// viewpoints of the interior (AO in corners, a lamp, edges everywhere) and of mirror-box (glass).
TEST(Antialias, TwoSeedsAgreeAtTheDefaults) {
  for (const char* name : {"interior", "mirror-box"}) {
    auto scene = make_builtin_scene(name);
    ASSERT_TRUE(scene.ok());
    LightfieldRenderOptions a, b;
    b.seed = a.seed + 1;
    auto ta = FrameTracer::create(*scene, 0, a);
    auto tb = FrameTracer::create(*scene, 0, b);
    ASSERT_TRUE(ta.ok() && tb.ok());
    capture::ViewFrame fa, fb;
    const Vec3 p = scene->default_rig.viewpoints[0].position;
    RenderStats st = (*ta)->render_cube(p, 0, 0, 32, false, &fa);
    (*tb)->render_cube(p, 0, 0, 32, false, &fb);
    const double psnr = srgb_psnr(fa.color, fb.color);
    std::printf("%s: seed 1 vs 2 %.2f dB, %.2f samples per texel\n", name, psnr,
                static_cast<double>(st.samples) / st.pixels);
    EXPECT_GE(psnr, 45.0) << name;
    // And spp 1 (one centre sample) does not: the test can tell.
    a.spp = b.spp = 1;
    auto ua = FrameTracer::create(*scene, 0, a);
    auto ub = FrameTracer::create(*scene, 0, b);
    ASSERT_TRUE(ua.ok() && ub.ok());
    (*ua)->render_cube(p, 0, 0, 32, false, &fa);
    (*ub)->render_cube(p, 0, 0, 32, false, &fb);
    EXPECT_LT(srgb_psnr(fa.color, fb.color), 45.0) << name;
  }
}

// A sphere over a floor, lit by the sun and an ambient term with AO: the scene of the frozen
// spp = 1 values below (kept here, so that changes to the built-in scenes do not touch them).
Scene legacy_scene() {
  Scene s;
  s.name = "legacy";
  Material grey, red;
  red.albedo = {0.8f, 0.2f, 0.1f};
  s.materials = {grey, red};
  Object floor;
  floor.name = "floor";
  floor.mesh.positions = {{-5, -1, -5}, {5, -1, -5}, {5, -1, 5}, {-5, -1, 5}};
  floor.mesh.triangles = {{0, 2, 1}, {0, 3, 2}};
  s.objects.push_back(floor);
  Object ball;
  ball.name = "ball";
  ball.material = 1;
  ball.spheres.push_back({glm::vec3(1.2f, -0.3f, 0.4f), 0.7f});
  s.objects.push_back(ball);
  s.sky.sun_irradiance = glm::vec3(1.5f);
  s.ambient = glm::vec3(0.6f);
  s.ao_distance = 3;
  return s;
}

// Colours of a 4 x 4 cube map from the origin, 8 AO samples, seed 7, rendered with one centre
// sample per texel (commit 5610434), printed with %.9g.
const float kLegacyColours[] = {
#include "antialias_legacy_colours.inc"
};

TEST(Antialias, OneSampleIsTheCentreSampleOfBefore) {
  LightfieldRenderOptions o;
  o.threads = 2;
  o.seed = 7;
  o.ao_samples = 8;
  o.spp = 1;
  auto tracer = FrameTracer::create(legacy_scene(), 0, o);
  ASSERT_TRUE(tracer.ok());
  capture::ViewFrame f;
  (*tracer)->render_cube({0, 0, 0}, 0, 0, 4, false, &f);
  ASSERT_EQ(f.color.size(), std::size(kLegacyColours));
  for (size_t i = 0; i < f.color.size(); ++i) {
    // Exact on the host that froze them; Embree's kernels differ in the last bits between CPUs.
    EXPECT_NEAR(f.color[i], kLegacyColours[i], 1e-5 * (1 + kLegacyColours[i])) << i;
  }
  // Another seed changes AO somewhere: the frozen values can tell a different sampling pattern.
  o.seed = 8;
  auto other = FrameTracer::create(legacy_scene(), 0, o);
  ASSERT_TRUE(other.ok());
  capture::ViewFrame g;
  (*other)->render_cube({0, 0, 0}, 0, 0, 4, false, &g);
  float largest = 0;
  for (size_t i = 0; i < g.color.size(); ++i) {
    largest = std::max(largest, std::fabs(g.color[i] - kLegacyColours[i]));
  }
  EXPECT_GT(largest, 1e-2f);
  if (std::getenv("CALF_PRINT_LEGACY")) {
    for (float c : f.color) std::printf("%.9g,\n", c);
  }
}

TEST(Antialias, OptionsAreValidated) {
  LightfieldRenderOptions o;
  EXPECT_TRUE(validate_render_options(o).ok());
  o.spp = 0;
  EXPECT_EQ(validate_render_options(o).id(), ErrorId::kCaptureOption);
  o.spp = 5000;
  EXPECT_EQ(validate_render_options(o).id(), ErrorId::kCaptureOption);
  o = LightfieldRenderOptions{};
  o.min_spp = 0;
  EXPECT_EQ(validate_render_options(o).id(), ErrorId::kCaptureOption);
  o = LightfieldRenderOptions{};
  for (float t : {-0.1f, 1.5f, NAN}) {
    o.tolerance = t;
    EXPECT_EQ(validate_render_options(o).id(), ErrorId::kCaptureOption) << t;
  }
}

}  // namespace
}  // namespace calf::samples
