// Tests of the tiles' least-squares colour fit (encoder/src/tiles_texture_solve.cc): samples made
// from known texel values by the renderer's bilinear magnification are reproduced, texels no
// sample reaches are filled harmonically, and radiance stays non-negative.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tiles_internal.h"  // encoder/src: TileNormals, solve_tile_colour

namespace calf::encoder::tiles {
namespace {

// A uniform double in [0, 1) from a counter (splitmix64), so the samples are fixed.
double uniform(uint64_t i) {
  uint64_t z = i * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}

// GL_LINEAR of a single-channel side x side texture at texel position (u, w).
double bilinear(const std::vector<double>& tex, uint32_t side, double u, double w) {
  const uint32_t x0 = std::min<uint32_t>(static_cast<uint32_t>(u), side - 2);
  const uint32_t y0 = std::min<uint32_t>(static_cast<uint32_t>(w), side - 2);
  const double ax = u - x0, ay = w - y0;
  auto at = [&](uint32_t x, uint32_t y) { return tex[size_t{y} * side + x]; };
  return (1 - ax) * (1 - ay) * at(x0, y0) + ax * (1 - ay) * at(x0 + 1, y0) +
         (1 - ax) * ay * at(x0, y0 + 1) + ax * ay * at(x0 + 1, y0 + 1);
}

// The start value the builder hands the solver: the normalised bilinear splat.
std::vector<float> splat(const std::vector<double>& su, const std::vector<double>& sw,
                         const std::vector<double>& value, uint32_t side) {
  std::vector<double> sum(size_t{side} * side, 0.0), weight(size_t{side} * side, 0.0);
  for (size_t s = 0; s < su.size(); ++s) {
    const uint32_t x0 = std::min<uint32_t>(static_cast<uint32_t>(su[s]), side - 2);
    const uint32_t y0 = std::min<uint32_t>(static_cast<uint32_t>(sw[s]), side - 2);
    const double ax = su[s] - x0, ay = sw[s] - y0;
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const double b = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
        const size_t i = size_t{y0 + dy} * side + x0 + dx;
        sum[i] += b * value[s];
        weight[i] += b;
      }
    }
  }
  std::vector<float> rgba(size_t{side} * side * 4, 0.0f);
  for (size_t i = 0; i < sum.size(); ++i) {
    const float v = weight[i] > 0 ? static_cast<float>(sum[i] / weight[i]) : 0.0f;
    for (int c = 0; c < 3; ++c) rgba[4 * i + c] = v;
    rgba[4 * i + 3] = 1.0f;
  }
  return rgba;
}

double fit_rms(const std::vector<float>& rgba, uint32_t side, const std::vector<double>& su,
               const std::vector<double>& sw, const std::vector<double>& value) {
  std::vector<double> channel(size_t{side} * side);
  for (size_t i = 0; i < channel.size(); ++i) channel[i] = rgba[4 * i];
  double sq = 0;
  for (size_t s = 0; s < su.size(); ++s) {
    const double e = bilinear(channel, side, su[s], sw[s]) - value[s];
    sq += e * e;
  }
  return std::sqrt(sq / double(su.size()));
}

TEST(TilesTextureSolve, RecoversTexelsTheSamplesWereMadeFrom) {
  // A checker of 4 x 4 texel blocks (hard edges, as a tiled floor) magnified bilinearly at 3,000
  // scattered positions: the fit must find the checker again; the splat blurs every edge.
  constexpr uint32_t kSide = 16;
  std::vector<double> truth(kSide * kSide);
  for (uint32_t y = 0; y < kSide; ++y) {
    for (uint32_t x = 0; x < kSide; ++x) truth[y * kSide + x] = ((x / 4 + y / 4) % 2) ? 0.9 : 0.1;
  }
  std::vector<double> su, sw, value;
  TileNormals normals;
  normals.reset(kSide, true);
  for (uint64_t s = 0; s < 3000; ++s) {
    su.push_back(uniform(2 * s) * (kSide - 1));
    sw.push_back(uniform(2 * s + 1) * (kSide - 1));
    value.push_back(bilinear(truth, kSide, su.back(), sw.back()));
    const float c[3] = {float(value.back()), float(value.back()), float(value.back())};
    normals.add(su.back(), sw.back(), c);
  }
  std::vector<float> rgba = splat(su, sw, value, kSide);
  double splat_max = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    splat_max = std::max(splat_max, std::abs(rgba[4 * i] - truth[i]));
  }
  const double splat_rms = fit_rms(rgba, kSide, su, sw, value);
  solve_tile_colour(normals, 1e-4, 200, rgba.data());
  double solved_max = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    solved_max = std::max(solved_max, std::abs(rgba[4 * i] - truth[i]));
    EXPECT_EQ(rgba[4 * i], rgba[4 * i + 1]);  // the channels are solved alike
    EXPECT_EQ(rgba[4 * i + 3], 1.0f);         // alpha is not touched
  }
  const double solved_rms = fit_rms(rgba, kSide, su, sw, value);
  EXPECT_GT(splat_max, 0.15);
  EXPECT_LT(solved_max, 0.02);
  EXPECT_LT(solved_rms, splat_rms / 10);
}

TEST(TilesTextureSolve, WeightedSamplesSolveTheWeightedLeastSquares) {
  // Two textures sampled at the same 2,000 positions, one set at weight 1 and the other at 0.25
  // (a tile's own samples and its secondary ones): minimising sum w (Bx - y)^2 over both gives
  // x = (1 * a + 0.25 * b) / 1.25 texel for texel, because both sets are exact bilinear
  // magnifications. A weight applied twice in the normal matrix (w^2 b_i b_j) would give
  // (a + 0.0625 b) / 1.0625 instead: 0.02 away at these values.
  constexpr uint32_t kSide = 8;
  constexpr double kWeight = 0.25;
  std::vector<double> a(kSide * kSide), b(kSide * kSide);
  for (uint32_t i = 0; i < kSide * kSide; ++i) {
    a[i] = 0.2 + 0.6 * uniform(100000 + i);
    b[i] = 0.2 + 0.6 * uniform(200000 + i);
  }
  TileNormals normals;
  normals.reset(kSide, true);
  std::vector<double> su, sw, value;
  for (uint64_t s = 0; s < 2000; ++s) {
    const double u = uniform(2 * s) * (kSide - 1), w = uniform(2 * s + 1) * (kSide - 1);
    const float ca = float(bilinear(a, kSide, u, w)), cb = float(bilinear(b, kSide, u, w));
    const float colour_a[3] = {ca, ca, ca}, colour_b[3] = {cb, cb, cb};
    normals.add(u, w, colour_a);
    normals.add(u, w, colour_b, kWeight);
    su.push_back(u);
    sw.push_back(w);
    value.push_back((ca + kWeight * cb) / (1 + kWeight));
  }
  std::vector<float> rgba = splat(su, sw, value, kSide);
  solve_tile_colour(normals, 1e-6, 400, rgba.data());
  double worst = 0, worst_squared_weight = 0;
  for (uint32_t i = 0; i < kSide * kSide; ++i) {
    worst = std::max(worst, std::abs(rgba[4 * i] - (a[i] + kWeight * b[i]) / (1 + kWeight)));
    const double squared = (a[i] + kWeight * kWeight * b[i]) / (1 + kWeight * kWeight);
    worst_squared_weight = std::max(worst_squared_weight, std::abs(rgba[4 * i] - squared));
  }
  EXPECT_LT(worst, 2e-3);
  EXPECT_GT(worst_squared_weight, 1e-2);
  // One sample at weight 0.25: weight x b on the right-hand side, weight x b x b on the diagonal.
  TileNormals one;
  one.reset(kSide, true);
  const float grey[3] = {0.5f, 0.5f, 0.5f};
  one.add(2.25, 3.5, grey, kWeight);
  EXPECT_FLOAT_EQ(one.sums[4 * (3 * kSide + 2) + 3], float(kWeight * 0.75 * 0.5));
  EXPECT_FLOAT_EQ(one.coupling[5 * (3 * kSide + 2) + TileNormals::kDiag],
                  float(kWeight * 0.75 * 0.5 * 0.75 * 0.5));
}

TEST(TilesTextureSolve, FillsUnsampledTexelsHarmonically) {
  // Samples only on the left (0.2) and right (0.8) edges: the membrane between them is the
  // linear ramp, whatever the start.
  constexpr uint32_t kSide = 12;
  TileNormals normals;
  normals.reset(kSide, true);
  for (uint32_t y = 0; y < kSide; ++y) {
    const float left[3] = {0.2f, 0.2f, 0.2f}, right[3] = {0.8f, 0.8f, 0.8f};
    normals.add(0.0, y, left);
    normals.add(kSide - 1.0, y, right);
  }
  std::vector<float> rgba(kSide * kSide * 4, 0.0f);
  solve_tile_colour(normals, 0.2, 300, rgba.data());
  for (uint32_t y = 0; y < kSide; ++y) {
    for (uint32_t x = 0; x < kSide; ++x) {
      const double want = 0.2 + 0.6 * x / (kSide - 1.0);
      // The membrane pulls the sampled edge texels inwards a little: lambda 0.2 of a sample's
      // weight against one sample per edge texel.
      EXPECT_NEAR(rgba[4 * (y * kSide + x)], want, 0.03) << x << "," << y;
    }
  }
}

TEST(TilesTextureSolve, OvershootIsClampedAndZeroIterationsKeepTheStart) {
  // A step from 0 to 1 between two texel centres: inverting the magnification rings below 0.
  constexpr uint32_t kSide = 8;
  TileNormals normals;
  normals.reset(kSide, true);
  for (uint64_t s = 0; s < 800; ++s) {
    const double u = uniform(2 * s) * (kSide - 1), w = uniform(2 * s + 1) * (kSide - 1);
    const float v = u < 3.5 ? 0.0f : 1.0f;
    const float c[3] = {v, v, v};
    normals.add(u, w, c);
  }
  std::vector<float> start(kSide * kSide * 4, 0.5f);
  std::vector<float> rgba = start;
  solve_tile_colour(normals, 0.2, 0, rgba.data());
  EXPECT_EQ(rgba, start);
  solve_tile_colour(normals, 1e-4, 100, rgba.data());
  float lo = 1, hi = 0;
  for (size_t i = 0; i < rgba.size(); i += 4) {
    lo = std::min(lo, rgba[i]);
    hi = std::max(hi, rgba[i]);
  }
  EXPECT_EQ(lo, 0.0f);  // clamped: the unclamped fit goes below 0 next to the step
  EXPECT_GT(hi, 1.0f);  // and above 1 on the other side (not clamped: radiance may exceed 1)
}

}  // namespace
}  // namespace calf::encoder::tiles
