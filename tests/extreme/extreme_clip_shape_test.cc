// Numerical extremes of clip shape: a clip of one frame; a depth window W at or beyond
// the frame count; one rectangle per P-frame (A = 1); faces of 1 and 4 texels, a face that is not
// a multiple of the cell size (20 with cells of 16), and 2048-texel faces. Each is encoded,
// decoded by playing, seeking and wandering, compared with the capture it came from, and played.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "calf/decoder/lightfield_reference.h"
#include "calf/format/grid.h"
#include "calf/player/playback.h"
#include "extreme_common.h"

namespace calf::extreme {
namespace {

using player::Playback;
using player::PlaybackOptions;
using player::RenderedImage;

// The depth a log-16 code stands for, from Eq. 13 (SPEC §11.1.6) in long double.
double depth_of_code(uint16_t code, float near, float far) {
  if (code == kLog16Sky) return std::numeric_limits<double>::infinity();
  return static_cast<double>(
      near * std::exp(std::log(static_cast<long double>(far) / near) * code / 65534.0L));
}

// Checks that every depth code of `face` decodes to the capture's depth within half a code step
// (plus float rounding), sky to sky.
void expect_depths(const DecodedClip& clip, uint32_t view, CubeFace face,
                   const std::function<float(uint32_t x, uint32_t y)>& want,
                   const std::string& what) {
  const auto& info = clip.decoder->view(view);
  const double step = std::log(static_cast<double>(info.z_far) / info.z_near) / 65534;
  const double bound = std::expm1(step / 2) + 1e-6;
  const uint32_t n = clip.header().face_size;
  const auto codes = clip.textures->depth(view, face);
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const double got = depth_of_code(codes[size_t{y} * n + x], info.z_near, info.z_far);
      const double z = want(x, y);
      if (std::isinf(z)) {
        ASSERT_TRUE(std::isinf(got)) << what << " texel " << x << "," << y;
      } else {
        ASSERT_NEAR(got / z, 1.0, bound) << what << " texel " << x << "," << y;
      }
    }
  }
}

// ---- One frame ----

// Per-texel colour that names the texel (exact in half floats) and a smooth depth.
float texel_colour(int face, uint32_t x, uint32_t y, int c) {
  return c == 0 ? (face + 1) / 8.0f : c == 1 ? (x % 32 + 1) / 32.0f : (y % 32 + 1) / 32.0f;
}
float texel_depth(uint32_t view, int face, uint32_t x, uint32_t y) {
  return 2.0f + 0.25f * face + 0.0625f * (x % 32) + 0.03125f * (y % 32) + 0.5f * view;
}

void fill_named_texels(uint32_t view, capture::ViewFrame& vf) {
  for (int f = 0; f < 6; ++f) {
    for (uint32_t y = 0; y < vf.face_size; ++y) {
      for (uint32_t x = 0; x < vf.face_size; ++x) {
        const size_t i = vf.texel_index(cube_face_from_index(f), x, y);
        for (int c = 0; c < 3; ++c) vf.color[3 * i + c] = texel_colour(f, x, y, c);
        vf.depth[i] = texel_depth(view, f, x, y);
      }
    }
  }
}

TEST(OneFrame, EncodesDecodesSeeksAndPlays) {
  TempDir tmp("one");
  const capture::CaptureManifest m = make_manifest(8, 1, {{0, 0, 0}, {0.5, 0, 0}});
  ASSERT_TRUE(
      write_capture(tmp.path() / "cap", m, [](uint32_t v, uint32_t, capture::ViewFrame& vf) {
        fill_named_texels(v, vf);
      }).ok());
  encoder::LightfieldEncodeOptions eo;
  eo.cell_size = 4;
  eo.colour = encoder::ColourCoding::kRgba16f;
  const std::string clip = tmp.file("one.calf");
  auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  EXPECT_EQ(stats->colour_keyframes, stats->colour_cells);  // 2 views x 6 faces x 4 cells
  EXPECT_EQ(stats->colour_cells, 48u);
  EXPECT_EQ(stats->depth_pframes, 0u);
  EXPECT_EQ(stats->min_colour_quality_db, std::numeric_limits<double>::infinity());

  auto decoded = decode_clip(clip, 0);
  ASSERT_TRUE(decoded);
  for (uint32_t v = 0; v < 2; ++v) {
    for (int f = 0; f < 6; ++f) {
      const std::vector<float> rgb = decoded->textures->colour(v, cube_face_from_index(f));
      for (uint32_t y = 0; y < 8; ++y) {
        for (uint32_t x = 0; x < 8; ++x) {
          for (int c = 0; c < 3; ++c) {
            ASSERT_EQ(rgb[3 * (y * 8 + x) + c], texel_colour(f, x, y, c));
          }
        }
      }
      expect_depths(
          *decoded, v, cube_face_from_index(f),
          [&](uint32_t x, uint32_t y) { return texel_depth(v, f, x, y); }, "one frame");
    }
  }
  // The t chunk holds one keyframe and one t; the depth chunk one keyframe rectangle.
  auto ref = decoder::LightfieldReference::open(*decoded->reader, 0);
  ASSERT_TRUE(ref.ok());
  auto tl = ref->cell_timeline(1, 5, 3);
  ASSERT_TRUE(tl.ok());
  EXPECT_EQ(tl->keyframes, std::vector<uint32_t>{0});
  EXPECT_EQ(tl->t, std::vector<uint8_t>{0});
  auto rects = ref->depth_rect_counts(1, 5, 0);
  ASSERT_TRUE(rects.ok());
  EXPECT_EQ(*rects, std::vector<uint32_t>{1});
  // Frame 1 does not exist: a clear error naming the frame and the count.
  decoder::LightfieldFrameUpdates fu;
  const Status past = decoded->decoder->advance(1, {}, {}, &fu);
  EXPECT_EQ(past.id(), ErrorId::kDecoderArgument);
  EXPECT_NE(past.message().find("1"), std::string::npos) << past.message();
  // Played: every time shows frame 0.
  PlaybackOptions po;
  po.use_gl = false;
  auto play = Playback::open(clip, po, nullptr);
  ASSERT_TRUE(play.ok());
  EXPECT_EQ((*play)->frame_count(), 1u);
  for (double t : {-1.0, 0.0, 0.5, 1e9}) EXPECT_EQ((*play)->frame_at_time(t), 0u) << t;
  Camera cam;
  cam.position = {0.2, 0.1, 0};
  cam.forward = {0.3, -0.2, -1};
  cam.width = cam.height = 12;
  ASSERT_TRUE((*play)->prepare((*play)->frame_at_time(1e9), std::span<const Camera>(&cam, 1)).ok());
  RenderedImage img;
  ASSERT_TRUE((*play)->render(cam, &img).ok());
  EXPECT_EQ(bad_pixels(img), 0u);
}

// ---- W >= frame count, A = 1 ----

// 16-texel faces (depth regions of 8), 7 frames. On +X, in tile 0, a 2 x 2 block moves one texel
// per frame along the diagonal and texel (6, 6) toggles between 2.5 and 3.5 every odd frame; the
// rest of the face is at 3 and the other faces at 4, -Y half sky.
float moving_depth(uint32_t frame, int face, uint32_t x, uint32_t y) {
  if (face == 3 && y < 8) return kInfF;
  if (face != 0) return 4.0f;
  const uint32_t b = 1 + frame % 5;
  if (x >= b && x < b + 2 && y >= b && y < b + 2) return 1.5f + 0.125f * frame;
  if (x == 6 && y == 6) return frame % 2 ? 3.5f : 2.5f;
  return 3.0f;
}

TEST(DepthWindow, WindowAtOrBeyondTheFrameCountWithOneRectangle) {
  TempDir tmp("window");
  constexpr uint32_t kFrames = 7;
  const capture::CaptureManifest m = make_manifest(16, kFrames, {{0, 0, 0}});
  ASSERT_TRUE(
      write_capture(tmp.path() / "cap", m, [](uint32_t, uint32_t frame, capture::ViewFrame& vf) {
        const float rgb[3] = {0.5f, 0.5f, 0.5f};
        for (int f = 0; f < 6; ++f) {
          fill_face(vf, cube_face_from_index(f), rgb, 0);
          for (uint32_t y = 0; y < 16; ++y) {
            for (uint32_t x = 0; x < 16; ++x) {
              vf.depth[vf.texel_index(cube_face_from_index(f), x, y)] =
                  moving_depth(frame, f, x, y);
            }
          }
        }
      }).ok());
  struct Case {
    uint32_t window, interval;
    encoder::DepthCoding depth;
  };
  // W = the frame count in one group; W = 65535 (the largest) with groups of K = 3 frames, so
  // the window is clamped to the group; BC5 depth (rectangles 4-aligned).
  for (const Case& k : {Case{kFrames, 30, encoder::DepthCoding::kRaw16},
                        Case{65535, 3, encoder::DepthCoding::kRaw16},
                        Case{kFrames, 30, encoder::DepthCoding::kBc5}}) {
    encoder::LightfieldEncodeOptions eo;
    eo.cell_size = 8;
    eo.colour = encoder::ColourCoding::kRgba16f;  // given: no HDR pre-pass over the set
    eo.depth_window = k.window;
    eo.max_aabbs = 1;
    eo.depth_keyframe_interval = k.interval;
    eo.depth = k.depth;
    const std::string name =
        cat("W", k.window, "_K", k.interval, k.depth == encoder::DepthCoding::kBc5 ? "_bc5" : "");
    const std::string clip = tmp.file(cat(name, ".calf"));
    auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
    ASSERT_TRUE(stats.ok()) << name << ": " << stats.status().to_string();
    // A = 1: every P-frame of the changing tile is one rectangle covering both changes.
    {
      auto reader = container::Reader::open(clip);
      ASSERT_TRUE(reader.ok());
      auto ref = decoder::LightfieldReference::open(*reader, 0);
      ASSERT_TRUE(ref.ok());
      auto counts = ref->depth_rect_counts(0, 0, 0);
      ASSERT_TRUE(counts.ok()) << counts.status().to_string();
      ASSERT_EQ(counts->size(), kFrames);
      for (uint32_t f = 0; f < kFrames; ++f) EXPECT_EQ((*counts)[f], 1u) << name << " frame " << f;
    }
    if (k.depth == encoder::DepthCoding::kBc5) {
      // BC5 is lossy: only the absence of NaN in its error report is checked here.
      EXPECT_FALSE(std::isnan(stats->depth_mean_rel_error));
      continue;
    }
    // Every frame by playing forward, by seeking in a scrambled order on one decoder (stepping
    // through P-frames W at a time, restarting from a group keyframe when it must), and by
    // opening a fresh decoder per frame: the capture's depth each time.
    const auto check = [&](DecodedClip& d, uint32_t frame, const std::string& how) {
      for (int f = 0; f < 6; ++f) {
        expect_depths(
            d, 0, cube_face_from_index(f),
            [&](uint32_t x, uint32_t y) { return moving_depth(frame, f, x, y); },
            cat(name, " ", how, " frame ", frame));
      }
    };
    auto player = decode_clip(clip, 0);
    ASSERT_TRUE(player);
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
      ASSERT_TRUE(player->advance(frame).ok());
      check(*player, frame, "playing");
    }
    auto seeker = decode_clip(clip, 0);
    ASSERT_TRUE(seeker);
    for (uint32_t frame : {6u, 2u, 5u, 0u, 3u, 1u, 4u, 6u}) {
      ASSERT_TRUE(seeker->advance(frame).ok());
      check(*seeker, frame, "seeking");
    }
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
      auto fresh = decode_clip(clip, frame);
      ASSERT_TRUE(fresh);
      check(*fresh, frame, "fresh");
    }
  }
}

// ---- Face sizes ----

struct Coding {
  encoder::ColourCoding colour;
  encoder::DepthCoding depth;
  double colour_tol;  // largest colour error against the capture
  const char* name;
};

// Encodes a set of `n`-texel faces (2 frames: frame 1 changes +X texel (n-1, n-1)) in several
// formats; the decoded state equals the reference decoder's and the capture (within the
// format's error); calf-play (CPU and GL) shows the texel a ray through its centre points at.
void check_face_size(uint32_t n, uint32_t cell, const Vec3& ray_to_last_texel) {
  TempDir tmp(cat("face", n));
  const capture::CaptureManifest m = make_manifest(n, 2, {{0, 0, 0}});
  const auto colour = [&](uint32_t frame, int f, uint32_t x, uint32_t y, int c) {
    if (frame == 1 && f == 0 && x == n - 1 && y == n - 1) return c == 0 ? 0.0625f : 0.875f;
    return texel_colour(f, x, y, c);
  };
  ASSERT_TRUE(
      write_capture(tmp.path() / "cap", m, [&](uint32_t, uint32_t frame, capture::ViewFrame& vf) {
        fill_named_texels(0, vf);
        for (int f = 0; f < 6; ++f) {
          for (uint32_t y = 0; y < n; ++y) {
            for (uint32_t x = 0; x < n; ++x) {
              const size_t i = vf.texel_index(cube_face_from_index(f), x, y);
              for (int c = 0; c < 3; ++c) vf.color[3 * i + c] = colour(frame, f, x, y, c);
            }
          }
        }
      }).ok());
  const Coding codings[] = {
      {encoder::ColourCoding::kRgba16f, encoder::DepthCoding::kRaw16, 0.0, "rgba16f+raw16"},
      {encoder::ColourCoding::kBc1, encoder::DepthCoding::kBc5, 0.12, "bc1+bc5"},
      {encoder::ColourCoding::kBc7, encoder::DepthCoding::kRaw16, 0.05, "bc7+raw16"},
      {encoder::ColourCoding::kBc6h, encoder::DepthCoding::kBc5, 0.1, "bc6h+bc5"},
  };
  for (const Coding& k : codings) {
    const std::string what = cat("face ", n, " ", k.name);
    encoder::LightfieldEncodeOptions eo;
    eo.cell_size = cell;
    eo.colour = k.colour;
    eo.depth = k.depth;
    const std::string clip = tmp.file(cat(k.name, ".calf"));
    auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
    ASSERT_TRUE(stats.ok()) << what << ": " << stats.status().to_string();
    for (uint32_t frame : {0u, 1u}) {
      auto decoded = decode_clip(clip, frame);
      ASSERT_TRUE(decoded);
      ASSERT_EQ(decoded->header().face_size, n);
      auto ref = decoder::LightfieldReference::open(*decoded->reader, 0);
      ASSERT_TRUE(ref.ok());
      for (int f = 0; f < 6; ++f) {
        const CubeFace face = cube_face_from_index(f);
        decoder::LightfieldFace want;
        ASSERT_TRUE(ref->decode_face(0, f, frame, &want).ok());
        const std::vector<float> rgb = decoded->textures->colour(0, face);
        ASSERT_EQ(rgb, want.colour) << what << " face " << f;
        const auto depth = decoded->textures->depth(0, face);
        ASSERT_TRUE(std::equal(depth.begin(), depth.end(), want.depth.begin())) << what;
        for (uint32_t y = 0; y < n; ++y) {
          for (uint32_t x = 0; x < n; ++x) {
            for (int c = 0; c < 3; ++c) {
              ASSERT_NEAR(rgb[3 * (size_t{y} * n + x) + c], colour(frame, f, x, y, c), k.colour_tol)
                  << what << " frame " << frame << " face " << f << " texel " << x << "," << y;
            }
          }
        }
        if (k.depth == encoder::DepthCoding::kRaw16) {
          expect_depths(
              *decoded, 0, face, [&](uint32_t x, uint32_t y) { return texel_depth(0, f, x, y); },
              what);
        }
      }
    }
    if (k.colour != encoder::ColourCoding::kRgba16f) continue;
    // calf-play, view-dependent decoding, a 1 x 1 eye at the viewpoint aimed at the centre of
    // +X texel (n-1, n-1) (in the last, partial cell when n is not a multiple of the cell): at a
    // texel centre the bilinear colour is that texel's.
    Camera cam;
    cam.forward = ray_to_last_texel;
    cam.width = cam.height = 1;
    for (bool gl : {false, true}) {
      player::OsMesaContext* ctx = gl ? gl_context() : nullptr;
      if (gl && ctx == nullptr) continue;
      PlaybackOptions po;
      po.use_gl = gl;
      po.of<player::LightfieldOptions>().selection.budget.target_frame_ms = 0;
      auto play = Playback::open(clip, po, gl ? &ctx->gl() : nullptr);
      ASSERT_TRUE(play.ok()) << what << ": " << play.status().to_string();
      for (uint32_t frame : {0u, 1u}) {
        ASSERT_TRUE((*play)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
        EXPECT_GT((*play)->lightfield()->last_stats().visible_cells, 0u);
        RenderedImage img;
        ASSERT_TRUE((*play)->render(cam, &img).ok());
        ASSERT_EQ(bad_pixels(img), 0u);
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(img.color[c], colour(frame, 0, n - 1, n - 1, c), 1e-5)
              << what << (gl ? " GL" : " CPU") << " frame " << frame << " channel " << c;
        }
        EXPECT_NEAR(img.depth[0] / texel_depth(0, 0, n - 1, n - 1), 1.0, 2e-3) << what;
      }
    }
  }
}

// The ray through the centre of +X texel (n-1, n-1): s = t = (n - 0.5) / n, and by the cube
// table sc = -z = 2s - 1, tc = -y = 2t - 1 on the +X face.
Vec3 last_texel_ray(uint32_t n) {
  const double sc = 2 * (n - 0.5) / n - 1;
  return {1, -sc, -sc};
}

TEST(FaceSize, OneTexelFaces) {
  check_face_size(1, 4, last_texel_ray(1));
}
TEST(FaceSize, FourTexelFaces) {
  check_face_size(4, 4, last_texel_ray(4));
}
TEST(FaceSize, TwentyTexelFacesWithCellsOf16) {
  // 20 = 16 + 4: the second cell column and row are 4 texels wide; depth regions are 12 and 8.
  auto cells = FaceGrid::with_cell_size(20, 16);
  ASSERT_TRUE(cells.ok());
  EXPECT_EQ(cells->cells_per_side(), 2u);
  EXPECT_EQ(cells->cell_rect(1, 1), (PixelRect{16, 16, 4, 4}));
  check_face_size(20, 16, last_texel_ray(20));
}

// 2048-texel faces, one view, one frame, a constant colour and depth per face (the cheapest
// content): the grid, the encoder and the view-dependent decoder at that size. Release: ~10 s and
// 1 GB; under ASan + UBSan ~15 s of CPU and 1.3 GB, most of it writing and reading the
// 2048 x 12288 EXR and converting 25 M texels in the capture reader and the encoder.
TEST(FaceSize, Faces2048) {
  const auto t0 = std::chrono::steady_clock::now();
  TempDir tmp("face2048");
  constexpr uint32_t kN = 2048;
  const capture::CaptureManifest m = make_manifest(kN, 1, {{0, 0, 0}});
  const auto face_rgb = [](int f, int c) {
    return c == 0 ? (f + 1) / 8.0f : c == 1 ? 0.5f : 0.25f;
  };
  ASSERT_TRUE(write_capture(tmp.path() / "cap", m, [&](uint32_t, uint32_t, capture::ViewFrame& vf) {
                for (int f = 0; f < 6; ++f) {
                  const float rgb[3] = {face_rgb(f, 0), face_rgb(f, 1), face_rgb(f, 2)};
                  fill_face(vf, cube_face_from_index(f), rgb, 1.0f + f);
                }
              }).ok());
  encoder::LightfieldEncodeOptions eo;
  eo.cell_size = 256;
  eo.colour =
      encoder::ColourCoding::kRgba16f;  // given: no HDR pre-pass; raw halves: no BC or sRGB work
  eo.threads = 2;
  eo.levels.zstd_level = 1;  // level 19 spends seconds on 60 MB of constant chunks
  const std::string clip = tmp.file("big.calf");
  auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  EXPECT_EQ(stats->colour_cells, 6u * 8 * 8);
  EXPECT_EQ(stats->depth_regions, 6u * 2 * 2);
  const auto t1 = std::chrono::steady_clock::now();

  auto reader = container::Reader::open(clip);
  ASSERT_TRUE(reader.ok());
  auto ref = decoder::LightfieldReference::open(*reader, 0);
  ASSERT_TRUE(ref.ok());
  EXPECT_EQ(ref->header().face_size, kN);
  EXPECT_EQ(ref->header().depth_region_size, 1024u);
  for (int f : {0, 5}) {
    decoder::LightfieldFace face;
    ASSERT_TRUE(ref->decode_face(0, f, 0, &face).ok());
    ASSERT_EQ(face.depth.size(), size_t{kN} * kN);
    for (size_t i = 0; i < face.depth.size(); i += 4099) {
      // z_near = 1 (face 0), z_far = 6 (face 5): codes 0 and 65534.
      ASSERT_EQ(face.depth[i], f == 0 ? 0 : kLog16MaxFinite);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(face.colour[3 * i + c], face_rgb(f, c));
    }
  }
  // A narrow eye at the viewpoint looking at +X: only a few of the 384 cells are decoded.
  auto d = decoder::LightfieldDecoder::open(*reader, 0);
  ASSERT_TRUE(d.ok());
  EyeView eye;
  eye.forward = {1, 0, 0};
  eye.fov_y = 0.1;
  eye.near = 0.5;
  eye.far = 10;
  decoder::LightfieldFrameUpdates fu;
  ASSERT_TRUE(d->advance(0, std::span<const EyeView>(&eye, 1), {}, &fu).ok());
  EXPECT_EQ(fu.stats.errors, 0u);
  EXPECT_EQ(fu.stats.total_cells, 384u);
  EXPECT_GE(fu.stats.visible_cells, 1u);
  EXPECT_LE(fu.stats.visible_cells, 4u);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("2048 faces: capture + encode %.1f s, decode %.1f s, %zu bytes, %u cells visible\n",
              std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count(),
              static_cast<size_t>(fs::file_size(clip)), fu.stats.visible_cells);
}

}  // namespace
}  // namespace calf::extreme
