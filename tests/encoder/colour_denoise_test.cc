// Tests of the temporal pre-filter of render noise (encoder/include/calf/encoder/colour_denoise.h).
#include "calf/encoder/colour_denoise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/format/bc.h"
#include "calf/format/colour.h"

namespace calf {
namespace {

constexpr uint32_t kFace = 32;
constexpr size_t kFaceTexels = size_t{kFace} * kFace;
constexpr size_t kFrameTexels = 6 * kFaceTexels;
constexpr double kSigma = 0.01;  // noise standard deviation in sRGB values

// One view: colour as half RGB, depth codes, no material.
struct View {
  uint32_t frames = 0;
  std::vector<uint16_t> colour;
  std::vector<uint16_t> depth;

  explicit View(uint32_t f)
      : frames(f), colour(kFrameTexels * 3 * f), depth(kFrameTexels * f, 1000) {}
  size_t texel(uint32_t f, uint32_t face, uint32_t x, uint32_t y) const {
    return f * kFrameTexels + face * kFaceTexels + size_t{y} * kFace + x;
  }
  // Sets every channel of a texel to the sRGB value s.
  void set_srgb(size_t t, double s) {
    const uint16_t h = bc::float_to_half(linear_from_srgb(static_cast<float>(s)));
    for (int c = 0; c < 3; ++c) colour[3 * t + c] = h;
  }
  double srgb(size_t t, int c = 0) const {
    return srgb_from_linear(bc::half_to_float(colour[3 * t + c]));
  }
};

// A grey of sRGB `level` with Gaussian noise of kSigma, a new draw every frame and channel.
View noisy_static(uint32_t frames, double level, uint32_t seed) {
  View v(frames);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kSigma);
  for (size_t t = 0; t < kFrameTexels * frames; ++t) {
    for (int c = 0; c < 3; ++c) {
      v.colour[3 * t + c] =
          bc::float_to_half(linear_from_srgb(static_cast<float>(level + noise(rng))));
    }
  }
  return v;
}

Expected<encoder::StaticDenoiseStats> filter(View& v, uint32_t window, uint32_t threads = 1,
                                             uint32_t segment_frames = 0) {
  encoder::StaticDenoiseOptions o;
  o.window = window;
  o.threads = threads;
  o.segment_frames = segment_frames;
  return encoder::denoise_static_colour(v.colour, v.depth, {}, v.frames, kFace, o);
}

// The variance about `level` (sRGB) of every value of every frame.
double variance_about(const View& v, double level) {
  double sum = 0;
  for (size_t i = 0; i < v.colour.size(); ++i) {
    const double d = srgb_from_linear(bc::half_to_float(v.colour[i])) - level;
    sum += d * d;
  }
  return sum / static_cast<double>(v.colour.size());
}

// Gaussian noise on static geometry: the mean of W frames has 1/W of the variance.
TEST(ColourDenoiseTest, StaticNoiseVarianceFallsAsOneOverTheWindow) {
  for (const uint32_t w : {2u, 4u, 8u}) {
    View v = noisy_static(8, 0.5, 7);
    const double before = variance_about(v, 0.5);
    EXPECT_NEAR(before, kSigma * kSigma, 0.05 * kSigma * kSigma);
    auto s = filter(v, w);
    ASSERT_TRUE(s.ok()) << s.status().to_string();
    // 1/W, a little more where a noise outlier fails the guards and ends the window early.
    const double ratio = variance_about(v, 0.5) / before;
    EXPECT_GT(ratio * w, 0.9) << "window " << w;
    EXPECT_LT(ratio * w, 1.3) << "window " << w;
    // Nearly every texel-frame was averaged (the guards reject a few noise outliers).
    EXPECT_GT(s->averaged, s->texels * 95 / 100) << "window " << w;
  }
}

// A real change (a patch 6 sigma brighter from frame 4 on, on the same geometry) is not averaged
// across: frames before it keep their level, frames after it theirs; both sides are denoised.
TEST(ColourDenoiseTest, RealChangeIsNotSmeared) {
  View v = noisy_static(8, 0.4, 11);
  std::mt19937 rng(12);
  std::normal_distribution<double> noise(0.0, kSigma);
  const double bright = 0.4 + 6 * kSigma;
  for (uint32_t f = 4; f < 8; ++f) {
    for (uint32_t y = 8; y < 24; ++y) {
      for (uint32_t x = 8; x < 24; ++x) v.set_srgb(v.texel(f, 2, x, y), bright + noise(rng));
    }
  }
  ASSERT_TRUE(filter(v, 8).ok());
  for (uint32_t f = 0; f < 8; ++f) {
    double sum = 0, sq = 0;
    uint32_t count = 0;
    for (uint32_t y = 10; y < 22; ++y) {  // the patch's inside, away from its edge
      for (uint32_t x = 10; x < 22; ++x) {
        const double s = v.srgb(v.texel(f, 2, x, y));
        sum += s;
        sq += s * s;
        ++count;
      }
    }
    const double mean = sum / count, var = sq / count - mean * mean;
    EXPECT_NEAR(mean, f < 4 ? 0.4 : bright, 0.2 * kSigma) << "frame " << f;
    EXPECT_LT(var, 0.4 * kSigma * kSigma) << "frame " << f << ": not denoised on its own side";
  }
}

// A lighting change of 4 sigma over a whole face from frame to frame (signal, below what one
// texel's difference tells from noise) is caught by the neighbourhood test: no frame is pulled
// towards another's level.
TEST(ColourDenoiseTest, ShadingChangeIsNotAveraged) {
  View v(6);
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, kSigma);
  for (uint32_t f = 0; f < 6; ++f) {
    for (size_t t = 0; t < kFrameTexels; ++t) v.set_srgb(f * kFrameTexels + t, 0.3 + noise(rng));
    for (size_t t = 0; t < kFaceTexels; ++t) {  // face 1 brightens 4 sigma a frame
      v.set_srgb(v.texel(f, 1, 0, 0) + t, 0.3 + 4 * kSigma * f + noise(rng));
    }
  }
  ASSERT_TRUE(filter(v, 6).ok());
  for (uint32_t f = 0; f < 6; ++f) {
    double sum = 0;
    for (size_t t = 0; t < kFaceTexels; ++t) sum += v.srgb(v.texel(f, 1, 0, 0) + t);
    EXPECT_NEAR(sum / kFaceTexels, 0.3 + 4 * kSigma * f, 0.1 * kSigma) << "frame " << f;
  }
}

// A moving object of the same colour statistics as the background (only its depth tells it
// apart): a texel whose geometry changes from both neighbouring frames keeps its own value bit
// for bit; the static background around it is denoised.
TEST(ColourDenoiseTest, MovingEdgeKeepsItsOwnFrame) {
  View v = noisy_static(6, 0.5, 3);
  // A 6-texel-wide bar on face 0 moving 3 texels a frame.
  auto in_bar = [](uint32_t f, uint32_t x) { return x >= 4 + 3 * f && x < 10 + 3 * f; };
  for (uint32_t f = 0; f < 6; ++f) {
    for (uint32_t y = 0; y < kFace; ++y) {
      for (uint32_t x = 0; x < kFace; ++x) {
        if (in_bar(f, x)) v.depth[v.texel(f, 0, x, y)] = 500;
      }
    }
  }
  const View before = v;
  ASSERT_TRUE(filter(v, 6).ok());
  auto geometry_changes = [&](uint32_t f, uint32_t g, uint32_t x) {
    for (const int dx : {-1, 0, 1}) {
      const int xx = static_cast<int>(x) + dx;
      if (xx < 0 || xx >= static_cast<int>(kFace)) continue;
      if (in_bar(f, static_cast<uint32_t>(xx)) != in_bar(g, static_cast<uint32_t>(xx))) return true;
    }
    return false;
  };
  uint64_t kept = 0;
  for (uint32_t f = 0; f < 6; ++f) {
    for (uint32_t x = 0; x < kFace; ++x) {
      const bool from_previous = f == 0 || geometry_changes(f, f - 1, x);
      const bool from_next = f == 5 || geometry_changes(f, f + 1, x);
      if (!from_previous || !from_next) continue;
      for (uint32_t y = 0; y < kFace; ++y) {
        const size_t t = v.texel(f, 0, x, y);
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(v.colour[3 * t + c], before.colour[3 * t + c])
              << "frame " << f << " texel (" << x << ", " << y << ")";
        }
        ++kept;
      }
    }
  }
  EXPECT_GT(kept, 6u * 6 * kFace);  // the bar's texels and its edges, every frame
  // Face 1 (no motion) is denoised.
  double sum = 0;
  for (uint32_t f = 0; f < 6; ++f) {
    for (size_t t = 0; t < kFaceTexels; ++t) {
      const double d = v.srgb(v.texel(f, 1, 0, 0) + t) - 0.5;
      sum += d * d;
    }
  }
  EXPECT_LT(sum / (6 * kFaceTexels), 0.25 * kSigma * kSigma);
}

// Converged content (colour that changes only where the geometry moves, and noise that is the
// same every frame) is left bit for bit: no block has measured noise.
TEST(ColourDenoiseTest, ConvergedInputUntouched) {
  View v = noisy_static(1, 0.5, 9);  // one frame of "fixed-seed noise"
  View c(6);
  for (uint32_t f = 0; f < 6; ++f) {
    std::copy(v.colour.begin(), v.colour.end(), c.colour.begin() + f * kFrameTexels * 3);
    for (uint32_t y = 4; y < 12; ++y) {  // a moving object, another colour and depth
      for (uint32_t x = 2 * f; x < 2 * f + 8; ++x) {
        c.depth[c.texel(f, 3, x, y)] = 200;
        c.set_srgb(c.texel(f, 3, x, y), 0.9);
      }
    }
  }
  const std::vector<uint16_t> before = c.colour;
  auto s = filter(c, 8);
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(s->averaged, 0u);
  EXPECT_TRUE(c.colour == before);
}

// The result never depends on the thread count; with closed segments a segment filters as the
// same frames alone do (what frame-range shards rely on).
TEST(ColourDenoiseTest, ThreadsAndSegments) {
  const View noisy = noisy_static(8, 0.6, 21);
  View one = noisy, two = noisy, seg = noisy;
  ASSERT_TRUE(filter(one, 4, 1).ok());
  ASSERT_TRUE(filter(two, 4, 2).ok());
  EXPECT_TRUE(one.colour == two.colour);
  ASSERT_TRUE(filter(seg, 4, 2, 4).ok());
  EXPECT_FALSE(seg.colour == one.colour);  // windows no longer cross frame 4
  View second(4);
  std::copy(noisy.colour.begin() + 4 * kFrameTexels * 3, noisy.colour.end(), second.colour.begin());
  ASSERT_TRUE(filter(second, 4, 1).ok());
  EXPECT_TRUE(std::equal(second.colour.begin(), second.colour.end(),
                         seg.colour.begin() + 4 * kFrameTexels * 3));
}

TEST(ColourDenoiseTest, WindowOneAndBadSizes) {
  View v = noisy_static(4, 0.5, 1);
  const std::vector<uint16_t> before = v.colour;
  ASSERT_TRUE(filter(v, 1).ok());
  EXPECT_TRUE(v.colour == before);
  auto bad_window = filter(v, encoder::kMaxDenoiseWindow + 1);
  ASSERT_FALSE(bad_window.ok());
  EXPECT_EQ(bad_window.status().id(), ErrorId::kInvalidArgument);
  encoder::StaticDenoiseOptions o;
  auto bad = encoder::denoise_static_colour(v.colour, std::span<const uint16_t>(v.depth).first(10),
                                            {}, v.frames, kFace, o);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().id(), ErrorId::kInvalidArgument);
}

// --colour-rdo auto's BC6H lambda is kDenoisedBc6hRdo only for a capture measured noisy with the
// pre-filter on: converged content (no noise level) and the other formats keep their defaults.
TEST(ColourDenoiseTest, RdoStrengthFollowsThePreFilter) {
  encoder::LightfieldEncodeOptions o;
  o.denoise_window = 16;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc6h), 0.5);  // no noise level
  o.noise_psnr_db = 45.7;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc6h), encoder::kDenoisedBc6hRdo);
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc7), 0.5);
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc1), 12.0);
  o.denoise_window = 0;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc6h), 0.5);
  o.denoise_window = 16;
  o.colour_rdo = 0.25;
  EXPECT_EQ(encoder::colour_rdo_lambda(o, encoder::ColourCoding::kBc6h), 0.25);
}

}  // namespace
}  // namespace calf
