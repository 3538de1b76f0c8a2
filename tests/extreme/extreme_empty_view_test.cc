// Numerical extremes of emptiness: a capture set whose every depth is +inf (sky
// everywhere), and eyes that see nothing any view has data for: placed far outside the view
// volume looking away from everything, inside geometry (behind every view's surface), with every
// view abstaining, or with nothing decoded at all. Each renders the sky colour or a documented
// fallback (docs/EXTREMES.md), never a NaN, through the CPU renderer and the GL renderer.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/playback.h"
#include "extreme_common.h"

namespace calf::extreme {
namespace {

using player::Playback;
using player::PlaybackOptions;
using player::RenderedImage;

constexpr float kSky[3] = {0.25f, 0.5f, 0.75f};  // exact in half floats
constexpr float kWall[3] = {0.75f, 0.25f, 0.125f};

// Every texel of every view sees the sky: depth +inf, one uniform colour.
Status write_sky_capture(const fs::path& dir, uint32_t frames, uint32_t face_size = 16) {
  const capture::CaptureManifest m = make_manifest(face_size, frames, {{0, 0, 0}, {1, 0, 0}});
  return write_capture(dir, m, [](uint32_t, uint32_t, capture::ViewFrame& vf) {
    for (int f = 0; f < 6; ++f) fill_face(vf, cube_face_from_index(f), kSky, kInfF);
  });
}

// Two viewpoints, (0, 0, 0) and (0, 0.5, 0), each seeing a sphere cap of radius 3 on its +X face
// (colour kWall) and sky everywhere else.
Status write_wall_capture(const fs::path& dir) {
  const capture::CaptureManifest m = make_manifest(16, 1, {{0, 0, 0}, {0, 0.5, 0}});
  return write_capture(dir, m, [](uint32_t, uint32_t, capture::ViewFrame& vf) {
    for (int f = 0; f < 6; ++f) fill_face(vf, cube_face_from_index(f), kSky, kInfF);
    fill_face(vf, CubeFace::kPosX, kWall, 3.0f);
  });
}

Expected<encoder::LightfieldEncodeStats> encode(const fs::path& cap, const std::string& clip,
                                                encoder::ColourCoding coding) {
  encoder::LightfieldEncodeOptions eo;
  eo.cell_size = 8;
  eo.colour = coding;
  return encoder::encode_lightfield_file(cap, clip, eo);
}

Camera camera(const Vec3& position, const Vec3& forward, uint32_t size = 8) {
  Camera c;
  c.position = position;
  c.forward = forward;
  c.up = std::fabs(forward.y) > 0.9 * std::sqrt(forward.x * forward.x + forward.y * forward.y +
                                                forward.z * forward.z)
             ? Vec3{1, 0, 0}
             : Vec3{0, 1, 0};
  c.fov_y = 1.2;
  c.width = c.height = size;
  return c;
}

// Every pixel shows `rgb` (within `tol`) at depth +inf.
void expect_sky(const RenderedImage& img, const float rgb[3], double tol, const std::string& what) {
  ASSERT_EQ(bad_pixels(img), 0u) << what;
  for (size_t k = 0; k < img.depth.size(); ++k) {
    ASSERT_TRUE(std::isinf(img.depth[k])) << what << " pixel " << k << " depth " << img.depth[k];
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(img.color[3 * k + c], rgb[c], tol) << what;
  }
}

// Renders `cams` through calf-play's loop (view selection, view-dependent decoding, CPU or GL).
void play_and_check(
    const std::string& clip, bool gl, const std::vector<Camera>& cams,
    const std::function<void(const RenderedImage&, size_t, const std::string&)>& check) {
  PlaybackOptions po;
  po.use_gl = gl;
  po.of<player::LightfieldOptions>().selection.budget.target_frame_ms = 0;
  player::OsMesaContext* ctx = gl ? gl_context() : nullptr;
  if (gl && ctx == nullptr) {
    std::printf("no OSMesa GL 4.5 context: GL half skipped\n");
    return;
  }
  auto play = Playback::open(clip, po, gl ? &ctx->gl() : nullptr);
  ASSERT_TRUE(play.ok()) << play.status().to_string();
  for (size_t i = 0; i < cams.size(); ++i) {
    for (uint32_t frame = 0; frame < (*play)->frame_count(); frame += 2) {
      ASSERT_TRUE((*play)->prepare(frame, std::span<const Camera>(&cams[i], 1)).ok());
      RenderedImage img;
      ASSERT_TRUE((*play)->render(cams[i], &img).ok());
      check(img, i, cat(gl ? "GL" : "CPU", " camera ", i, " frame ", frame));
    }
  }
}

TEST(SkyEverywhere, EncodesSmallDecodesToSkyAndRendersTheSkyColour) {
  TempDir tmp("sky");
  ASSERT_TRUE(write_sky_capture(tmp.path() / "cap", 4).ok());
  for (encoder::ColourCoding coding :
       {encoder::ColourCoding::kAuto, encoder::ColourCoding::kRgba16f}) {
    const std::string clip =
        tmp.file(coding == encoder::ColourCoding::kAuto ? "auto.calf" : "f16.calf");
    auto stats = encode(tmp.path() / "cap", clip, coding);
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    // Small: every cell one keyframe, every depth P-frame empty, each chunk a few bytes of zstd.
    EXPECT_EQ(stats->colour_keyframes, stats->colour_cells);
    EXPECT_EQ(stats->depth_pframes, stats->depth_empty_pframes);
    EXPECT_FALSE(std::isnan(stats->min_colour_quality_db));
    const uint64_t chunks = stats->colour.chunks + stats->depth.chunks;
    const uint64_t payload = stats->colour.stored + stats->depth.stored;
    const uint64_t file = fs::file_size(clip);
    std::printf("sky everywhere (%s): raw %llu bytes, %llu chunks, payload %llu, file %llu\n",
                coding == encoder::ColourCoding::kAuto ? "BC1" : "rgba16f",
                static_cast<unsigned long long>(stats->colour.raw + stats->depth.raw),
                static_cast<unsigned long long>(chunks), static_cast<unsigned long long>(payload),
                static_cast<unsigned long long>(file));
    EXPECT_LE(payload, chunks * 40);
    EXPECT_LE(file, 64 + (chunks + 2) * (64 + 48) + 2048);

    // Decoded: no view saw a finite depth (index flag clear, placeholder range 1..2), every code
    // is sky, every colour the sky's (exact in rgba16f; BC1 stores 5:6:5 sRGB endpoints).
    auto decoded = decode_clip(clip, 3);
    ASSERT_TRUE(decoded);
    const double tol = coding == encoder::ColourCoding::kRgba16f ? 0.0 : 0.01;
    for (uint32_t v = 0; v < 2; ++v) {
      EXPECT_FALSE(decoded->decoder->view(v).has_depth);
      EXPECT_EQ(decoded->decoder->view(v).z_near, 1.0f);
      EXPECT_EQ(decoded->decoder->view(v).z_far, 2.0f);
      for (int f = 0; f < 6; ++f) {
        for (uint16_t code : decoded->textures->depth(v, cube_face_from_index(f))) {
          ASSERT_EQ(code, kLog16Sky);
        }
        const std::vector<float> rgb = decoded->textures->colour(v, cube_face_from_index(f));
        for (size_t i = 0; i < rgb.size(); ++i) ASSERT_NEAR(rgb[i], kSky[i % 3], tol);
      }
    }
    if (coding == encoder::ColourCoding::kAuto) {
      // On 16-texel faces the 64-byte index entry of each chunk is most of the file; on 64-texel
      // faces (4 frames, one cell per face) the whole clip is under 1 % of the raw streams.
      ASSERT_TRUE(write_sky_capture(tmp.path() / "cap64", 4, 64).ok());
      encoder::LightfieldEncodeOptions eo;
      eo.cell_size = 64;
      eo.colour = encoder::ColourCoding::kBc1;
      const std::string big = tmp.file("sky64.calf");
      auto s64 = encoder::encode_lightfield_file(tmp.path() / "cap64", big, eo);
      ASSERT_TRUE(s64.ok()) << s64.status().to_string();
      const uint64_t raw = s64->colour.raw + s64->depth.raw;
      std::printf("sky everywhere, 64-texel faces: raw %llu bytes, file %llu\n",
                  static_cast<unsigned long long>(raw),
                  static_cast<unsigned long long>(fs::file_size(big)));
      EXPECT_LE(fs::file_size(big) * 100, raw);
      continue;
    }

    // Rendered from inside the view volume, at a viewpoint, and far outside it, looking at a
    // cube corner, along an axis and back: the sky colour at infinite depth.
    const std::vector<Camera> cams = {camera({0.5, 0.2, -0.1}, {1, 1, 1}),
                                      camera({0, 0, 0}, {0, 0, -1}),
                                      camera({1e4, -3e3, 50}, {-1, 0.2, 0.1})};
    for (bool gl : {false, true}) {
      play_and_check(clip, gl, cams, [&](const RenderedImage& img, size_t, const std::string& w) {
        expect_sky(img, kSky, 1e-6, w);
      });
    }
  }
}

TEST(NothingToSee, EyeFarOutsideLookingAwaySeesTheSky) {
  TempDir tmp("away");
  ASSERT_TRUE(write_wall_capture(tmp.path() / "cap").ok());
  const std::string clip = tmp.file("wall.calf");
  ASSERT_TRUE(encode(tmp.path() / "cap", clip, encoder::ColourCoding::kRgba16f).ok());
  // 50 units behind the viewpoints (the view volume is 1.5 across), looking away from the walls,
  // and 1e5 units away looking sideways: sky, decoded for these eyes by view-dependent decoding
  // (cells holding sky reach as far as the eye does).
  const std::vector<Camera> cams = {camera({-50, 0, 0}, {-1, 0, 0}),
                                    camera({-1e5, 3, 7}, {0, 0.3, 1})};
  for (bool gl : {false, true}) {
    play_and_check(clip, gl, cams, [&](const RenderedImage& img, size_t, const std::string& w) {
      expect_sky(img, kSky, 1e-6, w);
    });
  }
}

TEST(NothingToSee, EyeBehindEveryViewsSurfaceHitsAtTheMarchStart) {
  TempDir tmp("inside");
  ASSERT_TRUE(write_wall_capture(tmp.path() / "cap").ok());
  const std::string clip = tmp.file("wall.calf");
  ASSERT_TRUE(encode(tmp.path() / "cap", clip, encoder::ColourCoding::kRgba16f).ok());
  // The eye at (5, 0, 0) is beyond both walls (radius 3): no view has seen that space, every
  // view calls every point near it "behind my surface", so the march stops at its first sample.
  // The defined fallback: depth = the march's near end, colour = the views' blend of what they
  // stored in the directions of that point (the wall, kWall, for every view).
  const Vec3 eye{5, 0, 0};
  // The march range rule (docs/RENDERING.md): far = max_j |eye - P_j| + z_far_j, near =
  // max(min_j z_near_j / 4, far / 2^20). The walls are flat (every finite depth 3): z_near = 3.
  const double far = std::sqrt(25.0 + 0.25) + 3.0 * (1 + 1.0 / 1024);
  const double near = std::max(3.0 / 4, far / 1048576);
  const std::vector<Camera> cams = {camera(eye, {-1, 0, 0}), camera(eye, {0.2, 1, -0.3})};
  for (bool gl : {false, true}) {
    play_and_check(clip, gl, cams, [&](const RenderedImage& img, size_t, const std::string& w) {
      ASSERT_EQ(bad_pixels(img), 0u) << w;
      for (size_t k = 0; k < img.depth.size(); ++k) {
        ASSERT_NEAR(img.depth[k], near, near * 1e-5) << w << " pixel " << k;
        for (int c = 0; c < 3; ++c) ASSERT_NEAR(img.color[3 * k + c], kWall[c], 1e-5) << w;
      }
    });
  }
}

TEST(NothingToSee, EveryViewAbstainingIsEmptySpaceShowingTheViewsColour) {
  TempDir tmp("abstain");
  ASSERT_TRUE(write_wall_capture(tmp.path() / "cap").ok());
  const std::string clip = tmp.file("wall.calf");
  ASSERT_TRUE(encode(tmp.path() / "cap", clip, encoder::ColourCoding::kRgba16f).ok());
  auto decoded = decode_clip(clip, 0);
  ASSERT_TRUE(decoded);
  auto views = view_set_of(*decoded);
  ASSERT_TRUE(views.ok());
  // Views within min_view_distance of a sample do not vote on it (Alg. 4 line 21); at 100 no
  // view votes anywhere, every sample counts as empty and no ray hits. With no view seeing sky
  // in the ray's direction either, the sky rule falls back to all views' colours there: the wall
  // colour towards +X, the sky colour elsewhere.
  player::LightfieldRenderOptions o;
  o.near = 0.01;
  o.far = 10;
  o.min_view_distance = 100;
  auto cpu = player::LightfieldCpuRenderer::make(*views, o);
  ASSERT_TRUE(cpu.ok());
  RenderedImage toward, away;
  Camera cam = camera({0, 0.25, 0}, {1, 0, 0});
  cam.fov_y = 0.3;  // every ray stays on the +X faces of both views
  ASSERT_TRUE(cpu->render(cam, &toward).ok());
  expect_sky(toward, kWall, 1e-6, "abstaining views, towards the wall");
  ASSERT_TRUE(cpu->render(camera({0, 0.25, 0}, {-1, 0, 0}), &away).ok());
  expect_sky(away, kSky, 1e-6, "abstaining views, away from the wall");
}

TEST(NothingToSee, NothingDecodedRendersTheInitialBlackSky) {
  TempDir tmp("undecoded");
  ASSERT_TRUE(write_wall_capture(tmp.path() / "cap").ok());
  const std::string clip = tmp.file("wall.calf");
  ASSERT_TRUE(encode(tmp.path() / "cap", clip, encoder::ColourCoding::kRgba16f).ok());
  auto reader = container::Reader::open(clip);
  ASSERT_TRUE(reader.ok());
  auto d = decoder::LightfieldDecoder::open(*reader, 0);  // view-dependent
  ASSERT_TRUE(d.ok());
  std::vector<decoder::LightfieldViewInfo> infos = {d->view(0), d->view(1)};
  decoder::CpuTextures textures(d->header(), infos);
  // No viewer: nothing is visible, nothing is decoded.
  decoder::LightfieldFrameUpdates fu;
  ASSERT_TRUE(d->advance(0, {}, {}, &fu).ok());
  EXPECT_EQ(fu.updates.size(), 0u);
  EXPECT_EQ(fu.stats.visible_cells, 0u);
  EXPECT_FALSE(std::isnan(fu.stats.mbps_at_24fps()));
  ASSERT_TRUE(textures.apply(fu).ok());
  // The textures are as a renderer starts them: black, all sky. Rendered: black sky.
  player::ViewSet views;
  for (uint32_t v = 0; v < 2; ++v) {
    auto range = LogDepthRange::make(infos[v].z_near, infos[v].z_far);
    ASSERT_TRUE(range.ok());
    const Vec3 p = infos[v].position;
    auto view = player::View::make(p, *range, 16, false);
    ASSERT_TRUE(view.ok());
    for (int f = 0; f < 6; ++f) {
      const CubeFace face = cube_face_from_index(f);
      ASSERT_TRUE(view->write_colour_rect(face, {0, 0, 16, 16}, textures.colour(v, face)).ok());
      ASSERT_TRUE(view->write_depth_rect(face, {0, 0, 16, 16}, textures.depth(v, face)).ok());
    }
    views.views.push_back(std::move(*view));
  }
  auto cpu =
      player::LightfieldCpuRenderer::make(views, *player::march_range_for(views, {0, 0.2, 0}, {}));
  ASSERT_TRUE(cpu.ok());
  RenderedImage img;
  ASSERT_TRUE(cpu->render(camera({0, 0.2, 0}, {1, 0.1, 0}), &img).ok());
  const float black[3] = {0, 0, 0};
  expect_sky(img, black, 0, "nothing decoded");
}

}  // namespace
}  // namespace calf::extreme
