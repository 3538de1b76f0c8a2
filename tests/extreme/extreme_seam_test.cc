// Eye rays grazing a face seam and a cube corner: the CPU renderer and the GL renderer
// must return a finite colour taken from the texel that the tie-break rule of calf/format/cube.h
// names ("the face of the first axis whose magnitude is the largest, in X, Y, Z order"), and, with
// bilinear colour, the mix of the taps on both sides of the seam.
//
// The scene: one viewpoint at the origin inside a sphere of radius 2 (constant depth, so every
// ray from the viewpoint hits at 2 and depth never decides which texel wins), faces of 8 texels,
// and a colour that names its texel: R = (face + 1) / 8, G = (x + 1) / 16, B = (y + 1) / 16
// (exact in half floats, so the GL textures hold the same values). Every expected texel below
// was worked out by hand from the GL cube-map table in cube.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "calf/player/capture_views.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/lightfield_gl_renderer.h"
#include "extreme_common.h"

namespace calf::extreme {
namespace {

using player::LightfieldRenderOptions;
using player::RenderedImage;

constexpr uint32_t kN = 8;

struct TexelColour {
  int face, x, y;
  double rgb(int c) const {
    return c == 0 ? (face + 1) / 8.0 : c == 1 ? (x + 1) / 16.0 : (y + 1) / 16.0;
  }
};

player::ViewSet seam_views() {
  capture::ViewFrame vf;
  vf.resize(kN, false);
  for (int f = 0; f < 6; ++f) {
    for (uint32_t y = 0; y < kN; ++y) {
      for (uint32_t x = 0; x < kN; ++x) {
        const size_t i = vf.texel_index(cube_face_from_index(f), x, y);
        const TexelColour t{f, static_cast<int>(x), static_cast<int>(y)};
        for (int c = 0; c < 3; ++c) vf.color[3 * i + c] = static_cast<float>(t.rgb(c));
        vf.depth[i] = 2.0f;
      }
    }
  }
  // One texel far from every seam tested is farther, so that the measured range is not flat.
  vf.depth[vf.texel_index(CubeFace::kNegZ, 4, 4)] = 4.0f;
  player::ViewSet set;
  auto v = player::view_from_capture_frame(vf, {0, 0, 0}, "seam scene");
  EXPECT_TRUE(v.ok()) << v.status().to_string();
  set.views.push_back(std::move(*v));
  return set;
}

Vec3 unit(double x, double y, double z) {
  const double n = std::sqrt(x * x + y * y + z * z);
  return {x / n, y / n, z / n};
}

// A ray along an exact seam or corner (`base`), or one ulp off it: component `axis` (0..2) moved
// one ulp away from zero (`away`) or towards it.
struct SeamRay {
  std::string name;
  Vec3 base;
  int axis = -1;  // -1: the exact seam or corner
  bool away = true;
  TexelColour want;  // the texel the tie-break rule names for the ray
  // For a ray one ulp off a seam: the texel of the seam itself. Marching scales the direction by
  // the hit distance, which can round a 1-ulp difference between two components away; the
  // renderer then sees the exact seam and rightly applies the tie-break. Either is correct.
  TexelColour tie{-1, 0, 0};

  // The direction with the perturbation in double (CPU) or in float (GL) precision.
  Vec3 direction(bool in_float) const {
    double c[3] = {base.x, base.y, base.z};
    if (axis >= 0) {
      if (in_float) {
        const float f = static_cast<float>(c[axis]);
        c[axis] = std::nextafter(f, away ? 2 * f : 0.0f);
      } else {
        c[axis] = std::nextafter(c[axis], away ? 2 * c[axis] : 0.0);
      }
    }
    return {c[0], c[1], c[2]};
  }
};

std::vector<SeamRay> seam_rays() {
  const Vec3 xy = unit(1, 1, 0.3), corner = unit(1, 1, 1), xz = unit(1, 0.3, -1);
  const Vec3 nc = unit(-1, -1, -1), ny = unit(0, -1, 1);
  const TexelColour px_seam{0, 2, 0}, py_seam{2, 7, 5};  // +X (2, 0) and +Y (7, 5) at the seam
  const TexelColour px_corner{0, 0, 0}, py_corner{2, 7, 7}, pz_corner{4, 7, 0};
  const TexelColour none{-1, 0, 0};
  return {
      // (1, 1, 0.3): |x| == |y| -> +X; on +X, s = (1 - 0.3) / 2 -> column 2, t = 0 -> row 0.
      {"seam +X|+Y", xy, -1, true, px_seam, none},
      // |y| one ulp larger -> +Y; on +Y, s = (x / y + 1) / 2 -> 1 -> column 7, t = 0.65 -> row 5.
      {"seam +X|+Y, y + 1 ulp", xy, 1, true, py_seam, px_seam},
      {"seam +X|+Y, x - 1 ulp", xy, 0, false, py_seam, px_seam},
      {"seam +X|+Y, x + 1 ulp", xy, 0, true, px_seam, none},
      {"seam +X|+Y, y - 1 ulp", xy, 1, false, px_seam, none},
      // (1, 0.3, -1): |x| == |z| -> +X; s = (-z / x + 1) / 2 = 1 -> column 7, t = 0.35 -> row 2.
      {"seam +X|-Z", xz, -1, true, {0, 7, 2}, none},
      // |z| one ulp larger -> -Z; on -Z, s = (-x / |z| + 1) / 2 -> 0, t = 0.35 -> row 2.
      {"seam +X|-Z, |z| + 1 ulp", xz, 2, true, {5, 0, 2}, {0, 7, 2}},
      // (0, -1, 1): |y| == |z| -> -Y; on -Y, s = 0.5 -> column 4, t = (-z / |y| + 1) / 2 = 0.
      {"seam -Y|+Z", ny, -1, true, {3, 4, 0}, none},
      // |z| larger -> +Z; s = (x / z + 1) / 2 = 0.5 -> column 4, t = (-y / z + 1) / 2 -> 1 ->
      // row 7.
      {"seam -Y|+Z, z + 1 ulp", ny, 2, true, {4, 4, 7}, {3, 4, 0}},
      // (1, 1, 1): all equal -> +X at its (0, 0) corner texel.
      {"corner", corner, -1, true, px_corner, none},
      {"corner, y + 1 ulp", corner, 1, true, py_corner, px_corner},
      {"corner, z + 1 ulp", corner, 2, true, pz_corner, px_corner},
      {"corner, x + 1 ulp", corner, 0, true, px_corner, none},
      // |y| == |z| > |x|: Y before Z.
      {"corner, x - 1 ulp", corner, 0, false, py_corner, px_corner},
      // (-1, -1, -1) -> -X: s = (z / |x| + 1) / 2 = 0, t = (-y / |x| + 1) / 2 = 1 -> row 7.
      {"corner -X-Y-Z", nc, -1, true, {1, 0, 7}, none},
  };
}

bool colour_is(const double* rgb, const TexelColour& t, double tol) {
  for (int c = 0; c < 3; ++c) {
    if (!(std::fabs(rgb[c] - t.rgb(c)) <= tol)) return false;
  }
  return true;
}

std::string texel_text(const TexelColour& t) {
  char b[64];
  std::snprintf(b, sizeof b, "face %d texel (%d, %d)", t.face, t.x, t.y);
  return b;
}

TEST(SeamRays, CpuNearestColourFollowsTheTieBreakRule) {
  const player::ViewSet views = seam_views();
  LightfieldRenderOptions o = *player::march_range_for(views, {0, 0, 0}, {});
  o.bilinear_colour = false;
  auto cpu = player::LightfieldCpuRenderer::make(views, o);
  ASSERT_TRUE(cpu.ok()) << cpu.status().to_string();
  int strict = 0, ulp_cases = 0;
  for (const SeamRay& ray : seam_rays()) {
    const player::RaySample s = cpu->trace({0, 0, 0}, ray.direction(false));
    ASSERT_TRUE(s.hit) << ray.name;
    EXPECT_NEAR(s.depth, 2.0, 2e-3) << ray.name;
    for (double c : s.rgb) ASSERT_TRUE(std::isfinite(c)) << ray.name;
    const bool exact = colour_is(s.rgb, ray.want, 1e-12);
    if (ray.tie.face < 0) {
      EXPECT_TRUE(exact) << ray.name << ": want " << texel_text(ray.want) << ", got rgb "
                         << s.rgb[0] << " " << s.rgb[1] << " " << s.rgb[2];
    } else {
      ++ulp_cases;
      strict += exact;
      EXPECT_TRUE(exact || colour_is(s.rgb, ray.tie, 1e-12))
          << ray.name << ": want " << texel_text(ray.want) << " (or the seam's "
          << texel_text(ray.tie) << "), got rgb " << s.rgb[0] << " " << s.rgb[1] << " " << s.rgb[2];
    }
  }
  std::printf("CPU: %d of %d one-ulp rays kept their side of the seam through the march\n", strict,
              ulp_cases);
}

// Bilinear colour at an exact seam and corner: the four taps, off-face ones re-projected onto the
// neighbouring face (seamless cube filtering), weighted as worked out here.
//  seam (1, 1, 0.3) on +X at (u, v) = (2.8, 0): taps (2, -1) -> +Y (7, 5) and (3, -1) -> +Y (7, 4)
//    with weights 0.35 / 0.15, (2, 0) and (3, 0) on +X with 0.35 / 0.15;
//  corner (1, 1, 1) on +X at (0, 0): (-1, -1) -> +Y (7, 7) (the diagonal tap's direction
//    (1, 1.125, 1.125) ties Y and Z: Y), (0, -1) -> +Y (7, 7), (-1, 0) -> +Z (7, 0), (0, 0) +X,
//    each 0.25.
double mix(const std::vector<std::pair<double, TexelColour>>& taps, int c) {
  double v = 0;
  for (const auto& [w, t] : taps) v += w * t.rgb(c);
  return v;
}
const std::vector<std::pair<double, TexelColour>> kSeamTaps = {
    {0.35, {2, 7, 5}}, {0.15, {2, 7, 4}}, {0.35, {0, 2, 0}}, {0.15, {0, 3, 0}}};
const std::vector<std::pair<double, TexelColour>> kCornerTaps = {
    {0.25, {2, 7, 7}}, {0.25, {2, 7, 7}}, {0.25, {4, 7, 0}}, {0.25, {0, 0, 0}}};

TEST(SeamRays, CpuBilinearColourMixesBothSidesOfTheSeam) {
  const player::ViewSet views = seam_views();
  LightfieldRenderOptions plain;
  plain.colour_sharpen = 0;  // the taps' own colours, as GL's seamless filtering mixes them
  const LightfieldRenderOptions o = *player::march_range_for(views, {0, 0, 0}, plain);
  auto cpu = player::LightfieldCpuRenderer::make(views, o);
  ASSERT_TRUE(cpu.ok());
  const player::RaySample seam = cpu->trace({0, 0, 0}, unit(1, 1, 0.3));
  const player::RaySample corner = cpu->trace({0, 0, 0}, unit(1, 1, 1));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(seam.rgb[c], mix(kSeamTaps, c), 1e-9) << "seam channel " << c;
    EXPECT_NEAR(corner.rgb[c], mix(kCornerTaps, c), 1e-9) << "corner channel " << c;
  }
  // Every ray of a camera staring at the corner (pixels straddle three faces) is finite, hits
  // at 2 and its colour is inside the colours of the three faces' corner region.
  Camera cam;
  cam.forward = {1, 1, 1};
  cam.fov_y = 0.2;
  cam.width = cam.height = 15;
  RenderedImage img;
  ASSERT_TRUE(cpu->render(cam, &img).ok());
  EXPECT_EQ(bad_pixels(img), 0u);
  for (size_t k = 0; k < img.depth.size(); ++k) {
    ASSERT_NEAR(img.depth[k], 2.0, 2e-3);
    ASSERT_TRUE(img.color[3 * k] >= 1 / 8.0f && img.color[3 * k] <= 5 / 8.0f) << k;
  }
}

TEST(SeamRays, GlRendererAgreesAtSeamsAndCorners) {
  player::OsMesaContext* gl = gl_context();
  if (gl == nullptr) GTEST_SKIP() << "no OSMesa GL 4.5 core context";
  const player::ViewSet views = seam_views();
  auto up_views = player::updates_from_view_set(views);
  ASSERT_TRUE(up_views.ok()) << up_views.status().to_string();
  auto gv = player::GlViews::make(gl->gl(), up_views->layout);
  ASSERT_TRUE(gv.ok()) << gv.status().to_string();
  ASSERT_TRUE((*gv)->apply(up_views->frame).ok());
  LightfieldRenderOptions o = *player::march_range_for(views, {0, 0, 0}, {});
  o.bilinear_colour = false;
  auto renderer = player::LightfieldGlRenderer::make(**gv, o);
  ASSERT_TRUE(renderer.ok()) << renderer.status().to_string();

  // A 1 x 1 camera: its only ray is exactly normalize(forward) (a = b = 0), in float.
  const auto render_ray = [&](const Vec3& forward, RenderedImage* img) {
    Camera cam;
    cam.forward = forward;
    cam.up = std::fabs(forward.y) > 0.9 * std::sqrt(forward.x * forward.x + forward.y * forward.y +
                                                    forward.z * forward.z)
                 ? Vec3{1, 0, 0}
                 : Vec3{0, 1, 0};
    cam.width = cam.height = 1;
    const Status s = (*renderer)->render(cam, img);
    ASSERT_TRUE(s.ok()) << s.to_string();
  };
  int strict = 0, ulp_cases = 0;
  for (const SeamRay& ray : seam_rays()) {
    // The double ulp is below float precision: the GL rays move by one float ulp instead.
    const Vec3 d = ray.direction(true);
    RenderedImage img;
    render_ray(d, &img);
    ASSERT_EQ(bad_pixels(img), 0u) << ray.name;
    EXPECT_NEAR(img.depth[0], 2.0, 2e-3) << ray.name;
    const double rgb[3] = {img.color[0], img.color[1], img.color[2]};
    const bool exact = colour_is(rgb, ray.want, 1e-6);
    if (ray.tie.face < 0) {
      EXPECT_TRUE(exact) << "GL " << ray.name << ": want " << texel_text(ray.want) << ", got rgb "
                         << rgb[0] << " " << rgb[1] << " " << rgb[2];
    } else {
      ++ulp_cases;
      strict += exact;
      EXPECT_TRUE(exact || colour_is(rgb, ray.tie, 1e-6))
          << "GL " << ray.name << ": want " << texel_text(ray.want) << " (or the seam's "
          << texel_text(ray.tie) << "), got rgb " << rgb[0] << " " << rgb[1] << " " << rgb[2];
    }
  }
  std::printf("GL: %d of %d one-float-ulp rays kept their side of the seam\n", strict, ulp_cases);

  // Bilinear: the same mixes as the CPU reference (the taps' own colours: colour_sharpen 0).
  o.bilinear_colour = true;
  o.colour_sharpen = 0;
  ASSERT_TRUE((*renderer)->set_options(o).ok());
  RenderedImage seam, corner;
  render_ray({1, 1, 0.3}, &seam);
  render_ray({1, 1, 1}, &corner);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(seam.color[c], mix(kSeamTaps, c), 1e-5) << "GL seam channel " << c;
    EXPECT_NEAR(corner.color[c], mix(kCornerTaps, c), 1e-5) << "GL corner channel " << c;
  }
}

}  // namespace
}  // namespace calf::extreme
