// Numerical extremes of colour: HDR values up to 65504 (the largest half) and tiny
// positives down to the smallest subnormal half (2^-24), through rgba16f (exact) and BC6H (within
// the block codec's documented error); and cells whose reconstruction error is zero (constant
// and black cells: PSNR +inf), which must neither break the keyframe search nor put a NaN in the
// statistics, and which must cost next to nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "calf/decoder/lightfield_reference.h"
#include "calf/encoder/colour_keyframes.h"
#include "calf/format/lightfield_layout.h"
#include "calf/player/image_compare.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/playback.h"
#include "extreme_common.h"

namespace calf::extreme {
namespace {

using player::RenderedImage;

constexpr float kHalfMax = 65504.0f;
constexpr float kHalfTiny = 0x1p-24f;       // the smallest subnormal half
constexpr float kHalfMinNormal = 0x1p-14f;  // the smallest normal half

// ---- HDR extremes ----

// +X of the only view, 8 x 8 texels as four 4 x 4 blocks (R = G = the value, B = 0.25):
//   block (0, 0) 65504          block (1, 0) 6e-8 (stored as the half 2^-24)
//   block (0, 1) 2^-14          block (1, 1) checkerboard of 65504 and 1e-7 (half: 2 * 2^-24)
// Frame 1 turns block (0, 0) to 0.5. The other faces are a constant HDR 2.0. Depth 1 + face.
float hdr_value(uint32_t x, uint32_t y, uint32_t frame) {
  const uint32_t bx = x / 4, by = y / 4;
  if (bx == 0 && by == 0) return frame == 0 ? kHalfMax : 0.5f;
  if (bx == 1 && by == 0) return 6e-8f;
  if (bx == 0 && by == 1) return kHalfMinNormal;
  return (x + y) % 2 == 0 ? kHalfMax : 1e-7f;
}

Status write_hdr_capture(const fs::path& dir) {
  const capture::CaptureManifest m = make_manifest(8, 2, {{0, 0, 0}});
  return write_capture(dir, m, [](uint32_t, uint32_t frame, capture::ViewFrame& vf) {
    for (int f = 0; f < 6; ++f) {
      const float rgb[3] = {2.0f, 2.0f, 2.0f};
      fill_face(vf, cube_face_from_index(f), rgb, 1.0f + f);
    }
    for (uint32_t y = 0; y < 8; ++y) {
      for (uint32_t x = 0; x < 8; ++x) {
        const size_t i = vf.texel_index(CubeFace::kPosX, x, y);
        vf.color[3 * i] = vf.color[3 * i + 1] = hdr_value(x, y, frame);
        vf.color[3 * i + 2] = 0.25f;
      }
    }
  });
}

// The bit pattern of a non-negative value that is exactly a half, as a number (subnormals count
// in steps of 2^-24; normals as exponent field * 1024 + mantissa), so that the distance between
// two patterns is their distance in half ulps.
double half_bits(float v) {
  if (v < kHalfMinNormal) return v / kHalfTiny;
  int e;
  std::frexp(v, &e);  // v = m * 2^e, m in [0.5, 1)
  const int exponent = e - 1;
  return (exponent + 15) * 1024.0 + (std::ldexp(v, -exponent) - 1) * 1024.0;
}
int half_ulps(float a, float b) {
  return static_cast<int>(std::lround(std::fabs(half_bits(a) - half_bits(b))));
}

TEST(HdrColour, HalfExtremesComeBackExactlyThroughRgba16fAndWithinBc6hError) {
  TempDir tmp("hdr");
  ASSERT_TRUE(write_hdr_capture(tmp.path() / "cap").ok());
  for (encoder::ColourCoding coding :
       {encoder::ColourCoding::kRgba16f, encoder::ColourCoding::kBc6h}) {
    const bool bc6h = coding == encoder::ColourCoding::kBc6h;
    encoder::LightfieldEncodeOptions eo;
    eo.cell_size = 8;
    eo.colour = coding;
    const std::string clip = tmp.file(bc6h ? "bc6h.calf" : "rgba16f.calf");
    auto stats = encoder::encode_lightfield_file(tmp.path() / "cap", clip, eo);
    ASSERT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_TRUE(stats->hdr);
    EXPECT_FALSE(std::isnan(stats->min_colour_quality_db));
    for (uint32_t frame : {0u, 1u}) {
      auto decoded = decode_clip(clip, frame);
      ASSERT_TRUE(decoded);
      const std::vector<float> rgb = decoded->textures->colour(0, CubeFace::kPosX);
      int worst_ulps = 0;
      for (uint32_t y = 0; y < 8; ++y) {
        for (uint32_t x = 0; x < 8; ++x) {
          const size_t i = 3 * (size_t{y} * 8 + x);
          const float want = as_half(hdr_value(x, y, frame));
          for (int c = 0; c < 3; ++c) {
            ASSERT_TRUE(std::isfinite(rgb[i + c]) && rgb[i + c] >= 0 && rgb[i + c] <= kHalfMax)
                << "frame " << frame << " texel " << x << "," << y;
          }
          const bool mixed_block = x >= 4 && y >= 4;
          // B is 0.25 everywhere: exact in rgba16f, within one half ulp in a constant BC6H block
          // and within 1 % in the block whose R and G span 65504 .. 1e-7.
          if (!mixed_block) {
            EXPECT_LE(half_ulps(rgb[i + 2], 0.25f), bc6h ? 1 : 0) << x << "," << y;
          } else {
            EXPECT_NEAR(rgb[i + 2], 0.25f, bc6h ? 0.0025 : 0.0) << x << "," << y;
          }
          if (!bc6h) {
            ASSERT_EQ(rgb[i], want) << "rgba16f texel " << x << "," << y;  // lossless
          } else if (!mixed_block) {
            // Constant blocks: BC6H stores 10..16-bit endpoints, so a constant block is within
            // one half ulp of its value (docs/BLOCK_CODECS.md, "HDR inputs").
            const int ulps = half_ulps(rgb[i], want);
            worst_ulps = std::max(worst_ulps, ulps);
            EXPECT_LE(ulps, 1) << "BC6H texel " << x << "," << y << ": " << rgb[i] << " for "
                               << want;
          } else if (want == kHalfMax) {
            // One block spanning 65504 and 1e-7: the bright texels keep their value to 1 % ...
            EXPECT_NEAR(rgb[i] / kHalfMax, 1.0, 0.01) << x << "," << y;
          } else {
            // ... the dim ones land anywhere below the HDR metric's floor 2^-14, which is all
            // the keyframe metric can tell apart (log2-PSNR clamps at 2^-14, SPEC §11.1.4).
            EXPECT_LE(rgb[i], kHalfMinNormal) << x << "," << y;
          }
        }
      }
      if (bc6h)
        std::printf("BC6H frame %u: constant blocks within %d half ulp\n", frame, worst_ulps);
    }

    // Rendered from the viewpoint: the ray through the centre of +X texel (1, 1) (direction
    // (1, 0.625, 0.625) by the cube table: s = t = 1.5 / 8) shows 65504 itself, and a camera
    // over the whole face gives no Inf or NaN even where 65504 is blended.
    auto decoded = decode_clip(clip, 0);
    ASSERT_TRUE(decoded);
    auto views = view_set_of(*decoded);
    ASSERT_TRUE(views.ok());
    auto cpu = player::LightfieldCpuRenderer::make(*views,
                                                   *player::march_range_for(*views, {0, 0, 0}, {}));
    ASSERT_TRUE(cpu.ok());
    const double n = std::sqrt(1 + 2 * 0.625 * 0.625);
    const player::RaySample s = cpu->trace({0, 0, 0}, {1 / n, 0.625 / n, 0.625 / n});
    ASSERT_TRUE(s.hit);
    EXPECT_NEAR(s.rgb[0] / kHalfMax, 1.0, bc6h ? 1.0 / 1024 : 1e-9);
    EXPECT_NEAR(s.rgb[2], 0.25, 1e-9);
    Camera cam;
    cam.forward = {1, 0, 0};
    cam.fov_y = 1.6;
    cam.width = cam.height = 16;
    RenderedImage img;
    ASSERT_TRUE(cpu->render(cam, &img).ok());
    EXPECT_EQ(bad_pixels(img), 0u);
    float brightest = 0;
    for (float v : img.color) brightest = std::max(brightest, v);
    EXPECT_LE(brightest, kHalfMax);
    EXPECT_GE(brightest, 0.99f * kHalfMax);

    // The GL renderer (BC6H textures decoded by the GPU, float shading) through calf-play's loop;
    // rgba16f textures are what every other GL test uses.
    player::OsMesaContext* gl = bc6h ? gl_context() : nullptr;
    if (gl == nullptr) continue;
    player::PlaybackOptions po;
    po.of<player::LightfieldOptions>().selection.budget.target_frame_ms = 0;
    auto gpu = player::Playback::open(clip, po, &gl->gl());
    ASSERT_TRUE(gpu.ok()) << gpu.status().to_string();
    ASSERT_TRUE((*gpu)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
    RenderedImage gimg;
    ASSERT_TRUE((*gpu)->render(cam, &gimg).ok());
    EXPECT_EQ(bad_pixels(gimg), 0u) << "GL BC6H";
    float gl_brightest = 0;
    for (float v : gimg.color) gl_brightest = std::max(gl_brightest, v);
    EXPECT_NEAR(gl_brightest, brightest, brightest * 1e-4);
  }
}

TEST(HdrColour, ValuesAboveTheLargestHalfAreRefusedNamingThePixel) {
  TempDir tmp("hdr_over");
  const capture::CaptureManifest m = make_manifest(4, 1, {{0, 0, 0}});
  for (float bad : {65505.0f, 1e30f, kInfF, std::nanf("")}) {
    auto w = capture::CaptureSetWriter::create(tmp.path(), m);
    ASSERT_TRUE(w.ok());
    capture::ViewFrame vf;
    vf.resize(4, false);
    const float rgb[3] = {1, 1, 1};
    for (int f = 0; f < 6; ++f) fill_face(vf, cube_face_from_index(f), rgb, 1.0f);
    vf.color[3 * vf.texel_index(CubeFace::kPosY, 3, 2) + 1] = bad;
    const Status s = w->write(0, 0, vf);
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_EQ(s.id(), ErrorId::kCaptureColourPixel);
    EXPECT_NE(s.message().find("face +Y texel (3, 2): colour channel G"), std::string::npos)
        << s.message();
    w->abandon();
  }
}

// ---- Constant and black cells: MSE 0 ----

// Frames 0..3 one colour, frames 4..7 black, compared without a codec in between: every frame
// is reproduced exactly (t = 0 from K0, t = 255 from K7), so every quality is +inf. Alg. 2 then
// keeps the widest segment: keyframes {0, 7}, t = 0 0 0 0 255 255 255 0, worst quality +inf.
TEST(ConstantCells, InfinitePsnrKeepsTheKeyframeSearchFinite) {
  constexpr uint32_t kTexels = 16, kFrames = 8;
  std::vector<float> frames(kTexels * 3 * kFrames, 0.0f);
  for (uint32_t f = 0; f < 4; ++f) {
    for (uint32_t i = 0; i < kTexels; ++i) {
      frames[(f * kTexels + i) * 3 + 0] = 0.2f;
      frames[(f * kTexels + i) * 3 + 1] = 0.4f;
      frames[(f * kTexels + i) * 3 + 2] = 0.6f;
    }
  }
  const encoder::ShownKeyframeFn shown = [&](uint32_t f) -> Expected<std::span<const float>> {
    return std::span<const float>(frames).subspan(f * kTexels * 3, kTexels * 3);
  };
  for (const encoder::CellQualityFn& quality :
       {encoder::CellQualityFn(encoder::psnr_srgb), encoder::CellQualityFn(encoder::psnr_log2)}) {
    for (encoder::KeyframeSearch search :
         {encoder::KeyframeSearch::kGalloping, encoder::KeyframeSearch::kExhaustive}) {
      encoder::KeyframeOptions o;
      o.search = search;
      auto k = encoder::select_cell_keyframes(frames, kFrames, kTexels, shown, quality, o);
      ASSERT_TRUE(k.ok()) << k.status().to_string();
      EXPECT_EQ(k->keyframes, (std::vector<uint32_t>{0, 7}));
      EXPECT_EQ(k->t, (std::vector<uint8_t>{0, 0, 0, 0, 255, 255, 255, 0}));
      EXPECT_EQ(k->min_quality_db, std::numeric_limits<double>::infinity());
    }
  }
  // A cell black in every frame: one keyframe, quality +inf, never NaN.
  const std::vector<float> black(kTexels * 3 * kFrames, 0.0f);
  const encoder::ShownKeyframeFn shown_black = [&](uint32_t f) -> Expected<std::span<const float>> {
    return std::span<const float>(black).subspan(f * kTexels * 3, kTexels * 3);
  };
  auto k =
      encoder::select_cell_keyframes(black, kFrames, kTexels, shown_black, encoder::psnr_log2, {});
  ASSERT_TRUE(k.ok());
  EXPECT_EQ(k->keyframes, std::vector<uint32_t>{0});
  EXPECT_EQ(k->min_quality_db, std::numeric_limits<double>::infinity());
  EXPECT_EQ(encoder::psnr_srgb(std::span<const float>(black).first(48),
                               std::span<const float>(black).first(48)),
            std::numeric_limits<double>::infinity());
}

// The player's metrics on exact reconstructions (calf-play's per-frame statistics): MSE 0 gives
// PSNR +inf (never NaN) and SSIM exactly 1, also for black images (mean and variance 0) and for
// HDR images at 65504 (clamped to 1 by the sRGB encoding).
TEST(ConstantCells, ExactFramesGiveInfinitePsnrAndUnitSsim) {
  for (float v : {0.0f, 0.5f, kHalfMax}) {
    RenderedImage img;
    img.width = img.height = 16;
    img.color.assign(16 * 16 * 3, v);
    img.depth.assign(16 * 16, 1.0f);
    auto p = player::psnr(player::rgb_ref(img), player::rgb_ref(img));
    auto q = player::ssim(player::rgb_ref(img), player::rgb_ref(img));
    auto e = player::error_map(player::rgb_ref(img), player::rgb_ref(img));
    ASSERT_TRUE(p.ok() && q.ok() && e.ok()) << v;
    EXPECT_EQ(*p, std::numeric_limits<double>::infinity()) << v;
    EXPECT_EQ(*q, 1.0) << v;
    for (float x : *e) ASSERT_EQ(x, 0.0f) << v;
  }
}

// 16-texel faces of four 8 x 8 cells, 8 frames: on every face cell 0 is black, cell 1 a constant
// grey, cell 2 the colour-then-black cell above, cell 3 black with one HDR texel when `hdr`.
// Depth is constant per face. Everything static except cell 2.
Status write_constant_capture(const fs::path& dir, bool hdr) {
  const capture::CaptureManifest m = make_manifest(16, 8, {{0, 0, 0}});
  return write_capture(dir, m, [hdr](uint32_t, uint32_t frame, capture::ViewFrame& vf) {
    for (int f = 0; f < 6; ++f) {
      for (uint32_t y = 0; y < 16; ++y) {
        for (uint32_t x = 0; x < 16; ++x) {
          const size_t i = vf.texel_index(cube_face_from_index(f), x, y);
          const uint32_t cell = (y / 8) * 2 + x / 8;
          float rgb[3] = {0, 0, 0};
          if (cell == 1) rgb[0] = rgb[1] = rgb[2] = 0.5f;
          if (cell == 2 && frame < 4) rgb[0] = 0.25f, rgb[1] = 0.5f, rgb[2] = 0.75f;
          if (cell == 3 && hdr && x == 12 && y == 12) rgb[0] = 4.0f;
          for (int c = 0; c < 3; ++c) vf.color[3 * i + c] = rgb[c];
          vf.depth[i] = 2.0f + f;
        }
      }
    }
  });
}

TEST(ConstantCells, BlackAndConstantCellsCostNextToNothingAndDecodeExactly) {
  TempDir tmp("const");
  for (bool hdr : {false, true}) {
    const fs::path cap = tmp.path() / (hdr ? "cap_hdr" : "cap_ldr");
    ASSERT_TRUE(write_constant_capture(cap, hdr).ok());
    // LDR: auto (BC1) and rgba16f; HDR: auto (BC6H).
    for (encoder::ColourCoding coding :
         {encoder::ColourCoding::kAuto, encoder::ColourCoding::kRgba16f}) {
      if (hdr && coding != encoder::ColourCoding::kAuto) continue;
      encoder::LightfieldEncodeOptions eo;
      eo.cell_size = 8;
      eo.colour = coding;
      const std::string clip = tmp.file("c.calf");
      auto stats = encoder::encode_lightfield_file(cap, clip, eo);
      ASSERT_TRUE(stats.ok()) << stats.status().to_string();
      const auto& s = *stats;
      // No NaN anywhere in the statistics; exact reconstructions count as +inf dB.
      for (double v : {s.min_colour_quality_db, s.depth_max_rel_error, s.depth_mean_rel_error}) {
        EXPECT_FALSE(std::isnan(v));
      }
      EXPECT_GE(s.min_colour_quality_db, eo.min_psnr_db);
      // 24 cells: 18 static (one keyframe each) and 6 colour-then-black cells (keyframes 0, 7).
      EXPECT_EQ(s.colour_cells, 24u);
      EXPECT_EQ(s.colour_keyframes, 18u + 6u * 2u);
      EXPECT_EQ(s.depth_pframes, s.depth_empty_pframes);  // depth never changes
      // Tiny: every chunk is a few bytes of zstd; the file is mostly its 64-byte index entries.
      const uint64_t chunks = s.colour.chunks + s.depth.chunks;
      const uint64_t payload = s.colour.stored + s.depth.stored;
      const uint64_t file = fs::file_size(clip);
      std::printf("%s %s: raw %llu bytes, chunks %llu, stored payload %llu, file %llu\n",
                  hdr ? "HDR" : "LDR", coding == encoder::ColourCoding::kAuto ? "auto" : "rgba16f",
                  static_cast<unsigned long long>(s.colour.raw + s.depth.raw),
                  static_cast<unsigned long long>(chunks), static_cast<unsigned long long>(payload),
                  static_cast<unsigned long long>(file));
      EXPECT_LE(payload, chunks * 40);
      EXPECT_LE(file, 64 + chunks * (64 + 48) + 2048);

      // Decoded: black is exactly 0, the constant grey exact (rgba16f) or within BC1 / BC6H
      // quantisation, the colour-then-black cell black from frame 4 on.
      for (uint32_t frame : {0u, 5u}) {
        auto decoded = decode_clip(clip, frame);
        ASSERT_TRUE(decoded);
        EXPECT_FALSE(std::isnan(decoded->last.stats.mbps_at_24fps()));
        for (int f = 0; f < 6; ++f) {
          const std::vector<float> rgb = decoded->textures->colour(0, cube_face_from_index(f));
          for (uint32_t y = 0; y < 16; ++y) {
            for (uint32_t x = 0; x < 16; ++x) {
              const uint32_t cell = (y / 8) * 2 + x / 8;
              const size_t i = 3 * (size_t{y} * 16 + x);
              if (cell == 0 || (cell == 2 && frame >= 4) || (cell == 3 && !(x == 12 && y == 12))) {
                for (int c = 0; c < 3; ++c) {
                  ASSERT_EQ(rgb[i + c], 0.0f) << "black texel " << x << "," << y << " face " << f;
                }
              } else if (cell == 1) {
                const double tol = coding == encoder::ColourCoding::kRgba16f ? 0 : 0.02;
                for (int c = 0; c < 3; ++c) ASSERT_NEAR(rgb[i + c], 0.5, tol);
              }
            }
          }
        }
      }
      auto reader = container::Reader::open(clip);
      ASSERT_TRUE(reader.ok());
      auto ref = decoder::LightfieldReference::open(*reader, 0);
      ASSERT_TRUE(ref.ok());
      auto timeline = ref->cell_timeline(0, 0, 2);
      ASSERT_TRUE(timeline.ok());
      EXPECT_EQ(timeline->keyframes, (std::vector<uint32_t>{0, 7}));
      EXPECT_EQ(timeline->t, (std::vector<uint8_t>{0, 0, 0, 0, 255, 255, 255, 0}));
    }
  }
}

}  // namespace
}  // namespace calf::extreme
