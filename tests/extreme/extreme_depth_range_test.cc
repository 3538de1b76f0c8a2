// Numerical extremes of depth: a log-16 range from 1e-4 to 1e6 (ten decades, the
// widest calf promises to code) and a flat scene whose every depth is equal (z_near == z_far
// measured). Expected codes and depths are computed here from Eq. 13 in long double, never read
// back from calf/format/log_depth.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "calf/format/log_depth.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/playback.h"
#include "extreme_common.h"

namespace calf::extreme {
namespace {

using player::Playback;
using player::PlaybackOptions;
using player::RenderedImage;

// Eq. 13 as calf scales it (65534 finite codes, SPEC §11.1.6), evaluated in long double.
long double exact_code(long double z, long double near, long double far) {
  return 65534.0L * std::log(z / near) / std::log(far / near);
}
// The relative depth step between codes: ln(far / near) / 65534.
double code_step(double near, double far) {
  return static_cast<double>(std::log(static_cast<long double>(far) / near) / 65534.0L);
}

// ---- Unit level: the mapping itself at 1e-4 .. 1e6 ----

TEST(DepthRange1e4To1e6, CodesAreEq13RoundedAndDepthsComeBackWithinHalfAStep) {
  const float near = 1e-4f, far = 1e6f;
  auto r = LogDepthRange::make(near, far);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  const double step = code_step(near, far);  // 3.51e-4: 0.035 % per code
  EXPECT_NEAR(r->relative_step(), step, step * 1e-9);
  // Half a code step of relative error, plus the float rounding of the decoded depth (2^-24) and
  // of the depth handed in.
  const double bound = std::expm1(step / 2) + 1.2e-7;
  // Both ends are exact (code 0 and 65534 decode to z_near and z_far themselves) ...
  EXPECT_EQ(*r->encode(near), 0);
  EXPECT_EQ(*r->encode(far), kLog16MaxFinite);
  EXPECT_EQ(r->decode(0), near);
  EXPECT_EQ(r->decode(kLog16MaxFinite), far);
  // ... the middle (geometric: 10) and a sweep of 200001 depths over the ten decades follow
  // Eq. 13 to the code and come back within half a step.
  double worst = 0;
  size_t checked = 0;
  for (int i = 0; i <= 200000; ++i) {
    const float z = static_cast<float>(near * std::pow(10.0L, 10.0L * i / 200000));
    if (!(z >= near && z <= far)) continue;
    const long double x = exact_code(z, near, far);
    const long double frac = x - std::floor(x);
    if (std::fabs(frac - 0.5L) < 1e-4L) continue;  // a tie to 1e-4 of a code: either is right
    const auto code = r->encode(z);
    ASSERT_TRUE(code.ok()) << z;
    ASSERT_EQ(*code, static_cast<uint16_t>(std::lround(static_cast<double>(x)))) << "depth " << z;
    const double err = std::fabs(r->decode(*code) / static_cast<double>(z) - 1);
    worst = std::max(worst, err);
    ASSERT_LE(err, bound) << "depth " << z;
    ++checked;
  }
  EXPECT_GT(checked, 199000u);
  const float middle = 10.0f;
  EXPECT_EQ(*r->encode(middle),
            static_cast<uint16_t>(std::lround(static_cast<double>(exact_code(middle, near, far)))));
  std::printf("near 1e-4, far 1e6: step %.3e, worst round trip %.3e (bound %.3e)\n", step, worst,
              bound);
  // A depth a quarter of a step outside either end is float rounding of a measured extreme and
  // clamps; three steps outside is an error naming the depth and the range.
  EXPECT_EQ(*r->encode(static_cast<float>(near * (1 - step / 4))), 0);
  EXPECT_EQ(*r->encode(static_cast<float>(far * (1 + step / 4))), kLog16MaxFinite);
  for (float outside :
       {static_cast<float>(near * (1 - 3 * step)), static_cast<float>(far * (1 + 3 * step))}) {
    auto e = r->encode(outside);
    ASSERT_FALSE(e.ok()) << outside;
    EXPECT_EQ(e.status().id(), ErrorId::kDepthOutOfRange);
    EXPECT_NE(e.status().message().find("z_near 9.99999975e-05"), std::string::npos)
        << e.status().message();
  }
  // Sky keeps its own code next to the largest finite one.
  EXPECT_EQ(*r->encode(kInfF), kLog16Sky);
  EXPECT_EQ(r->decode(kLog16Sky), kInfF);
}

// ---- Unit level: near == far ----

TEST(FlatDepth, EqualNearAndFarIsAClearErrorButAMeasuredFlatRangeCodesExactly) {
  // Asked for directly, z_near == z_far is refused, naming both values.
  auto bad = LogDepthRange::make(3.0f, 3.0f);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().id(), ErrorId::kDepthRange);
  EXPECT_NE(bad.status().message().find("z_far 3 must be greater than z_near 3"), std::string::npos)
      << bad.status().message();
  // Measured from a flat view (every depth the same), the range is widened upward (downward at
  // FLT_MAX) and the depth itself codes to an end code that decodes to it bit for bit.
  const float max = std::numeric_limits<float>::max();
  for (float z : {1e-30f, 1e-4f, 0.5f, 3.0f, 1e6f, 3e38f, max}) {
    auto r = LogDepthRange::covering(z, z);
    ASSERT_TRUE(r.ok()) << z << ": " << r.status().to_string();
    auto code = r->encode(z);
    ASSERT_TRUE(code.ok()) << z;
    EXPECT_TRUE(*code == 0 || *code == kLog16MaxFinite) << z << " codes as " << *code;
    EXPECT_EQ(r->decode(*code), z) << z;
    EXPECT_TRUE(std::isfinite(r->relative_step()) && r->relative_step() > 0) << z;
  }
  // The smallest subnormal cannot be widened (z / 1024 underflows to 0): a clear error, not a
  // degenerate range.
  const float tiny = std::numeric_limits<float>::denorm_min();
  auto r = LogDepthRange::covering(tiny, tiny);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kDepthRange);
  EXPECT_NE(r.status().message().find("must be greater than z_near"), std::string::npos);
}

// ---- Round trip: capture -> encode -> decode -> render ----

// One viewpoint at the origin; each face a sphere of its own radius and its own colour, so a ray
// into face f from the viewpoint sees exactly (colour f, depth f).
struct FaceScene {
  float depth[6];
  float rgb[6][3];
};

FaceScene wide_range_scene() {
  FaceScene s = {{1e-4f, 1e6f, 10.0f, 1.0f, 1000.0f, 0.01f}, {}};
  for (int f = 0; f < 6; ++f) {
    // Values exact in half floats: rgba16f colour must come back bit for bit.
    s.rgb[f][0] = (f + 1) / 8.0f;
    s.rgb[f][1] = 0.5f;
    s.rgb[f][2] = 1.0f - (f + 1) / 8.0f;
  }
  return s;
}

Status write_face_scene(const fs::path& dir, const FaceScene& s, uint32_t face_size) {
  const capture::CaptureManifest m = make_manifest(face_size, 1, {{0, 0, 0}});
  return write_capture(dir, m, [&](uint32_t, uint32_t, capture::ViewFrame& vf) {
    for (int f = 0; f < 6; ++f) fill_face(vf, cube_face_from_index(f), s.rgb[f], s.depth[f]);
  });
}

// A camera at the origin looking at the centre of face f with a 20 degree field of view: every
// ray and every bilinear tap stays inside the face.
Camera face_camera(int f) {
  static const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  Camera c;
  c.forward = axes[f];
  c.up = (f == 2 || f == 3) ? Vec3{0, 0, 1} : Vec3{0, 1, 0};
  c.fov_y = 20 * 3.141592653589793 / 180;
  c.width = c.height = 5;
  return c;
}

// Checks a render of face f: every pixel shows the face's colour and either its depth (within
// the march's refinement and half a code step) or, when `clamped_near` > 0, the march's near end
// (a surface nearer than the march starts is met at its first sample).
void expect_face(const RenderedImage& img, const FaceScene& s, int f, double clamped_near,
                 const std::string& what) {
  ASSERT_EQ(bad_pixels(img), 0u) << what;
  const double want_depth = clamped_near > 0 ? clamped_near : s.depth[f];
  for (size_t k = 0; k < img.depth.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(img.color[3 * k + c], s.rgb[f][c], 1e-6) << what << " face " << f;
    }
    ASSERT_NEAR(img.depth[k] / want_depth, 1.0, 2e-3) << what << " face " << f << " pixel " << k;
  }
}

TEST(DepthRange1e4To1e6, CaptureEncodeDecodeRenderRoundTrip) {
  TempDir tmp("range");
  const FaceScene scene = wide_range_scene();
  ASSERT_TRUE(write_face_scene(tmp.path() / "cap", scene, 8).ok());
  encoder::LightfieldEncodeOptions eo;
  eo.cell_size = 4;
  eo.colour = encoder::ColourCoding::kRgba16f;
  const std::string clip = tmp.file("clip.calf");
  auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();

  // The decoder holds z_near = 1e-4, z_far = 1e6 (as floats) and the Eq. 13 code of each face.
  auto decoded = decode_clip(clip, 0);
  ASSERT_TRUE(decoded);
  const auto& info = decoded->decoder->view(0);
  EXPECT_TRUE(info.has_depth);
  EXPECT_EQ(info.z_near, 1e-4f);
  EXPECT_EQ(info.z_far, 1e6f);
  for (int f = 0; f < 6; ++f) {
    const long double x = exact_code(scene.depth[f], 1e-4f, 1e6f);
    const auto want = static_cast<uint16_t>(std::lround(static_cast<double>(x)));
    for (uint16_t code : decoded->textures->depth(0, cube_face_from_index(f))) {
      ASSERT_EQ(code, want) << "face " << f;
    }
    const std::vector<float> rgb = decoded->textures->colour(0, cube_face_from_index(f));
    for (size_t i = 0; i < rgb.size(); ++i) ASSERT_EQ(rgb[i], scene.rgb[f][i % 3]) << "face " << f;
  }

  // Playback on the CPU with the default march range: far = 1e6 from the eye, near =
  // max(z_near / 4, far / 2^20) = 0.954 (the range is capped at 2^20). Every face shows its colour
  // and its depth except the spheres at 1e-4 (+X) and 0.01 (-Z), nearer than the march starts:
  // they are met at its first sample, i.e. at its near end (documented in docs/EXTREMES.md).
  const double default_near = std::max(1e-4f / 4.0, 1e6 / 1048576.0);
  PlaybackOptions po;
  po.use_gl = false;
  po.of<player::LightfieldOptions>().selection.budget.target_frame_ms = 0;
  auto cpu = Playback::open(clip, po, nullptr);
  ASSERT_TRUE(cpu.ok()) << cpu.status().to_string();
  for (int f = 0; f < 6; ++f) {
    const Camera cam = face_camera(f);
    ASSERT_TRUE((*cpu)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
    EXPECT_GT((*cpu)->lightfield()->last_stats().visible_cells, 0u) << "face " << f;
    RenderedImage img;
    ASSERT_TRUE((*cpu)->render(cam, &img).ok());
    expect_face(img, scene, f, scene.depth[f] < default_near ? default_near : 0,
                "CPU, default range");
  }
  // With the march range set to the data's (near 1e-4 / 4, far 1.01e6; 64 steps of 46 %, 8
  // bisections) every face, the 1e-4 one included, comes back at its depth.
  po.of<player::LightfieldOptions>().fixed_march_range = true;
  po.of<player::LightfieldOptions>().render.near = 2.5e-5;
  po.of<player::LightfieldOptions>().render.far = 1.01e6;
  auto wide = Playback::open(clip, po, nullptr);
  ASSERT_TRUE(wide.ok());
  for (int f = 0; f < 6; ++f) {
    const Camera cam = face_camera(f);
    ASSERT_TRUE((*wide)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
    RenderedImage img;
    ASSERT_TRUE((*wide)->render(cam, &img).ok());
    expect_face(img, scene, f, 0, "CPU, data range");
  }

  // The GL renderer (float arithmetic) gives the same answers.
  player::OsMesaContext* gl = gl_context();
  if (gl == nullptr) GTEST_SKIP() << "no OSMesa GL 4.5 context: GL half skipped";
  auto gpu = Playback::open(clip, po, &gl->gl());
  ASSERT_TRUE(gpu.ok()) << gpu.status().to_string();
  for (bool data_range : {true, false}) {
    player::LightfieldRenderOptions ro = po.of<player::LightfieldOptions>().render;
    if (!data_range) {
      ro.near = default_near;
      ro.far = 1e6;
    }
    ASSERT_TRUE((*gpu)->lightfield()->set_render_options(ro).ok());
    for (int f = 0; f < 6; ++f) {
      const Camera cam = face_camera(f);
      ASSERT_TRUE((*gpu)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
      RenderedImage img;
      ASSERT_TRUE((*gpu)->render(cam, &img).ok());
      expect_face(img, scene, f, scene.depth[f] < default_near && !data_range ? default_near : 0,
                  data_range ? "GL, data range" : "GL, default range");
    }
  }
}

TEST(FlatDepth, EveryDepthEqualEncodesDecodesAndRendersExactly) {
  TempDir tmp("flat");
  FaceScene scene = wide_range_scene();
  for (float& d : scene.depth) d = 3.0f;  // a sphere of radius 3 around the only viewpoint
  ASSERT_TRUE(write_face_scene(tmp.path() / "cap", scene, 16).ok());
  for (encoder::DepthCoding depth : {encoder::DepthCoding::kRaw16, encoder::DepthCoding::kBc5}) {
    encoder::LightfieldEncodeOptions eo;
    eo.cell_size = 8;
    eo.colour = encoder::ColourCoding::kRgba16f;
    eo.depth = depth;
    const std::string clip =
        tmp.file(depth == encoder::DepthCoding::kBc5 ? "bc5.calf" : "raw.calf");
    auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_EQ(stats->depth_max_rel_error, 0.0);  // BC5 of a constant code is exact
    auto decoded = decode_clip(clip, 0);
    ASSERT_TRUE(decoded);
    const auto& info = decoded->decoder->view(0);
    EXPECT_EQ(info.z_near, 3.0f);
    EXPECT_GT(info.z_far, 3.0f);  // widened so that the range is valid
    for (int f = 0; f < 6; ++f) {
      for (uint16_t code : decoded->textures->depth(0, cube_face_from_index(f))) {
        ASSERT_EQ(code, 0) << "face " << f;  // code 0 is z_near: 3 exactly
      }
    }
    // From the viewpoint every face shows its colour at depth 3.
    auto views = view_set_of(*decoded);
    ASSERT_TRUE(views.ok()) << views.status().to_string();
    auto range = player::march_range_for(*views, {0, 0, 0}, {});
    ASSERT_TRUE(range.ok());
    auto cpu = player::LightfieldCpuRenderer::make(*views, *range);
    ASSERT_TRUE(cpu.ok());
    for (int f = 0; f < 6; ++f) {
      RenderedImage img;
      ASSERT_TRUE(cpu->render(face_camera(f), &img).ok());
      expect_face(img, scene, f, 0, "flat, at the viewpoint");
    }
    // From an eye 1 off the centre the sphere's depth is |o + t d| = 3 solved for t, and the
    // colour is that of the face the hit point lies in (rays kept away from the seams).
    const Vec3 eye{0.4, -0.3, 0.2};
    auto off = player::march_range_for(*views, eye, {});
    ASSERT_TRUE(off.ok());
    auto cpu_off = player::LightfieldCpuRenderer::make(*views, *off);
    ASSERT_TRUE(cpu_off.ok());
    size_t checked = 0;
    for (int f = 0; f < 6; ++f) {
      Camera cam = face_camera(f);
      cam.position = eye;
      cam.fov_y = 10 * 3.141592653589793 / 180;
      RenderedImage img;
      ASSERT_TRUE(cpu_off->render(cam, &img).ok());
      ASSERT_EQ(bad_pixels(img), 0u);
      for (uint32_t j = 0; j < cam.height; ++j) {
        for (uint32_t i = 0; i < cam.width; ++i) {
          const Vec3 d = camera_ray(cam, i, j);
          const double od = eye.x * d.x + eye.y * d.y + eye.z * d.z;
          const double oo = eye.x * eye.x + eye.y * eye.y + eye.z * eye.z;
          const double t = -od + std::sqrt(od * od - oo + 9.0);
          const Vec3 p{eye.x + t * d.x, eye.y + t * d.y, eye.z + t * d.z};
          // The face of p: its largest component (no ties this far from the seams).
          const double a[3] = {std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)};
          const int axis = a[0] >= a[1] && a[0] >= a[2] ? 0 : a[1] >= a[2] ? 1 : 2;
          const double comp = axis == 0 ? p.x : axis == 1 ? p.y : p.z;
          const int face = 2 * axis + (comp < 0 ? 1 : 0);
          if (a[axis] < 1.15 * std::max({a[(axis + 1) % 3], a[(axis + 2) % 3]})) continue;
          const size_t k = size_t{j} * cam.width + i;
          ASSERT_NEAR(img.depth[k] / t, 1.0, 2e-3) << "face " << f << " pixel " << k;
          for (int c = 0; c < 3; ++c) ASSERT_NEAR(img.color[3 * k + c], scene.rgb[face][c], 1e-6);
          ++checked;
        }
      }
    }
    EXPECT_GE(checked, 100u);

    // Through calf-play's loop: view-dependent decoding culls cells whose frusta are only
    // 3 / 1024 deep (z_near 3, z_far 3.003); the faces the eye looks at must still be decoded
    // (the decoder starts from black and sky, which would show). CPU, and GL for the raw16 clip
    // (the GPU holds BC5 depth decoded to the same R16 codes).
    for (bool gl : {false, true}) {
      if (gl && depth == encoder::DepthCoding::kBc5) continue;
      player::OsMesaContext* ctx = gl ? gl_context() : nullptr;
      if (gl && ctx == nullptr) continue;
      PlaybackOptions po;
      po.use_gl = gl;
      po.of<player::LightfieldOptions>().selection.budget.target_frame_ms = 0;
      auto play = Playback::open(clip, po, gl ? &ctx->gl() : nullptr);
      ASSERT_TRUE(play.ok()) << play.status().to_string();
      for (int f = 0; f < 6; ++f) {
        Camera cam = face_camera(f);
        cam.position = eye;
        ASSERT_TRUE((*play)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
        EXPECT_GT((*play)->lightfield()->last_stats().visible_cells, 0u);
        RenderedImage img;
        ASSERT_TRUE((*play)->render(cam, &img).ok());
        ASSERT_EQ(bad_pixels(img), 0u);
        // The centre pixel: its ray hits well inside face f.
        const size_t k = (cam.height / 2) * cam.width + cam.width / 2;
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(img.color[3 * k + c], scene.rgb[f][c], 1e-5)
              << (gl ? "GL" : "CPU") << " face " << f;
        }
        EXPECT_TRUE(std::isfinite(img.depth[k]) && img.depth[k] > 2 && img.depth[k] < 4)
            << (gl ? "GL" : "CPU") << " face " << f << " depth " << img.depth[k];
      }
    }
  }
}

}  // namespace
}  // namespace calf::extreme
