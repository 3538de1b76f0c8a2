// Tests of colour keyframe selection (encoder/include/calf/encoder/colour_keyframes.h).
#include "calf/encoder/colour_keyframes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>

#include "calf/format/colour.h"

namespace calf {
namespace {

constexpr uint32_t kTexels = 16;
constexpr size_t kSize = kTexels * 3;

using Frame = std::vector<float>;

Frame random_frame(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Frame f(kSize);
  for (float& v : f) v = u(rng);
  return f;
}
Frame lerp(const Frame& a, const Frame& b, double t) {
  Frame f(kSize);
  for (size_t i = 0; i < kSize; ++i) f[i] = static_cast<float>((1 - t) * a[i] + t * b[i]);
  return f;
}
std::vector<float> concat(const std::vector<Frame>& frames) {
  std::vector<float> all;
  for (const auto& f : frames) all.insert(all.end(), f.begin(), f.end());
  return all;
}

// Keyframes shown exactly as given (a lossless spatial codec), counting calls.
struct Lossless {
  const std::vector<float>* all;
  std::map<uint32_t, int> calls;
  encoder::ShownKeyframeFn fn() {
    return [this](uint32_t f) -> Expected<std::span<const float>> {
      ++calls[f];
      return std::span<const float>(*all).subspan(f * kSize, kSize);
    };
  }
};

encoder::CellKeyframes select(const std::vector<float>& all, uint32_t n,
                              const encoder::ShownKeyframeFn& shown,
                              encoder::KeyframeOptions options = {}) {
  auto r = encoder::select_cell_keyframes(all, n, kTexels, shown, encoder::psnr_srgb, options);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return *r;
}

TEST(ColourKeyframesTest, StaticCellCostsOneKeyframe) {
  std::mt19937 rng(1);
  const Frame a = random_frame(rng);
  const auto all = concat(std::vector<Frame>(30, a));
  Lossless shown{&all, {}};
  const encoder::CellKeyframes k = select(all, 30, shown.fn());
  EXPECT_EQ(k.keyframes, (std::vector<uint32_t>{0}));
  EXPECT_EQ(k.t, std::vector<uint8_t>(30, 0));
  EXPECT_TRUE(std::isinf(k.min_quality_db));
}

TEST(ColourKeyframesTest, SingleFrame) {
  std::mt19937 rng(2);
  const auto all = concat({random_frame(rng)});
  Lossless shown{&all, {}};
  EXPECT_EQ(select(all, 1, shown.fn()).keyframes, (std::vector<uint32_t>{0}));
}

TEST(ColourKeyframesTest, LinearFadeNeedsOnlyItsEnds) {
  std::mt19937 rng(3);
  const Frame a = random_frame(rng), b = random_frame(rng);
  std::vector<Frame> frames;
  for (int i = 0; i < 21; ++i) frames.push_back(lerp(a, b, i / 20.0));
  const auto all = concat(frames);
  for (auto mode : {encoder::KeyframeSearch::kGalloping, encoder::KeyframeSearch::kExhaustive}) {
    Lossless shown{&all, {}};
    const encoder::CellKeyframes k = select(all, 21, shown.fn(), {50.0, mode});
    EXPECT_EQ(k.keyframes, (std::vector<uint32_t>{0, 20}));
    for (int i = 0; i <= 20; ++i) {
      if (i == 0 || i == 20) continue;
      EXPECT_NEAR(k.t[i], i / 20.0 * 255, 0.51) << i;
    }
    EXPECT_GE(k.min_quality_db, 50.0);
    for (const auto& [frame, count] : shown.calls) EXPECT_EQ(count, 1) << "cached frame " << frame;
  }
}

TEST(ColourKeyframesTest, UncorrelatedFramesAreAllKeyframes) {
  std::mt19937 rng(4);
  std::vector<Frame> frames;
  for (int i = 0; i < 8; ++i) frames.push_back(random_frame(rng));
  const auto all = concat(frames);
  Lossless shown{&all, {}};
  EXPECT_EQ(select(all, 8, shown.fn()).keyframes, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6, 7}));
}

// The same fade judged with lossy keyframes (quantised to 4 bits, as a spatial codec would) needs
// more keyframes: quality is measured on what the decoder shows, not on the input.
TEST(ColourKeyframesTest, QualityIsJudgedOnShownKeyframes) {
  std::mt19937 rng(5);
  const Frame a = random_frame(rng), b = random_frame(rng);
  std::vector<Frame> frames;
  for (int i = 0; i < 9; ++i) frames.push_back(lerp(a, b, i / 8.0));
  const auto all = concat(frames);
  std::vector<Frame> lossy_store(9);
  const encoder::ShownKeyframeFn lossy = [&](uint32_t f) -> Expected<std::span<const float>> {
    lossy_store[f] = Frame(all.begin() + f * kSize, all.begin() + (f + 1) * kSize);
    for (float& v : lossy_store[f]) v = std::round(v * 15) / 15;
    return std::span<const float>(lossy_store[f]);
  };
  Lossless exact{&all, {}};
  EXPECT_EQ(select(all, 9, exact.fn(), {40.0}).keyframes, (std::vector<uint32_t>{0, 8}));
  const encoder::CellKeyframes k =
      select(all, 9, lossy, {40.0, encoder::KeyframeSearch::kGalloping});
  EXPECT_GT(k.keyframes.size(), 2u);
  // Every non-keyframe frame, recomputed here from the lossy keyframes and stored t, is >= Q.
  for (uint32_t x = 0; x < 9; ++x) {
    auto it = std::upper_bound(k.keyframes.begin(), k.keyframes.end(), x);
    const uint32_t m = *(it - 1);
    if (m == x) continue;
    ASSERT_NE(it, k.keyframes.end());
    Frame rec(kSize);
    encoder::interpolate_keyframes(*lossy(m), *lossy(*it), k.t[x], rec);
    EXPECT_GE(encoder::psnr_srgb(frames[x], rec), 40.0) << x;
  }
}

// Frame 1 lies between frames 0 and 3 but not between 0 and 2: galloping stops at 1, the paper's
// exhaustive argmax finds 3.
TEST(ColourKeyframesTest, ExhaustiveFindsTheFarthestValidKeyframe) {
  std::mt19937 rng(6);
  const Frame a = random_frame(rng), c = random_frame(rng);
  const auto all = concat({a, lerp(a, c, 0.5), lerp(a, c, 0.25), c});
  Lossless g{&all, {}}, e{&all, {}};
  EXPECT_EQ(select(all, 4, e.fn(), {50.0, encoder::KeyframeSearch::kExhaustive}).keyframes,
            (std::vector<uint32_t>{0, 3}));
  EXPECT_GT(select(all, 4, g.fn(), {50.0, encoder::KeyframeSearch::kGalloping}).keyframes.size(),
            2u);
}

// A fade that then holds still: the farthest keyframe is the last frame, and frames equal to it
// are reconstructed with t = 255.
TEST(ColourKeyframesTest, FadeThenHoldReachesTheLastFrame) {
  std::mt19937 rng(7);
  const Frame a = random_frame(rng), b = random_frame(rng);
  const auto all = concat({a, lerp(a, b, 0.5), b, b, b, b});
  Lossless shown{&all, {}};
  const encoder::CellKeyframes k = select(all, 6, shown.fn());
  EXPECT_EQ(k.keyframes, (std::vector<uint32_t>{0, 5}));
  EXPECT_EQ(k.t, (std::vector<uint8_t>{0, 128, 255, 255, 255, 0}));
}

TEST(ColourKeyframesTest, BestTIsTheClosedFormRounded) {
  std::mt19937 rng(8);
  const Frame a = random_frame(rng), b = random_frame(rng);
  for (int t : {0, 1, 100, 128, 254, 255}) {
    EXPECT_EQ(encoder::best_interpolation_t(lerp(a, b, t / 255.0), a, b), t);
  }
  EXPECT_EQ(encoder::best_interpolation_t(lerp(a, b, 1.7), a, b), 255);  // clamped
  EXPECT_EQ(encoder::best_interpolation_t(lerp(a, b, -0.3), a, b), 0);
  EXPECT_EQ(encoder::best_interpolation_t(b, a, a), 0);  // identical keyframes
}

TEST(ColourKeyframesTest, PsnrSrgb) {
  const std::vector<float> zero(12, 0.0f);
  EXPECT_TRUE(std::isinf(encoder::psnr_srgb(zero, zero)));
  // sRGB 0.1 is linear ((0.1 + 0.055) / 1.055)^2.4; MSE 0.01 -> 20 dB.
  const float lin = static_cast<float>(std::pow((0.1 + 0.055) / 1.055, 2.4));
  const std::vector<float> grey(12, lin);
  EXPECT_NEAR(encoder::psnr_srgb(zero, grey), 20.0, 1e-4);
  // HDR values clamp to 1 on an LDR display.
  const std::vector<float> one(12, 1.0f), hot(12, 50.0f);
  EXPECT_TRUE(std::isinf(encoder::psnr_srgb(one, hot)));
}

TEST(ColourKeyframesTest, ErrorsPropagate) {
  std::mt19937 rng(9);
  const auto all = concat({random_frame(rng), random_frame(rng), random_frame(rng)});
  const encoder::ShownKeyframeFn failing = [](uint32_t f) -> Expected<std::span<const float>> {
    return Status(ErrorId::kInvalidArgument, "keyframe " + std::to_string(f) + " failed");
  };
  auto r = encoder::select_cell_keyframes(all, 3, kTexels, failing, encoder::psnr_srgb, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().message(), "keyframe 0 failed");
  Lossless shown{&all, {}};
  EXPECT_FALSE(
      encoder::select_cell_keyframes(all, 4, kTexels, shown.fn(), encoder::psnr_srgb, {}).ok());
  EXPECT_FALSE(
      encoder::select_cell_keyframes(all, 0, kTexels, shown.fn(), encoder::psnr_srgb, {}).ok());
}

// The noise-aware test (KeyframeOptions::noise). A static signal in sRGB values, each frame with
// its own Gaussian noise of sigma 0.01 (noise PSNR 40 dB in psnr_srgb's metric), on a 32 x 32
// cell (16 blocks of 8 x 8).
constexpr uint32_t kSide = 32;
constexpr uint32_t kNoisyTexels = kSide * kSide;
constexpr double kSigma = 0.01;
constexpr double kNoiseDb = 40.0;  // -20 log10(kSigma)

std::vector<float> noisy_frame(const std::vector<double>& signal_srgb, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, kSigma);
  std::vector<float> f(signal_srgb.size());
  for (size_t i = 0; i < f.size(); ++i) {
    f[i] = linear_from_srgb(static_cast<float>(signal_srgb[i] + n(rng)));
  }
  return f;
}

std::vector<double> random_signal(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.3, 0.7);
  std::vector<double> s(kNoisyTexels * 3);
  for (double& v : s) v = u(rng);
  return s;
}

// Q 1 dB below the noise: a frame held or interpolated from noisy keyframes measures 1.5 to 2
// times the noise variance against its own noisy input, so the plain test fails it.
encoder::CellKeyframes select_noisy(const std::vector<float>& all, uint32_t frames,
                                    bool noise_aware) {
  const encoder::ShownKeyframeFn shown = [&](uint32_t f) -> Expected<std::span<const float>> {
    return std::span<const float>(all).subspan(size_t{f} * kNoisyTexels * 3, kNoisyTexels * 3);
  };
  const double variance = kSigma * kSigma;
  const encoder::CellNoise noise =
      encoder::measure_cell_noise(all, frames, kSide, kSide, false, 1.0, 4 * variance);
  encoder::KeyframeOptions o;
  o.min_quality_db = kNoiseDb - 1;
  if (noise_aware) o.noise = &noise;
  auto r = encoder::select_cell_keyframes(all, frames, kNoisyTexels, shown, encoder::psnr_srgb, o);
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return *r;
}

// Frames of `signal`, frame `changed_frame` of `changed` instead.
std::vector<float> noisy_sequence(const std::vector<double>& signal,
                                  const std::vector<double>& changed, int changed_frame,
                                  std::mt19937& rng) {
  std::vector<float> all;
  for (int f = 0; f < 8; ++f) {
    const std::vector<float> frame = noisy_frame(f == changed_frame ? changed : signal, rng);
    all.insert(all.end(), frame.begin(), frame.end());
  }
  return all;
}

TEST(ColourKeyframesTest, CellNoiseMeasuresEachBlocksNoise) {
  std::mt19937 rng(10);
  const std::vector<double> signal = random_signal(rng);
  const auto all = noisy_sequence(signal, signal, -1, rng);
  const encoder::CellNoise noise =
      encoder::measure_cell_noise(all, 8, kSide, kSide, false, 1.0, 1.0);
  ASSERT_EQ(noise.block_variance.size(), 16u);
  for (const double v : noise.block_variance)
    EXPECT_NEAR(v, kSigma * kSigma, 0.25 * kSigma * kSigma);
  // factor scales it, max_variance bounds it; one frame has no pair: 0.
  const encoder::CellNoise half =
      encoder::measure_cell_noise(all, 8, kSide, kSide, false, 0.5, 1.0);
  EXPECT_DOUBLE_EQ(half.block_variance[5], noise.block_variance[5] / 2);
  const encoder::CellNoise capped =
      encoder::measure_cell_noise(all, 8, kSide, kSide, false, 1.0, 1e-5);
  EXPECT_EQ(capped.block_variance[5], 1e-5);
  EXPECT_EQ(encoder::measure_cell_noise(all, 1, kSide, kSide, false, 1.0, 1.0).block_variance,
            std::vector<double>(16, 0.0));
}

TEST(ColourKeyframesTest, NoiseAwareTestInterpolatesStaticNoise) {
  std::mt19937 rng(11);
  const std::vector<double> signal = random_signal(rng);
  const auto all = noisy_sequence(signal, signal, -1, rng);
  // The plain test charges the noise: every frame is a keyframe.
  EXPECT_EQ(select_noisy(all, 8, false).keyframes.size(), 8u);
  // Not charging the known noise, the static cell is one or two keyframes.
  EXPECT_LE(select_noisy(all, 8, true).keyframes.size(), 2u);
}

TEST(ColourKeyframesTest, NoiseAwareTestKeepsAChangeAboveTheNoise) {
  // Frame 4 differs from the others by a pattern of 5 sigma rms (25 times the noise variance):
  // it cannot be interpolated and stays a keyframe.
  std::mt19937 rng(12);
  const std::vector<double> signal = random_signal(rng);
  std::vector<double> changed = signal;
  std::normal_distribution<double> pattern(0.0, 5 * kSigma);
  for (double& v : changed) v = std::clamp(v + pattern(rng), 0.0, 1.0);
  const encoder::CellKeyframes k = select_noisy(noisy_sequence(signal, changed, 4, rng), 8, true);
  EXPECT_NE(std::find(k.keyframes.begin(), k.keyframes.end(), 4u), k.keyframes.end());
  EXPECT_LE(k.keyframes.size(), 4u);
}

TEST(ColourKeyframesTest, NoiseAwareTestKeepsALocalChange) {
  // A change of 4 sigma rms in one 8 x 8 block of the 16: over the whole cell it adds the noise
  // variance (16 / 16), within what Q allows beyond the noise part; the block's own test keeps it
  // a keyframe.
  std::mt19937 rng(13);
  const std::vector<double> signal = random_signal(rng);
  std::vector<double> changed = signal;
  std::normal_distribution<double> pattern(0.0, 4 * kSigma);
  for (uint32_t y = 8; y < 16; ++y) {
    for (uint32_t i = (y * kSide + 8) * 3; i < (y * kSide + 16) * 3; ++i) {
      changed[i] = std::clamp(changed[i] + pattern(rng), 0.0, 1.0);
    }
  }
  const encoder::CellKeyframes k = select_noisy(noisy_sequence(signal, changed, 4, rng), 8, true);
  EXPECT_NE(std::find(k.keyframes.begin(), k.keyframes.end(), 4u), k.keyframes.end());
}

}  // namespace
}  // namespace calf
