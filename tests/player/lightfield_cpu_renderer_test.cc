// The CPU reference renderer (paper 002 Alg. 4) on analytic scenes: reproduction at a viewpoint,
// reconstruction between viewpoints against exact ground truth, sky, occlusion, determinism,
// extremes and option validation. PSNRs are printed so regressions and improvements are visible.
#include "calf/player/lightfield_cpu_renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

#include "synthetic_scene.h"

namespace calf::player {
namespace {

using testing::corner_views;
using testing::ground_truth;
using testing::make_views;
using testing::psnr;
using testing::room_with_spheres;
using testing::Scene;

constexpr double kPi = 3.141592653589793;

RenderedImage render(const ViewSet& views, const Camera& cam, LightfieldRenderOptions o) {
  o = *march_range_for(views, cam.position, o);
  const Expected<LightfieldCpuRenderer> r = LightfieldCpuRenderer::make(views, o);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  RenderedImage img;
  EXPECT_TRUE(r->render(cam, &img).ok());
  return img;
}

// An eye inside the cube of corner_views({0, 0, 0.5}, 1.0), on none of its viewpoints, looking
// into the room at 70 degrees.
Camera between_viewpoints_camera(uint32_t width, uint32_t height) {
  Camera cam;
  cam.position = {0.12, 0.07, 0.55};
  cam.forward = {-0.1, -0.15, -1};
  cam.fov_y = 70 * kPi / 180;
  cam.width = width;
  cam.height = height;
  return cam;
}

// An eye at a viewpoint looking down -Z with a 90° square frustum of face_size pixels sees, pixel
// for pixel, the -Z face mirrored left-right (cube faces are seen from inside): pixel (i, j) is
// texel (n - 1 - i, j), along exactly the texel's ray.
TEST(LightfieldCpuRenderer, ReproducesTheViewImageAtItsViewpoint) {
  const Scene scene = room_with_spheres();
  constexpr uint32_t n = 48;
  for (size_t count : {size_t{1}, size_t{4}, size_t{8}}) {
    std::vector<Vec3> pos = corner_views({0, 0, 0.5}, 1.0);
    pos.resize(count);
    const ViewSet views = make_views(scene, pos, n);
    Camera cam;
    cam.position = pos[0];
    cam.width = cam.height = n;
    cam.fov_y = kPi / 2;
    std::vector<float> want;
    for (uint32_t j = 0; j < n; ++j) {
      for (uint32_t i = 0; i < n; ++i) {
        const float* c = views.views[0].colour_at(CubeFace::kNegZ, n - 1 - i, j);
        want.insert(want.end(), c, c + 3);
      }
    }
    // With 64 steps a ray grazing a silhouette can step over the thin sliver that every view
    // agrees is occupied (Alg. 4 has no minimum thickness); 256 steps resolve it.
    for (uint32_t steps : {64u, 256u}) {
      LightfieldRenderOptions o;
      o.steps = steps;
      const double p = psnr(render(views, cam, o).color, want);
      std::printf("at viewpoint, %zu views, %u steps: PSNR vs the view's own face %.2f dB\n", count,
                  steps, p);
      EXPECT_GE(p, steps == 64 ? 35.0 : 40.0);
    }
  }
}

TEST(LightfieldCpuRenderer, ReconstructsBetweenViewpointsAndMoreViewsAreNotWorse) {
  const Scene scene = room_with_spheres();
  const std::vector<Vec3> all = corner_views({0, 0, 0.5}, 1.0);
  const Camera cam = between_viewpoints_camera(48, 48);
  const RenderedImage gt = ground_truth(scene, cam);
  double previous = 0;
  for (size_t count : {size_t{2}, size_t{4}, size_t{8}}) {
    const ViewSet views = make_views(scene, {all.begin(), all.begin() + count}, 48);
    const RenderedImage img = render(views, cam, {});
    const double p = psnr(img.color, gt.color);
    size_t depth_ok = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      depth_ok += std::fabs(img.depth[k] / gt.depth[k] - 1) < 0.02;
    }
    std::printf("between viewpoints, %zu views: PSNR %.2f dB, depth within 2%% on %.1f%%\n", count,
                p, 100.0 * depth_ok / gt.depth.size());
    if (count == 8) {
      EXPECT_GE(p, 30.0);
      EXPECT_GE(depth_ok, gt.depth.size() * 95 / 100);
    }
    EXPECT_GE(p, previous - 0.25) << "more views made it worse";
    previous = p;
  }
}

// shade_at (the --gt-depth diagnostic of bench-player_quality) is trace() without the march:
// at the depth trace() found it returns trace()'s sample bit for bit, plain and RR, on hits and
// on sky; at the analytic ground truth's depth the image is nearer the ground truth than the
// march's, which is what the diagnostic measures.
TEST(LightfieldCpuRenderer, ShadeAtTheMarchDepthIsTheTraceAndExactDepthIsBetter) {
  const Scene scene = room_with_spheres();
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 48);
  Scene mirror;
  mirror.room_half = 3;
  mirror.mirror_floor = true;
  mirror.spheres = {{{0.4, -2.2, -1.5}, 0.6}};
  const ViewSet mirror_views =
      make_views(mirror, {{-0.6, 0, 0}, {0.6, 0, 0}, {0, 0.6, 0.5}, {0, -0.6, 0.5}}, 48,
                 /*material=*/true);
  Camera cam = between_viewpoints_camera(32, 32);
  const CameraFrame frame = camera_frame(cam);
  for (const bool rr : {false, true}) {
    const ViewSet& set = rr ? mirror_views : views;
    LightfieldRenderOptions o;
    o.rr = rr;
    o = *march_range_for(set, cam.position, o);
    const Expected<LightfieldCpuRenderer> r = LightfieldCpuRenderer::make(set, o);
    ASSERT_TRUE(r.ok());
    size_t sky = 0;
    for (uint32_t j = 0; j < cam.height; ++j) {
      for (uint32_t i = 0; i < cam.width; ++i) {
        const Vec3 d = camera_ray(cam, frame, i, j);
        const RaySample a = r->trace(cam.position, d);
        const RaySample b = r->shade_at(cam.position, d, a.depth);
        sky += !a.hit;
        ASSERT_EQ(a.hit, b.hit) << i << "," << j;
        ASSERT_EQ(a.depth, b.depth) << i << "," << j;
        for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(a.rgb[ch], b.rgb[ch]) << i << "," << j;
      }
    }
    EXPECT_EQ(sky, 0u) << "the room has no sky: the sky case is covered below";
  }
  // Sky: a ray out of the open scene of a sky-only capture.
  Scene open;
  open.room = false;
  open.spheres = {{{0, 0, -2}, 0.5}};
  const ViewSet open_views = make_views(open, {{0, 0, 0}, {0.3, 0, 0}}, 32);
  const Expected<LightfieldCpuRenderer> r_open =
      LightfieldCpuRenderer::make(open_views, *march_range_for(open_views, {0.1, 0, 0}, {}));
  ASSERT_TRUE(r_open.ok());
  const RaySample up = r_open->trace({0.1, 0, 0}, {0, 1, 0});
  ASSERT_FALSE(up.hit);
  const RaySample up_at = r_open->shade_at({0.1, 0, 0}, {0, 1, 0}, INFINITY);
  EXPECT_FALSE(up_at.hit);
  for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(up.rgb[ch], up_at.rgb[ch]);

  cam = between_viewpoints_camera(48, 48);
  const RenderedImage gt = ground_truth(scene, cam);
  const RenderedImage marched = render(views, cam, {});
  const Expected<LightfieldCpuRenderer> r =
      LightfieldCpuRenderer::make(views, *march_range_for(views, cam.position, {}));
  ASSERT_TRUE(r.ok());
  RenderedImage exact = marched;
  const CameraFrame exact_frame = camera_frame(cam);
  for (uint32_t j = 0; j < cam.height; ++j) {
    for (uint32_t i = 0; i < cam.width; ++i) {
      const size_t k = size_t{j} * cam.width + i;
      const RaySample s =
          r->shade_at(cam.position, camera_ray(cam, exact_frame, i, j), gt.depth[k]);
      for (int ch = 0; ch < 3; ++ch) exact.color[3 * k + ch] = static_cast<float>(s.rgb[ch]);
    }
  }
  const double p_marched = psnr(marched.color, gt.color), p_exact = psnr(exact.color, gt.color);
  std::printf("between viewpoints: march %.2f dB, shaded at the exact depth %.2f dB\n", p_marched,
              p_exact);
  EXPECT_GT(p_exact, p_marched);
}

TEST(LightfieldCpuRenderer, SkyOnlySceneRendersTheSky) {
  Scene scene;
  scene.room = false;
  scene.uniform_sky = true;
  const ViewSet views = make_views(scene, {{0, 0, 0}, {1, 0.5, -0.3}}, 16);
  Camera cam;
  cam.position = {0.3, -0.2, 0.7};
  cam.forward = {1, 1, 1};  // looks at a cube corner
  cam.width = cam.height = 24;
  LightfieldRenderOptions o;
  const RenderedImage img = render(views, cam, o);
  for (size_t k = 0; k < img.depth.size(); ++k) {
    ASSERT_TRUE(std::isinf(img.depth[k]));
    ASSERT_EQ(img.color[3 * k + 0], 0.25f);
    ASSERT_EQ(img.color[3 * k + 1], 0.5f);
    ASSERT_EQ(img.color[3 * k + 2], 0.9f);
  }
  // A gradient sky is reproduced up to bilinear filtering of 16-texel faces.
  scene.uniform_sky = false;
  const ViewSet gradient = make_views(scene, {{0, 0, 0}, {1, 0.5, -0.3}}, 16);
  const double p = psnr(render(gradient, cam, o).color, ground_truth(scene, cam).color);
  std::printf("gradient sky: PSNR %.2f dB\n", p);
  EXPECT_GE(p, 45.0);
}

// View 0 sees a sphere in front of part of the back wall; view 1, off to the side, sees that wall.
// From an eye near view 1 the wall behind the sphere (as seen from view 0) must be found.
TEST(LightfieldCpuRenderer, ResolvesAPointOccludedInOneViewButSeenByAnother) {
  Scene scene;
  scene.spheres = {{{0, 0, -1.5}, 0.6}};
  const ViewSet views = make_views(scene, {{0, 0, 0}, {1.8, 0, 0}}, 48);
  Camera cam;
  cam.position = {1.6, 0.05, 0.1};
  cam.forward = {-0.35, 0, -1};
  cam.width = cam.height = 48;
  cam.fov_y = 60 * kPi / 180;
  const RenderedImage img = render(views, cam, {});
  const RenderedImage gt = ground_truth(scene, cam);
  size_t occluded = 0, good = 0;
  for (uint32_t j = 0; j < cam.height; ++j) {
    for (uint32_t i = 0; i < cam.width; ++i) {
      const size_t k = size_t{j} * cam.width + i;
      const Vec3 d = camera_ray(cam, i, j);
      const Vec3 p = testing::add(cam.position, testing::mul(d, gt.depth[k]));
      // The line from view 0 to p passes well inside the sphere (not at its silhouette, where
      // a texel's worth of error is expected) and p is on the wall behind it.
      const Vec3 u = testing::unit(p);
      const Vec3 c = scene.spheres[0].centre;
      const double along = testing::dot3(c, u);
      const Vec3 off = testing::sub(c, testing::mul(u, along));
      const bool sphere_in_the_way =
          gt.depth[k] > 3 && along > 0 &&
          std::sqrt(testing::dot3(off, off)) < 0.8 * scene.spheres[0].radius;
      if (!sphere_in_the_way) continue;
      ++occluded;
      double err = 0;
      for (int ch = 0; ch < 3; ++ch) {
        err = std::max(err, double{std::fabs(img.color[3 * k + ch] - gt.color[3 * k + ch])});
      }
      good += std::fabs(img.depth[k] / gt.depth[k] - 1) < 0.02 && err < 0.05;
    }
  }
  std::printf("occluded in view 0: %zu pixels, %zu resolved\n", occluded, good);
  EXPECT_GE(occluded, 50u);
  EXPECT_GE(good, occluded * 95 / 100);
}

// Thin parts: small spheres 2 units in front of the eye, 4 units before the room's back wall,
// marched with coarse steps (8 steps over the range the views span, ~20 % of depth each), so that
// the plain march (Alg. 4 alone) steps over most of them. Surface hints find the crossing of the
// nearest view's surface and, tested at substeps, also the crossings a whole step would hide. The
// found pixels have the spheres' depth (analytic ground truth), and the spheres do not grow over
// the wall.
TEST(LightfieldCpuRenderer, SurfaceHintsFindPartsThinnerThanAStep) {
  Scene scene;
  for (int k = 0; k < 5; ++k)
    scene.spheres.push_back({{-0.6 + 0.3 * k, 0.06 * k - 0.1, -2.0}, 0.04});
  const std::vector<Vec3> pos = {{-0.5, 0, 0}, {0.5, 0, 0}, {0, 0.5, 0}, {0, -0.5, 0}};
  const ViewSet views = make_views(scene, pos, 96);
  Camera cam;
  cam.position = {0.08, 0.05, 0.1};
  cam.forward = {0, 0, -1};
  cam.fov_y = 40 * kPi / 180;
  cam.width = cam.height = 96;
  const RenderedImage gt = ground_truth(scene, cam);
  const auto found = [&](uint32_t hints, uint32_t substeps) {
    LightfieldRenderOptions o;
    o.steps = 8;
    o.surface_hints = hints;
    o.surface_hint_substeps = substeps;
    const RenderedImage img = render(views, cam, o);
    size_t on_sphere = 0, right = 0, grown = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      if (gt.depth[k] > 3) {
        grown += img.depth[k] < 3;
        continue;
      }
      ++on_sphere;
      right += std::fabs(img.depth[k] / gt.depth[k] - 1) < 0.02;
    }
    std::printf(
        "8 steps, %u hints, %u substeps: %zu of %zu sphere pixels found, %zu wall pixels "
        "covered\n",
        hints, substeps, right, on_sphere, grown);
    EXPECT_GE(on_sphere, 100u);
    EXPECT_LE(grown, on_sphere / 2);  // silhouettes grow by up to a pixel, not more
    return static_cast<double>(right) / on_sphere;
  };
  const double plain = found(0, 1), hinted = found(1, 1), sub = found(1, 4);
  EXPECT_LT(plain, 0.5);
  EXPECT_GT(hinted, plain + 0.2);
  EXPECT_GE(sub, hinted);
  EXPECT_GE(sub, 0.7);  // the misses left are silhouette pixels of 4 cm spheres
}

// Hint vetoes at fine captures: a sphere seen by an eye nearer to it than the views (as a model's
// path inside its ring rig), 1024² faces. Beside the sphere's silhouette the hint view sees the
// eye ray enter the sphere's shadow; the other views see that point in front of the sphere, but
// by little, since the sphere lies right behind it. A margin of 0.5 % of depth (a fixed
// relative rule: 2.56 texels here) lets many of those crossings through, a rim of wall pixels on
// one side of the silhouette; 0.2 texels (the default) vetoes most. Counted: wall pixels the render
// puts on the sphere beyond those the march alone (no hints) puts there, which is the depth
// footprint's own growth (measured: 70 without hints, +71 with the old margin, +34 with 0.2).
TEST(LightfieldCpuRenderer, HintMarginInTexelsKeepsSilhouettesFromGrowingAtFineCaptures) {
  Scene scene;
  scene.spheres = {{{0, 0, -2.0}, 0.35}};
  constexpr uint32_t kFace = 1024;
  const std::vector<Vec3> pos = {
      {-0.9, 0.1, 0.2}, {0.9, -0.1, 0.2}, {0.1, 0.9, 0.1}, {-0.1, -0.9, 0.1}, {0, 0, 0.5}};
  const ViewSet views = make_views(scene, pos, kFace);
  Camera cam;
  cam.position = {0.25, 0.15, -0.9};
  cam.forward = testing::unit(testing::sub(scene.spheres[0].centre, cam.position));
  cam.fov_y = 50 * kPi / 180;
  cam.width = cam.height = 160;
  const RenderedImage gt = ground_truth(scene, cam);
  const auto on_sphere = [&](size_t k) { return gt.depth[k] < 2.5; };
  size_t rim = 0;  // wall pixels next to a sphere pixel
  for (uint32_t j = 1; j + 1 < cam.height; ++j) {
    for (uint32_t i = 1; i + 1 < cam.width; ++i) {
      const size_t k = size_t{j} * cam.width + i;
      rim += !on_sphere(k) && (on_sphere(k - 1) || on_sphere(k + 1) || on_sphere(k - cam.width) ||
                               on_sphere(k + cam.width));
    }
  }
  const auto grown = [&](uint32_t hints, double margin_texels) {
    LightfieldRenderOptions o;
    o.steps = 128;
    o.surface_hints = hints;
    o.surface_hint_margin_texels = margin_texels;
    const RenderedImage img = render(views, cam, o);
    size_t n = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) n += !on_sphere(k) && img.depth[k] < 2.5;
    std::printf("%u hints, margin %.2f texels: %zu wall pixels on the sphere (rim %zu)\n", hints,
                margin_texels, n, rim);
    return static_cast<double>(n);
  };
  EXPECT_GE(rim, 200u);
  const double march = grown(0, 0), old_rule = grown(1, 0.005 * kFace / 2),
               now = grown(1, LightfieldRenderOptions{}.surface_hint_margin_texels);
  EXPECT_GT(old_rule, march + 30);
  EXPECT_LT(now - march, 0.6 * (old_rule - march));
  EXPECT_LE(now, 0.4 * rim);
}

// Mixed texels: views anti-aliased as calf-capture's are (4 x 4 rays per texel), so every texel
// on a silhouette of the spheres (7 texels across at 128² faces) holds the mean of sphere and
// sky, at the depth of whichever its centre ray meets. The eye, between the views and nearer the
// spheres, sees the points on a view's silhouette inside the sphere's disc, where the mixed colour
// paints sky into the sphere. Counted: pixels inside a disc (their ground truth, 4 x 4 rays, is the
// sphere alone), rendered with supersample 2. Measured: RMS colour error 0.0131 with no penalty,
// 0.0035 with the default; the whole image, whose error is the spheres' silhouettes against the
// sky, 26.87 against 26.80 dB (real captures gain, docs/RENDERING.md "Fourth round").
TEST(LightfieldCpuRenderer, MixedTexelsOfAntiAliasedViewsGiveTheirColourWeightAway) {
  Scene scene;
  scene.room = false;
  scene.uniform_sky = true;
  for (int k = 0; k < 6; ++k) {
    scene.spheres.push_back({{-0.55 + 0.22 * k, 0.05 * k - 0.12, -1.6 - 0.1 * k}, 0.1});
  }
  const std::vector<Vec3> pos = {
      {-0.6, 0.2, 0.6}, {0.6, -0.2, 0.6}, {0.2, 0.6, 0.5}, {-0.2, -0.6, 0.5}};
  const ViewSet views = make_views(scene, pos, 128, false, 4);
  Camera cam;
  cam.position = {0.1, 0.08, -0.4};
  cam.forward = {0, -0.02, -1};
  cam.fov_y = 45 * kPi / 180;
  cam.width = cam.height = 96;
  const RenderedImage gt = ground_truth(scene, cam, 4);
  const auto measure = [&](double penalty, double* sphere_rms) {
    LightfieldRenderOptions o;
    o.steps = 64;
    o.supersample = 2;
    o.mixed_texel_penalty = penalty;
    const RenderedImage img = render(views, cam, o);
    double se = 0;
    size_t n = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      // Pixels inside a sphere's disc: they and their eight neighbours' centre rays are on a
      // sphere, so the anti-aliased ground truth holds the sphere alone there.
      const uint32_t i = k % cam.width, j = k / cam.width;
      if (i == 0 || j == 0 || i + 1 == cam.width || j + 1 == cam.height) continue;
      bool inside = true;
      for (int dj = -1; dj <= 1; ++dj) {
        for (int di = -1; di <= 1; ++di) {
          inside = inside && std::isfinite(gt.depth[k + di + int64_t{dj} * cam.width]);
        }
      }
      if (!inside) continue;
      for (int ch = 0; ch < 3; ++ch) {
        const double e = img.color[3 * k + ch] - gt.color[3 * k + ch];
        se += e * e;
      }
      n += 3;
    }
    EXPECT_GE(n / 3, 300u);
    *sphere_rms = std::sqrt(se / static_cast<double>(n));
    const double p = psnr(img.color, gt.color);
    std::printf("mixed texel penalty %.0f: PSNR %.2f dB, inside the discs RMS error %.4f (%zu)\n",
                penalty, p, *sphere_rms, n / 3);
    return p;
  };
  double rms_off = 0, rms_on = 0;
  const double off = measure(0, &rms_off);
  const double on = measure(LightfieldRenderOptions{}.mixed_texel_penalty, &rms_on);
  EXPECT_LT(rms_on, 0.5 * rms_off);
  EXPECT_GT(on, off - 0.2);
  // The extreme penalty (mixed taps keep e^-50 of their weight) stays finite and as good.
  double rms_max = 0;
  EXPECT_TRUE(std::isfinite(measure(50, &rms_max)));
  EXPECT_LT(rms_max, 0.5 * rms_off);
}

// Coverage (format/CAPTURE.md "Coverage"): a sphere 5 texels across against the sky in coarse,
// anti-aliased views. Without coverage its silhouette is placed by whole texels (the footprint
// rule grows it by up to a texel); with the views' 4 x 4 cell masks it is placed within a quarter
// texel. Counted: eye pixels whose centre ray the render sends to the sphere where the ground
// truth sees sky, or the reverse. At the viewpoint (the eye on the one view) and between four.
TEST(LightfieldCpuRenderer, CoveragePlacesSilhouettesInsideTexels) {
  Scene scene;
  scene.room = false;
  scene.uniform_sky = true;
  scene.spheres = {{{0.05, -0.03, -2.0}, 0.3}};
  constexpr uint32_t kFace = 32;
  const auto wrong_pixels = [&](const std::vector<Vec3>& pos, const Vec3& eye, uint32_t mode,
                                double* p, uint32_t agreement = 1) {
    ViewSet views = make_views(scene, pos, kFace, false, 4);
    for (View& v : views.views) testing::add_coverage(scene, &v);
    Camera cam;
    cam.position = eye;
    cam.forward = testing::unit(testing::sub(scene.spheres[0].centre, eye));
    cam.fov_y = 24 * kPi / 180;
    cam.width = cam.height = 96;
    const RenderedImage gt = ground_truth(scene, cam);
    LightfieldRenderOptions o;
    o.steps = 128;
    o.coverage = mode;
    o.coverage_agreement = agreement;
    const RenderedImage img = render(views, cam, o);
    size_t wrong = 0, sphere = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      wrong += std::isfinite(img.depth[k]) != std::isfinite(gt.depth[k]);
      sphere += std::isfinite(gt.depth[k]);
    }
    *p = psnr(img.color, gt.color);
    std::printf(
        "coverage %u (agreement %u), %zu views: %zu pixels on the wrong side of the "
        "silhouette (sphere %zu), %.2f dB\n",
        mode, agreement, pos.size(), wrong, sphere, *p);
    EXPECT_GE(sphere, 1000u);
    return static_cast<double>(wrong);
  };
  double p0, p1, p2;
  const std::vector<Vec3> one = {{0, 0, 0}};
  const double at_view_off = wrong_pixels(one, one[0], 0, &p0);
  const double at_view_shares = wrong_pixels(one, one[0], 1, &p1);
  const double at_view_mask = wrong_pixels(one, one[0], 2, &p2);
  EXPECT_LT(at_view_mask, 0.35 * at_view_off);
  EXPECT_LT(at_view_shares, 0.6 * at_view_off);
  EXPECT_GT(p2, p0 + 3);
  const std::vector<Vec3> four = {
      {-0.3, 0.1, 0.2}, {0.3, -0.1, 0.2}, {0.1, 0.3, 0.1}, {-0.1, -0.3, 0.1}};
  const double between_off = wrong_pixels(four, {0.04, 0.03, 0.1}, 0, &p0);
  const double between_mask = wrong_pixels(four, {0.04, 0.03, 0.1}, 2, &p2);
  EXPECT_LT(between_mask, 0.5 * between_off);
  EXPECT_GT(p2, p0 + 1);
  // With two views needed to carve by coverage the silhouette is placed as well.
  double p3;
  const double between_agreed = wrong_pixels(four, {0.04, 0.03, 0.1}, 2, &p3, 2);
  EXPECT_LT(between_agreed, 0.5 * between_off);
}

// Emptiness by agreement: thin parts (spheres 1.6 coarse texels across, against the sky) seen
// by four views with coverage. Each view's 4 x 4 cells straddle their rims, so with every
// coverage vote counted (agreement 1) a point is carved wherever one view's cell misses the part;
// with two views needed (agreement 2) the parts survive nearly as the march without coverage
// finds them (measured: 1200 of 1239 pixels without coverage; mask 1104 / 1148, mask grown a cell
// 1191 / 1199 with agreement 1 / 2). Counted: the ground truth's sphere pixels the render finds at
// their depth (within 5 %).
TEST(LightfieldCpuRenderer, CoverageAgreementKeepsThinParts) {
  Scene scene;
  scene.room = false;
  scene.uniform_sky = true;
  for (int k = 0; k < 5; ++k)
    scene.spheres.push_back({{-0.8 + 0.4 * k, 0.05 * k - 0.1, -2.0}, 0.1});
  const std::vector<Vec3> pos = {
      {-0.3, 0.1, 0.2}, {0.3, -0.1, 0.2}, {0.1, 0.3, 0.1}, {-0.1, -0.3, 0.1}};
  ViewSet views = make_views(scene, pos, 32, false, 4);
  for (View& v : views.views) testing::add_coverage(scene, &v);
  Camera cam;
  cam.position = {0.04, 0.03, 0.1};
  cam.forward = {0, 0, -1};
  cam.fov_y = 30 * kPi / 180;
  cam.width = cam.height = 128;
  const RenderedImage gt = ground_truth(scene, cam);
  const auto found = [&](uint32_t mode, uint32_t agreement) {
    LightfieldRenderOptions o;
    o.steps = 128;
    o.coverage = mode;
    o.coverage_agreement = agreement;
    const RenderedImage img = render(views, cam, o);
    size_t on_sphere = 0, right = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      if (!std::isfinite(gt.depth[k])) continue;
      ++on_sphere;
      right += std::fabs(img.depth[k] / gt.depth[k] - 1) < 0.05;
    }
    std::printf("coverage %u, agreement %u: %zu of %zu thin-sphere pixels found\n", mode, agreement,
                right, on_sphere);
    EXPECT_GE(on_sphere, 30u);
    return static_cast<double>(right) / on_sphere;
  };
  const double off = found(0, 1), each = found(2, 1), agreed = found(2, 2);
  const double each3 = found(3, 1), agreed3 = found(3, 2);
  EXPECT_GT(agreed, each);
  EXPECT_GT(agreed3, each3);
  EXPECT_GT(agreed, 0.94 * off);
}

// The sphere of CoveragePlacesSilhouettesInsideTexels between four coarse anti-aliased views
// with coverage, and an eye close to them looking at it, with its ground truth.
struct SphereBetweenViews {
  Scene scene;
  std::vector<Vec3> pos;  // the views' positions
  Vec3 eye;
  ViewSet views;
  Camera cam;
  RenderedImage gt;
};
SphereBetweenViews sphere_between_views() {
  SphereBetweenViews s;
  s.scene.room = false;
  s.scene.uniform_sky = true;
  s.scene.spheres = {{{0.05, -0.03, -2.0}, 0.3}};
  s.pos = {{-0.3, 0.1, 0.2}, {0.3, -0.1, 0.2}, {0.1, 0.3, 0.1}, {-0.1, -0.3, 0.1}};
  s.views = make_views(s.scene, s.pos, 32, false, 4);
  for (View& v : s.views.views) testing::add_coverage(s.scene, &v);
  s.eye = {0.04, 0.03, 0.1};
  s.cam.position = s.eye;
  s.cam.forward = testing::unit(testing::sub(s.scene.spheres[0].centre, s.eye));
  s.cam.fov_y = 24 * kPi / 180;
  s.cam.width = s.cam.height = 96;
  s.gt = ground_truth(s.scene, s.cam);
  return s;
}

// Compositing partly covered surfaces (LightfieldRenderOptions::coverage_layers): the sphere of
// CoveragePlacesSilhouettesInsideTexels between four coarse anti-aliased views. Where the march
// ends on the sphere but the eye ray misses it (the footprint rule grows the silhouette by up to
// a texel), the views' cell masks say the point is uncovered and the ray goes on to the sky
// behind; rays well inside the silhouette keep nearly their colour. Counted: the squared colour
// error against the ground truth of the pixels the march grows onto the sphere, and of those
// well inside it.
TEST(LightfieldCpuRenderer, CoverageLayersShowTheSkyBehindGrownSilhouettes) {
  const SphereBetweenViews setup = sphere_between_views();
  const ViewSet& views = setup.views;
  const Camera& cam = setup.cam;
  const RenderedImage& gt = setup.gt;
  LightfieldRenderOptions o;
  o.steps = 128;
  const RenderedImage off = render(views, cam, o);
  o.coverage_layers = 2;
  o.coverage_alpha = 1;
  const RenderedImage layered = render(views, cam, o);
  o.coverage_layers_hints_only = true;
  const RenderedImage hinted = render(views, cam, o);
  double grown_off = 0, grown_layered = 0, grown_hinted = 0;
  double inside_off = 0, inside_layered = 0, inside_hinted = 0;
  size_t grown = 0, inside = 0;
  const auto se = [&](const RenderedImage& img, size_t k) {
    double e = 0;
    for (int c = 0; c < 3; ++c) e += std::pow(img.color[3 * k + c] - gt.color[3 * k + c], 2);
    return e;
  };
  for (size_t k = 0; k < gt.depth.size(); ++k) {
    if (!std::isfinite(gt.depth[k]) && std::isfinite(off.depth[k])) {
      ++grown;
      grown_off += se(off, k);
      grown_layered += se(layered, k);
      grown_hinted += se(hinted, k);
    }
    // Well inside: the ground truth's sphere covers the pixels within 12 of it (a texel of the
    // views is about 11 eye pixels).
    constexpr int kBorder = 12;
    const int i = static_cast<int>(k % cam.width), j = static_cast<int>(k / cam.width);
    const int w = static_cast<int>(cam.width), h = static_cast<int>(cam.height);
    if (i < kBorder || j < kBorder || i + kBorder >= w || j + kBorder >= h) continue;
    bool all = true;
    for (int dj = -kBorder; dj <= kBorder && all; ++dj) {
      for (int di = -kBorder; di <= kBorder && all; ++di) {
        all = std::isfinite(gt.depth[size_t(j + dj) * cam.width + size_t(i + di)]);
      }
    }
    if (!all) continue;
    ++inside;
    inside_off += se(off, k);
    inside_layered += se(layered, k);
    inside_hinted += se(hinted, k);
  }
  std::printf(
      "%zu grown pixels, squared error %.3f without layers, %.3f with, %.3f hints only; %zu inner "
      "pixels: %.3f without, %.3f with, %.3f hints only\n",
      grown, grown_off, grown_layered, grown_hinted, inside, inside_off, inside_layered,
      inside_hinted);
  EXPECT_GE(grown, 20u);
  EXPECT_LT(grown_layered, 0.7 * grown_off);
  EXPECT_LE(grown_hinted, grown_off);
  EXPECT_GE(inside, 500u);
  EXPECT_LT(inside_layered, 1.1 * inside_off + 1e-3 * inside);
  EXPECT_LT(inside_hinted, 1.1 * inside_off + 1e-3 * inside);
}

// Hint crossings confirmed by coverage (LightfieldRenderOptions::surface_hint_coverage): the sphere
// of CoveragePlacesSilhouettesInsideTexels between four coarse anti-aliased views, and the thin
// spheres of CoverageAgreementKeepsThinParts. The hint view's grazing rays cross its edge texels'
// depth beside the sphere, where the texel's cells show the sky: without the rule such a crossing
// ends the ray on the sphere (a grown silhouette), with it the march goes on to the sky. Counted:
// eye pixels the render sends to a sphere where the ground truth sees sky (grown), and the thin
// spheres' pixels found at their depth (within 5 %). Measured: 1085 grown pixels without the
// rule, 907 with R = 1 (1062 with R = 2, 907 with R = 3); with coverage mode 3, 508 and 417; the
// thin spheres keep 1200 of 1239 pixels either way.
TEST(LightfieldCpuRenderer, HintCoverageStopsGrowingSilhouettesIntoTheSky) {
  const SphereBetweenViews setup = sphere_between_views();
  const std::vector<Vec3>& pos = setup.pos;
  const Vec3& eye = setup.eye;
  const ViewSet& views = setup.views;
  const Camera& cam = setup.cam;
  const RenderedImage& gt = setup.gt;
  const auto grown = [&](uint32_t rule, uint32_t coverage) {
    LightfieldRenderOptions o;
    o.steps = 128;
    o.coverage = coverage;
    o.surface_hint_coverage = rule;
    const RenderedImage img = render(views, cam, o);
    size_t n = 0, sphere = 0;
    for (size_t k = 0; k < gt.depth.size(); ++k) {
      n += !std::isfinite(gt.depth[k]) && std::isfinite(img.depth[k]);
      sphere += std::isfinite(gt.depth[k]);
    }
    std::printf("hint coverage %u, coverage %u: %zu grown pixels (sphere %zu), %.2f dB\n", rule,
                coverage, n, sphere, psnr(img.color, gt.color));
    EXPECT_GE(sphere, 1000u);
    return static_cast<double>(n);
  };
  const double off = grown(0, 0), own = grown(1, 0), near = grown(2, 0), agreed = grown(3, 0);
  EXPECT_GE(off, 100);
  EXPECT_LT(own, 0.9 * off);
  EXPECT_LE(own, near);
  EXPECT_LE(own, agreed);
  EXPECT_LT(grown(1, 3), 0.9 * grown(0, 3));

  Scene thin;
  thin.room = false;
  thin.uniform_sky = true;
  for (int k = 0; k < 5; ++k) thin.spheres.push_back({{-0.8 + 0.4 * k, 0.05 * k - 0.1, -2.0}, 0.1});
  ViewSet thin_views = make_views(thin, pos, 32, false, 4);
  for (View& v : thin_views.views) testing::add_coverage(thin, &v);
  Camera wide;
  wide.position = eye;
  wide.forward = {0, 0, -1};
  wide.fov_y = 30 * kPi / 180;
  wide.width = wide.height = 128;
  const RenderedImage thin_gt = ground_truth(thin, wide);
  const auto found = [&](uint32_t rule) {
    LightfieldRenderOptions o;
    o.steps = 128;
    o.surface_hint_coverage = rule;
    const RenderedImage img = render(thin_views, wide, o);
    size_t on_sphere = 0, right = 0;
    for (size_t k = 0; k < thin_gt.depth.size(); ++k) {
      if (!std::isfinite(thin_gt.depth[k])) continue;
      ++on_sphere;
      right += std::fabs(img.depth[k] / thin_gt.depth[k] - 1) < 0.05;
    }
    std::printf("hint coverage %u: %zu of %zu thin-sphere pixels found\n", rule, right, on_sphere);
    return static_cast<double>(right) / on_sphere;
  };
  const double thin_off = found(0);
  EXPECT_GT(found(1), 0.9 * thin_off);
}

// Views without coverage render exactly as before whatever the coverage option says.
TEST(LightfieldCpuRenderer, ViewsWithoutCoverageRenderAsBefore) {
  const ViewSet views = make_views(room_with_spheres(), corner_views({0, 0, 0.5}, 1.0), 24);
  const Camera cam = between_viewpoints_camera(48, 40);
  LightfieldRenderOptions off, on;
  off.coverage = 0;
  on.coverage = 2;
  const RenderedImage a = render(views, cam, off), b = render(views, cam, on);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.depth, b.depth);
  on.coverage_layers = 2;
  on.coverage_alpha = 1;
  const RenderedImage c = render(views, cam, on);
  EXPECT_EQ(a.color, c.color);
  EXPECT_EQ(a.depth, c.depth);
  on.surface_hint_coverage = 3;
  const RenderedImage d = render(views, cam, on);
  EXPECT_EQ(a.color, d.color);
  EXPECT_EQ(a.depth, d.depth);
}

// LightfieldRenderOptions::blend_views: three views of the room's back wall, each painted one
// colour (as view-dependent shading would make them differ); the eye's ray meets the wall at p,
// where a_j = |o - P_j| / |p - o| is 0.025, 0.05 and 0.175. The colour is the mean of the views'
// colours under the Unstructured Lumigraph's weights max(0, 1 - a_j / t) / a_j, computed here
// from that formula: K = 1 and 2 keep the nearest one and two views, K = 3 (no fourth view)
// weighs all three 1 / a_j, an eye on a viewpoint shows that view alone. Then a small sphere
// hides p from the nearest view: it does not see p, so it does not take the nearest view's place
// in the count, and K = 1 shows the next view's colour, not the hidden one's.
TEST(LightfieldCpuRenderer, BlendViewsWeighsTheNearestViewsThatSeeThePoint) {
  const float colours[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  constexpr uint32_t n = 64;
  const auto painted = [&](const Scene& scene, const std::vector<Vec3>& at) {
    ViewSet views = make_views(scene, at, n);
    for (size_t i = 0; i < views.views.size(); ++i) {
      std::vector<float> c(size_t{n} * n * 3);
      for (size_t k = 0; k < c.size(); ++k) c[k] = colours[i][k % 3];
      for (int f = 0; f < kCubeFaceCount; ++f) {
        EXPECT_TRUE(
            views.views[i].write_colour_rect(cube_face_from_index(f), {0, 0, n, n}, c).ok());
      }
    }
    return views;
  };
  // Views at 0.1, 0.2 and 0.7 from the eye; depth_decay so small that every view weighs alike
  // by its depth (and every view counts as seeing p).
  Scene wall;  // the empty room: its back wall is z = -4
  const Vec3 eye{0.1, 0, 0};
  const ViewSet views = painted(wall, {{0, 0, 0}, {0.3, 0, 0}, {-0.6, 0, 0}});
  const auto shade = [&](const ViewSet& set, const Vec3& o, const Vec3& p, uint32_t k,
                         double depth_decay) {
    LightfieldRenderOptions opt;
    opt.blend_views = k;
    opt.depth_decay = depth_decay;
    opt.mixed_texel_penalty = 0;
    const Expected<LightfieldCpuRenderer> r = LightfieldCpuRenderer::make(set, opt);
    EXPECT_TRUE(r.ok());
    const Vec3 d = p - o;
    const double z = length(d);
    return r->shade_at(o, {d.x / z, d.y / z, d.z / z}, z);
  };
  const Vec3 p{0.1, 0, -4};
  const double a[3] = {0.1 / 4, 0.2 / 4, 0.7 / 4};
  const auto expect_mix = [&](const RaySample& s, const double w[3], const char* what) {
    const double sum = w[0] + w[1] + w[2];
    for (int ch = 0; ch < 3; ++ch) {
      EXPECT_NEAR(s.rgb[ch],
                  (w[0] * colours[0][ch] + w[1] * colours[1][ch] + w[2] * colours[2][ch]) / sum,
                  1e-4)
          << what << " channel " << ch;
    }
  };
  const double k1[3] = {(1 - a[0] / a[1]) / a[0], 0, 0};
  expect_mix(shade(views, eye, p, 1, 1e-6), k1, "K = 1");
  const double k2[3] = {(1 - a[0] / a[2]) / a[0], (1 - a[1] / a[2]) / a[1], 0};
  expect_mix(shade(views, eye, p, 2, 1e-6), k2, "K = 2");
  const double k3[3] = {1 / a[0], 1 / a[1], 1 / a[2]};
  expect_mix(shade(views, eye, p, 3, 1e-6), k3, "K = 3");
  const double on_view[3] = {0, 1, 0};
  expect_mix(shade(views, {0.3, 0, 0}, {0.3, 0, -4}, 2, 1e-6), on_view, "eye on view 1");
  // cam_decay's weights (K = 0) blend all three.
  const RaySample broad = shade(views, eye, p, 0, 1e-6);
  EXPECT_GT(broad.rgb[1], 0.1);
  EXPECT_GT(broad.rgb[2], 0.01);

  // The sphere hides p from view 1 (nearest the eye at 0.2, 0, 0; a = 0.025), not from views 0
  // (0.125) and 2 (0.35).
  Scene hidden;
  hidden.spheres = {{{0.25, 0, -2}, 0.25}};
  const ViewSet hidden_views = painted(hidden, {{-0.3, 0, 0}, {0.3, 0, 0}, {-1.2, 0, 0}});
  const RaySample next = shade(hidden_views, {0.2, 0, 0}, p, 1, 500);
  const double only_view_0[3] = {1, 0, 0};
  expect_mix(next, only_view_0, "view 1 hidden, K = 1");
}

TEST(LightfieldCpuRenderer, ImageDoesNotDependOnThreadCount) {
  const Scene scene = room_with_spheres();
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 24);
  Camera cam;
  cam.position = {0.2, -0.1, 0.4};
  cam.width = 33;
  cam.height = 17;
  LightfieldRenderOptions o;
  o.steps = 32;
  o.rr = true;  // exercised without material: must equal the plain render
  o.threads = 1;
  const RenderedImage a = render(views, cam, o);
  o.threads = 3;
  const RenderedImage b = render(views, cam, o);
  o.rr = false;
  o.threads = 7;
  const RenderedImage c = render(views, cam, o);
  ASSERT_EQ(a.color.size(), b.color.size());
  EXPECT_EQ(std::memcmp(a.color.data(), b.color.data(), a.color.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.depth.data(), b.depth.data(), a.depth.size() * 4), 0);
  EXPECT_EQ(std::memcmp(a.color.data(), c.color.data(), a.color.size() * 4), 0);
}

// Supersampling n x n is the box filter of the rays through an n x n grid of each pixel: at n = 2
// the same rays as the image of twice the size, so its colour is that image averaged over 2 x 2
// blocks and its depth their nearest. The large image's rays are camera_ray's pixel centres (the
// renderer's n = 1 path), not the sub-pixel formula under test. A grid off by a fraction of a
// pixel, a missing or repeated sub-sample or a wrong divisor changes every pixel (checked).
TEST(LightfieldCpuRenderer, SupersamplingIsTheBoxFilterOfItsSubPixelRays) {
  const ViewSet views = make_views(room_with_spheres(), corner_views({0, 0, 0.5}, 1.0), 32);
  Camera cam = between_viewpoints_camera(20, 14);
  LightfieldRenderOptions o;
  o.supersample = 2;
  const RenderedImage small = render(views, cam, o);
  cam.width *= 2;
  cam.height *= 2;
  o.supersample = 1;
  const RenderedImage large = render(views, cam, o);
  ASSERT_EQ(small.depth.size() * 4, large.depth.size());
  size_t differing = 0, edge_pixels = 0;
  for (uint32_t j = 0; j < cam.height / 2; ++j) {
    for (uint32_t i = 0; i < cam.width / 2; ++i) {
      double mean[3] = {0, 0, 0};
      float nearest = std::numeric_limits<float>::infinity(), farthest = 0;
      for (uint32_t sy = 0; sy < 2; ++sy) {
        for (uint32_t sx = 0; sx < 2; ++sx) {
          const size_t k = size_t{2 * j + sy} * cam.width + 2 * i + sx;
          for (int ch = 0; ch < 3; ++ch) mean[ch] += large.color[3 * k + ch] / 4.0;
          nearest = std::min(nearest, large.depth[k]);
          farthest = std::max(farthest, large.depth[k]);
        }
      }
      edge_pixels += farthest > 1.05f * nearest;
      const size_t k = size_t{j} * (cam.width / 2) + i;
      bool same = small.depth[k] == nearest;
      for (int ch = 0; ch < 3; ++ch)
        same = same && std::fabs(small.color[3 * k + ch] - mean[ch]) < 1e-5;
      differing += !same;
    }
  }
  std::printf(
      "supersample 2 against the 2x image averaged: %zu of %zu pixels differ (%zu on depth "
      "edges)\n",
      differing, small.depth.size(), edge_pixels);
  EXPECT_GE(edge_pixels, 10u);  // the comparison sees edges
  // The two images' rays differ by rounding only; a threshold decision may flip on a few.
  EXPECT_LE(differing, 2u);
}

// Against an anti-aliased ground truth (the exact scene, 4 x 4 rays per pixel box-filtered)
// supersampling brings the render closer than one ray through each pixel centre does.
TEST(LightfieldCpuRenderer, SupersamplingApproachesTheAntiAliasedImage) {
  const Scene scene = room_with_spheres();
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 96);
  const Camera cam = between_viewpoints_camera(48, 48);
  Camera fine = cam;
  fine.width = fine.height = 4 * cam.width;
  const RenderedImage gt_fine = ground_truth(scene, fine);
  std::vector<float> gt(3 * size_t{cam.width} * cam.height, 0.0f);
  for (uint32_t j = 0; j < fine.height; ++j) {
    for (uint32_t i = 0; i < fine.width; ++i) {
      const size_t k = size_t{j / 4} * cam.width + i / 4;
      for (int ch = 0; ch < 3; ++ch) {
        gt[3 * k + ch] += gt_fine.color[3 * (size_t{j} * fine.width + i) + ch] / 16.0f;
      }
    }
  }
  double previous = 0;
  for (uint32_t n : {1u, 2u, 3u}) {
    LightfieldRenderOptions o;
    o.supersample = n;
    const double p = psnr(render(views, cam, o).color, gt);
    std::printf("supersample %u against the anti-aliased ground truth: %.2f dB\n", n, p);
    if (n > 1) {
      EXPECT_GT(p, previous + (n == 2 ? 1.0 : 0.0)) << "supersample " << n;
    }
    previous = p;
  }
}

// Sharpened colour taps (LightfieldRenderOptions::colour_sharpen), worked by hand: one view, the
// eye on it, a one-pixel camera along the ray through texel-space point (u, 8.5) of the -Z face,
// whose rows read 0.5 but for column 9, 0.9 (0.1 for the clamp). Halfway between the centres of
// columns 8 and 9 (u = 9, a = 1/2 along x, 0 along y) each tap adds k 4 a (1 - a) = k times its
// Laplacian along x: column 8 reads 0.5 + k (1.0 - 1.4), column 9 0.9 + k (1.8 - 1.0), so the
// pixel is 0.7 + 0.2 k. At a texel centre (a = 0) the texel is read as it is, whatever k. With
// column 7 on another surface, column 8 is not sharpened: 0.7 + 0.4 k. With 0.1 at column 9 and
// k = 1, column 8 reads 0.5 + (1.0 - 0.6) and column 9 0.1 + (0.2 - 1.0) < 0: clamped, the pixel
// is (0.9 + 0) / 2.
TEST(LightfieldCpuRenderer, SharpenedColourAddsTheLaplacianBetweenTexelCentres) {
  constexpr uint32_t n = 16;
  ViewSet views = make_views(Scene{}, {{0, 0, 0}}, n);  // the room alone: -Z is a flat wall
  View& v = views.views[0];
  const auto paint = [&](float column9) {
    std::vector<float> rows(3 * n * n);
    for (uint32_t k = 0; k < n * n; ++k) {
      for (int ch = 0; ch < 3; ++ch) rows[3 * k + ch] = k % n == 9 ? column9 : 0.5f;
    }
    ASSERT_TRUE(v.write_colour_rect(CubeFace::kNegZ, {0, 0, n, n}, rows).ok());
  };
  const auto pixel_at = [&](double u, double k, double jump_texels = 8) {
    Camera cam;
    cam.position = v.position();
    cam.forward = direction_from_texel_coord({CubeFace::kNegZ, u, 8.5}, n);
    cam.fov_y = 0.01;
    cam.width = cam.height = 1;
    LightfieldRenderOptions o;
    o.colour_sharpen = k;
    o.colour_sharpen_jump_texels = jump_texels;
    o.surface_hints = 0;
    return render(views, cam, o).color[0];
  };
  paint(0.9f);
  EXPECT_NEAR(pixel_at(9.0, 0), 0.7, 1e-4);
  EXPECT_NEAR(pixel_at(9.0, 0.2), 0.7 + 0.2 * 0.2, 1e-4);
  EXPECT_NEAR(pixel_at(9.0, 1), 0.7 + 0.2, 1e-4);
  EXPECT_NEAR(pixel_at(9.5, 1), 0.9, 1e-4);  // column 9's centre
  EXPECT_NEAR(pixel_at(8.5, 1), 0.5, 1e-4);  // column 8's
  // Column 7 moves 25 % farther: ln 1.25 is 1.8 texel angles (2 / 16 radians) of this view,
  // another surface for a jump limit of 1, the same surface for the default 8.
  std::vector<uint16_t> code = {v.depth_code_at(CubeFace::kNegZ, 7, 8)};
  const double z = v.range().decode(code[0]);
  code[0] = v.range().encode_unchecked(static_cast<float>(1.25 * z));
  ASSERT_TRUE(v.write_depth_rect(CubeFace::kNegZ, {7, 8, 1, 1}, code).ok());
  EXPECT_NEAR(pixel_at(9.0, 0.2, 1), 0.7 + 0.4 * 0.2, 1e-4);
  EXPECT_NEAR(pixel_at(9.0, 0.2), 0.7 + 0.2 * 0.2, 1e-4);
  paint(0.1f);
  EXPECT_NEAR(pixel_at(9.0, 1), (0.9 + 0) / 2, 1e-4);
}

// What sharpening buys (docs/RENDERING.md "Sharpened colour"): anti-aliased views of a textured
// room (4 x 4 colour samples per texel, a few texels per period of the texture) seen between
// viewpoints at about one texel per pixel, with 2 x 2 eye rays, against the 4 x 4 anti-aliased
// ground truth. Bilinear taps blur each texel's footprint mean again; k = 0.2 (the measured best)
// gives part of it back, k = 1 overshoots.
TEST(LightfieldCpuRenderer, SharpenedColourApproachesTheAntiAliasedImage) {
  Scene scene = room_with_spheres();
  scene.texture_scale = 6;
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 64, false, 4);
  const Camera cam = between_viewpoints_camera(56, 56);  // 1.25 degrees a pixel; texels 1.4
  const RenderedImage gt = ground_truth(scene, cam, 4);
  double p[3];
  const double strengths[3] = {0, 0.2, 1};
  for (int k = 0; k < 3; ++k) {
    LightfieldRenderOptions o;
    o.supersample = 2;
    o.colour_sharpen = strengths[k];
    p[k] = psnr(render(views, cam, o).color, gt.color);
    std::printf("colour_sharpen %.1f against the anti-aliased ground truth: %.2f dB\n",
                strengths[k], p[k]);
  }
  EXPECT_GT(p[1], p[0] + 0.5);
  EXPECT_LT(p[2], p[1]);
}

// Rays exactly along face seams and cube corners, from a viewpoint and from between viewpoints.
TEST(LightfieldCpuRenderer, RaysAlongSeamsAndCorners) {
  const Scene scene = room_with_spheres();
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 24);
  int checked = 0;
  for (const Vec3& origin : {views.views[0].position(), Vec3{0.1, 0.05, 0.45}}) {
    LightfieldRenderOptions o = *march_range_for(views, origin, {});
    const LightfieldCpuRenderer r = *LightfieldCpuRenderer::make(views, o);
    for (int a = -1; a <= 1; ++a) {
      for (int b = -1; b <= 1; ++b) {
        for (int c = -1; c <= 1; ++c) {
          const int zeros = (a == 0) + (b == 0) + (c == 0);
          if (zeros > 1) continue;  // seams (one zero) and corners (none)
          const Vec3 d = testing::unit({double(a), double(b), double(c)});
          const RaySample s = r.trace(origin, d);
          double want[3], z;
          testing::shade(scene, origin, d, want, &z);
          // Skip rays that meet the room near one of its edges, where walls of unrelated albedo
          // meet and a texel's worth of error picks the other wall.
          const Vec3 p = testing::add(origin, testing::mul(d, z));
          const int near_walls =
              (std::fabs(p.x) > 3.6) + (std::fabs(p.y) > 3.6) + (std::fabs(p.z) > 3.6);
          if (near_walls > 1) continue;
          ++checked;
          ASSERT_TRUE(s.hit);
          // Seam and corner rays meet the walls at 45 degrees or more: a texel's depth slope.
          EXPECT_NEAR(s.depth / z, 1.0, 0.03) << a << b << c;
          for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(s.rgb[ch], want[ch], 0.05) << a << b << c;
        }
      }
    }
  }
  EXPECT_GE(checked, 20);
}

TEST(LightfieldCpuRenderer, TinyNearAndSingleView) {
  const Scene scene = room_with_spheres();
  Camera cam;
  cam.position = {0.1, 0.05, 0.3};
  cam.width = cam.height = 32;
  const RenderedImage gt = ground_truth(scene, cam);
  // z_near tiny: 1e-6 with the default 64 steps still resolves the room.
  const ViewSet views = make_views(scene, corner_views({0, 0, 0.5}, 1.0), 32);
  LightfieldRenderOptions o = *march_range_for(views, cam.position, {});
  o.near = 1e-6;
  const LightfieldCpuRenderer r = *LightfieldCpuRenderer::make(views, o);
  RenderedImage img;
  ASSERT_TRUE(r.render(cam, &img).ok());
  const double p_near = psnr(img.color, gt.color);
  // One view, eye off it: disocclusions show up but the rest is right.
  const ViewSet one = make_views(scene, {{0, 0, 0.5}}, 32);
  const double p_one = psnr(render(one, cam, {}).color, gt.color);
  std::printf("near 1e-6: PSNR %.2f dB; single view, eye 0.2 off it: PSNR %.2f dB\n", p_near,
              p_one);
  EXPECT_GE(p_near, 28.0);
  EXPECT_GE(p_one, 22.0);
}

TEST(LightfieldCpuRenderer, RejectsBadOptionsAndCameras) {
  const ViewSet views = make_views(room_with_spheres(), {{0, 0, 0}}, 4);
  const auto code = [&](LightfieldRenderOptions o) {
    return LightfieldCpuRenderer::make(views, o).status().id();
  };
  LightfieldRenderOptions o;
  o.steps = 0;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.blend_views = 9;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.coverage = 5;
  EXPECT_TRUE(LightfieldCpuRenderer::make(views, o).ok());
  o.coverage = 6;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.near = 0;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.far = std::numeric_limits<double>::infinity();
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.threads = 0;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.depth_decay = std::nan("");
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.surface_hint_substeps = 0;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o.surface_hint_substeps = 65;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  o.supersample = 0;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o.supersample = 9;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o = {};
  for (double bad : {-1.0, 50.5, std::nan("")}) {
    o.mixed_texel_penalty = bad;
    EXPECT_EQ(code(o), ErrorId::kPlayerOptions) << bad;
  }
  o.mixed_texel_penalty = 50;  // the largest: mixed taps keep e^-50 of their weight
  EXPECT_TRUE(LightfieldCpuRenderer::make(views, o).ok());
  o = {};
  for (double bad : {-0.5, std::numeric_limits<double>::infinity()}) {
    o.mixed_texel_bend_texels = bad;
    EXPECT_EQ(code(o), ErrorId::kPlayerOptions) << bad;
  }
  o = {};
  for (double bad : {-0.1, 1.5, std::nan("")}) {
    o.colour_sharpen = bad;
    EXPECT_EQ(code(o), ErrorId::kPlayerOptions) << bad;
  }
  o.colour_sharpen = 1;
  EXPECT_TRUE(LightfieldCpuRenderer::make(views, o).ok());
  for (double bad : {-1.0, std::numeric_limits<double>::infinity()}) {
    o.colour_sharpen_jump_texels = bad;
    EXPECT_EQ(code(o), ErrorId::kPlayerOptions) << bad;
  }
  o = {};
  o.coverage_layers = 9;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o.coverage_layers = 8;
  o.coverage_alpha = 3;
  EXPECT_EQ(code(o), ErrorId::kPlayerOptions);
  o.coverage_alpha = 2;
  EXPECT_TRUE(LightfieldCpuRenderer::make(views, o).ok());
  EXPECT_EQ(LightfieldCpuRenderer::make(ViewSet{}, {}).status().id(), ErrorId::kPlayerOptions);
  const LightfieldCpuRenderer r = *LightfieldCpuRenderer::make(views, {});
  RenderedImage img;
  Camera cam;
  cam.up = {0, 0, 2};  // parallel to forward
  EXPECT_EQ(r.render(cam, &img).id(), ErrorId::kPlayerOptions);
  cam = {};
  cam.fov_y = kPi;
  EXPECT_EQ(r.render(cam, &img).id(), ErrorId::kPlayerOptions);
  cam = {};
  cam.width = 0;
  EXPECT_EQ(r.render(cam, &img).id(), ErrorId::kPlayerOptions);
  // The frame's active views: an index at or above the view count.
  cam = {};
  cam.width = cam.height = 4;
  const uint32_t past_the_end[] = {1};
  EXPECT_EQ(r.render(cam, past_the_end, &img).id(), ErrorId::kPlayerOptions);
  EXPECT_EQ(r.restricted_to(past_the_end).status().id(), ErrorId::kPlayerOptions);
  const uint32_t first[] = {0};
  EXPECT_TRUE(r.render(cam, first, &img).ok());
}

// The RR variant on a mirror floor between viewpoints. Known gap: on this scene RR does not yet
// beat the plain blend (the room's smooth albedo reflects with little parallax); this pins that
// it at least does not lose, and prints both for the report. The goal is a clear win on the
// mirror/glass scene: tighten to rr > plain + 1 dB once it holds.
TEST(LightfieldCpuRenderer, RrVariantBeatsPlainOnAMirrorFloor) {
  Scene scene;
  scene.room_half = 3;
  scene.mirror_floor = true;
  scene.spheres = {{{0.4, -2.2, -1.5}, 0.6}};
  std::vector<Vec3> pos = {{-0.6, 0, 0}, {0.6, 0, 0}, {0, 0.6, 0.5}, {0, -0.6, 0.5}};
  const ViewSet views = make_views(scene, pos, 48, /*material=*/true);
  Camera cam;
  cam.position = {0.05, 0.1, 0.2};
  cam.forward = {0, -0.8, -1};
  cam.width = cam.height = 40;
  const RenderedImage gt = ground_truth(scene, cam);
  LightfieldRenderOptions o;
  const double plain = psnr(render(views, cam, o).color, gt.color);
  o.rr = true;
  o.rr_start = 0.05;
  const double rr = psnr(render(views, cam, o).color, gt.color);
  o.rr_replace_view_reflection = false;
  const double alg4 = psnr(render(views, cam, o).color, gt.color);
  std::printf(
      "mirror floor between viewpoints: plain %.2f dB, RR %.2f dB (Alg. 4 as written "
      "%.2f dB)\n",
      plain, rr, alg4);
  EXPECT_GT(rr, plain - 0.5);
  EXPECT_GT(rr, alg4 - 0.5);
}

// At a viewpoint the eye's and the view's secondary rays coincide, so replacing the view's own
// reflection leaves the view's image: RR with replacement reproduces the mirror floor as the view
// captured it, where Alg. 4 as written counts the reflection the view captured twice. Colours stay
// non-negative (the pixel is clamped).
TEST(LightfieldCpuRenderer, RrReplacementReproducesTheViewAtItsViewpoint) {
  Scene scene;
  scene.room_half = 3;
  scene.mirror_floor = true;
  scene.spheres = {{{0.4, -2.2, -1.5}, 0.6}};
  constexpr uint32_t n = 48;
  const std::vector<Vec3> pos = {{-0.6, 0, 0}, {0.6, 0, 0}, {0, 0.6, 0.5}, {0, -0.6, 0.5}};
  const ViewSet views = make_views(scene, pos, n, /*material=*/true);
  Camera cam;
  cam.position = pos[0];
  cam.forward = {0, -1, 0};  // the -Y face: the mirror floor
  cam.up = {0, 0, -1};
  cam.width = cam.height = n;
  cam.fov_y = kPi / 2;
  // The eye's frame: right = forward x up = (1, 0, 0), up (0, 0, -1): pixel (i, j) looks along
  // (a, -1, b), the -Y face's texel (i, n - 1 - j) (s = x, t = -z on that face).
  std::vector<float> want;
  for (uint32_t j = 0; j < n; ++j) {
    for (uint32_t i = 0; i < n; ++i) {
      const float* c = views.views[0].colour_at(CubeFace::kNegY, i, n - 1 - j);
      want.insert(want.end(), c, c + 3);
    }
  }
  LightfieldRenderOptions o;
  o.rr = true;
  const RenderedImage replaced = render(views, cam, o);
  o.rr_replace_view_reflection = false;
  const RenderedImage alg4 = render(views, cam, o);
  const double p_replaced = psnr(replaced.color, want), p_alg4 = psnr(alg4.color, want);
  std::printf("RR at a viewpoint against the view's face: replacement %.2f dB, Alg. 4 %.2f dB\n",
              p_replaced, p_alg4);
  EXPECT_GE(p_replaced, 40.0);
  EXPECT_LT(p_alg4, p_replaced - 10);
  for (float c : replaced.color) ASSERT_GE(c, 0.0f);
}

// Coverage mode 5 against mode 3: small spheres in front of larger ones against the sky, four
// views with coverage. Where the texel a direction falls in lies behind a front surface that a
// neighbour tap within the footprint gave, mode 3 compares the point with the farthest tap (often
// the sky) wherever that texel's cells do not show the front, and with the front wherever they
// show anything else, grown by a cell; mode 5 reads the texel's own cell: its own surface where
// the cell shows it, the surface behind where the texel's other cells are only farther ones.
// Measured at 32² faces, 96² eye: 327 pixels on the wrong side of a silhouette with mode 3
// (24.33 dB), 129 with mode 5 (26.38 dB); 571 without coverage.
TEST(LightfieldCpuRenderer, CoverageMode5LetsTheTexelBehindTheFrontAnswerForItself) {
  Scene scene;
  scene.room = false;
  scene.uniform_sky = true;
  for (int i = 0; i < 5; ++i) {
    scene.spheres.push_back({{-0.5 + 0.25 * i, 0.05 * (i % 2), -1.6}, 0.06});
    scene.spheres.push_back({{-0.45 + 0.25 * i, -0.08, -2.2}, 0.1});
  }
  const std::vector<Vec3> four = {
      {-0.3, 0.1, 0.2}, {0.3, -0.1, 0.2}, {0.1, 0.3, 0.1}, {-0.1, -0.3, 0.1}};
  ViewSet views = make_views(scene, four, 32, false, 4);
  for (View& v : views.views) testing::add_coverage(scene, &v);
  Camera cam;
  cam.position = {0.04, 0.03, 0.1};
  cam.forward = {0, 0, -1};
  cam.fov_y = 40 * kPi / 180;
  cam.width = cam.height = 96;
  const RenderedImage gt = ground_truth(scene, cam);
  size_t wrong[2];
  double p[2];
  for (int k = 0; k < 2; ++k) {
    LightfieldRenderOptions o;
    o.steps = 128;
    o.surface_hints = 4;
    o.surface_hint_vetoes = 0;
    o.coverage = k == 0 ? 3 : 5;
    const RenderedImage img = render(views, cam, o);
    wrong[k] = 0;
    for (size_t i = 0; i < gt.depth.size(); ++i) {
      wrong[k] += std::isfinite(img.depth[i]) != std::isfinite(gt.depth[i]);
    }
    p[k] = psnr(img.color, gt.color);
    std::printf("coverage %u: %zu pixels on the wrong side of a silhouette, %.2f dB\n", o.coverage,
                wrong[k], p[k]);
  }
  EXPECT_LT(static_cast<double>(wrong[1]), 0.6 * static_cast<double>(wrong[0]));
  EXPECT_GT(p[1], p[0] + 1);
}

}  // namespace
}  // namespace calf::player
