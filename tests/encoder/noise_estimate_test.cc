// Tests of the render-noise estimate (encoder/include/calf/encoder/noise_estimate.h) on synthetic
// frames whose noise is known: the expected PSNR is computed from sigma alone.
#include "calf/encoder/noise_estimate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calf/format/colour.h"

namespace calf {
namespace {

constexpr uint32_t kFace = 48;

// A smooth picture in the metric's domain (sRGB-encoded value, or log2 of linear colour) at
// texel (x, y) of `face`, channel c, brightened by `shift` (a lighting change from frame to
// frame, smooth over the face).
double base_value(uint32_t face, uint32_t x, uint32_t y, int c, double shift) {
  return 0.45 + 0.15 * std::sin(0.13 * x + 0.7 * face + c) * std::cos(0.11 * y) + shift;
}

// `frames` frames of one view: static geometry (depth 2 everywhere) except a square whose depth
// changes every frame (a moving object, its colour random), plus Gaussian noise of sigma in the
// metric's domain, drawn anew every frame. `lighting` brightens every frame by that much more.
std::vector<capture::ViewFrame> make_frames(uint32_t frames, double sigma,
                                            encoder::NoiseMetric metric, double lighting,
                                            uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<float> any(0.0f, 1.0f);
  std::vector<capture::ViewFrame> out(frames);
  for (uint32_t f = 0; f < frames; ++f) {
    capture::ViewFrame& v = out[f];
    v.resize(kFace, false);
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t y = 0; y < kFace; ++y) {
        for (uint32_t x = 0; x < kFace; ++x) {
          const size_t i = (size_t{face} * kFace + y) * kFace + x;
          const bool moving = face == 0 && x >= 8 + 4 * f && x < 24 + 4 * f && y >= 8 && y < 24;
          v.depth[i] = moving ? 1.0f + 0.1f * static_cast<float>(f) : 2.0f;
          for (int c = 0; c < 3; ++c) {
            if (moving) {
              v.color[3 * i + c] = any(rng);
              continue;
            }
            const double m = base_value(face, x, y, c, lighting * f) + sigma * noise(rng);
            v.color[3 * i + c] = metric == encoder::NoiseMetric::kLog2
                                     ? static_cast<float>(std::exp2(m * 8.0 - 6.0))
                                     : linear_from_srgb(static_cast<float>(m));
          }
        }
      }
    }
  }
  return out;
}

TEST(NoiseEstimateTest, GaussianNoiseInSrgbGivesItsPsnr) {
  for (const double sigma : {0.02, 0.007, 0.003}) {
    const auto frames = make_frames(4, sigma, encoder::NoiseMetric::kSrgb, 0.0, 7);
    const encoder::NoiseEstimate e =
        encoder::estimate_view_noise(frames, encoder::NoiseMetric::kSrgb, {});
    ASSERT_TRUE(e.psnr_db.has_value()) << sigma;
    // PSNR of a frame against its noise-free self, peak 1: -20 log10(sigma).
    EXPECT_NEAR(*e.psnr_db, -20.0 * std::log10(sigma), 0.4) << sigma;
    EXPECT_GT(e.samples, 500u);
  }
}

TEST(NoiseEstimateTest, SmoothLightingChangeIsNotNoise) {
  // Every frame 2 % brighter: the temporal difference is smooth, the high-pass removes it.
  const double sigma = 0.005;
  const auto frames = make_frames(4, sigma, encoder::NoiseMetric::kSrgb, 0.02, 11);
  const encoder::NoiseEstimate e =
      encoder::estimate_view_noise(frames, encoder::NoiseMetric::kSrgb, {});
  ASSERT_TRUE(e.psnr_db.has_value());
  EXPECT_NEAR(*e.psnr_db, -20.0 * std::log10(sigma), 0.4);
}

TEST(NoiseEstimateTest, GaussianNoiseInLog2GivesItsPsnr) {
  // Noise of sigma in log2 units (the base's log2 is m * 8 - 6, so sigma_log2 = 8 sigma), PSNR
  // with the 8-stop peak of encoder::psnr_log2: 10 log10(64 / sigma_log2^2).
  const double sigma = 0.004;
  const auto frames = make_frames(4, sigma, encoder::NoiseMetric::kLog2, 0.0, 13);
  const encoder::NoiseEstimate e =
      encoder::estimate_view_noise(frames, encoder::NoiseMetric::kLog2, {});
  ASSERT_TRUE(e.psnr_db.has_value());
  const double sigma_log2 = 8.0 * sigma;
  EXPECT_NEAR(*e.psnr_db, 10.0 * std::log10(64.0 / (sigma_log2 * sigma_log2)), 0.4);
}

TEST(NoiseEstimateTest, NoiseFreeFramesHaveNoEstimateAndKeepQ50) {
  // Identical static content: nothing changes, no sample.
  const auto still = make_frames(4, 0.0, encoder::NoiseMetric::kSrgb, 0.0, 1);
  const encoder::NoiseEstimate a =
      encoder::estimate_view_noise(still, encoder::NoiseMetric::kSrgb, {});
  EXPECT_FALSE(a.psnr_db.has_value());
  EXPECT_EQ(encoder::auto_psnr_db(a, encoder::kDefaultPsnrNoiseMargin), 50.0);
  // A noise-free lighting change: samples, but far above 50 dB + the margin.
  const auto lit = make_frames(4, 0.0, encoder::NoiseMetric::kSrgb, 0.02, 1);
  const encoder::NoiseEstimate b =
      encoder::estimate_view_noise(lit, encoder::NoiseMetric::kSrgb, {});
  EXPECT_GT(b.samples, 500u);
  if (b.psnr_db) {
    EXPECT_GT(*b.psnr_db, 50.0 + encoder::kDefaultPsnrNoiseMargin);
  }
  EXPECT_EQ(encoder::auto_psnr_db(b, encoder::kDefaultPsnrNoiseMargin), 50.0);
  // One frame: no pair, no estimate.
  const encoder::NoiseEstimate c =
      encoder::estimate_view_noise(std::span(still).first(1), encoder::NoiseMetric::kSrgb, {});
  EXPECT_FALSE(c.psnr_db.has_value());
  EXPECT_EQ(c.samples, 0u);
}

TEST(NoiseEstimateTest, AFewChangingBlocksAreNoEstimate) {
  // Still content but for one 8 x 8 block of one face that changes noisily every frame: 1 of
  // 216 blocks (< 2 %), what converged content shows beside a moving part.
  auto frames = make_frames(4, 0.0, encoder::NoiseMetric::kSrgb, 0.0, 3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> any(0.2f, 0.8f);
  for (capture::ViewFrame& v : frames) {
    for (uint32_t y = 32; y < 40; ++y) {
      for (uint32_t x = 32; x < 40; ++x) {
        for (int c = 0; c < 3; ++c)
          v.color[3 * ((size_t{2} * kFace + y) * kFace + x) + c] = any(rng);
      }
    }
  }
  encoder::NoiseEstimateOptions o;
  o.min_blocks = 1;
  const encoder::NoiseEstimate e =
      encoder::estimate_view_noise(frames, encoder::NoiseMetric::kSrgb, o);
  EXPECT_GT(e.samples, 0u);
  EXPECT_FALSE(e.psnr_db.has_value());
  o.min_share = 0;
  EXPECT_TRUE(
      encoder::estimate_view_noise(frames, encoder::NoiseMetric::kSrgb, o).psnr_db.has_value());
}

TEST(NoiseEstimateTest, AutoPsnrIsTheEstimateLessTheMarginCappedAt50) {
  encoder::NoiseEstimate e;
  e.psnr_db = 43.0;
  EXPECT_DOUBLE_EQ(encoder::auto_psnr_db(e, 4.0), 39.0);
  e.psnr_db = 60.0;
  EXPECT_DOUBLE_EQ(encoder::auto_psnr_db(e, 4.0), 50.0);
  e.psnr_db = 5.0;
  EXPECT_DOUBLE_EQ(encoder::auto_psnr_db(e, 4.0), encoder::kAutoPsnrFloorDb);
}

TEST(NoiseEstimateTest, NoiseAwareTestOnlyWhereQIsBelowTheCap) {
  encoder::NoiseEstimate e;
  EXPECT_EQ(encoder::auto_noise_psnr_db(e, 3.0), 0.0);  // no estimate: off
  e.psnr_db = 43.0;
  EXPECT_DOUBLE_EQ(encoder::auto_noise_psnr_db(e, 3.0), 43.0);
  // Q = min(50, 53 - 3) = 50, the cap: the plain test, as with --psnr 50.
  e.psnr_db = 53.0;
  EXPECT_EQ(encoder::auto_noise_psnr_db(e, 3.0), 0.0);
  e.psnr_db = 52.9;
  EXPECT_DOUBLE_EQ(encoder::auto_noise_psnr_db(e, 3.0), 52.9);
}

}  // namespace
}  // namespace calf
