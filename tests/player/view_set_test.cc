// View textures: creation, rect writes shaped like the decoder's texture updates, and their
// validation.
#include "calf/player/view_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace calf::player {
namespace {

View make(uint32_t n, bool material) {
  const Expected<View> v = View::make({1, 2, 3}, *LogDepthRange::make(0.5f, 20.0f), n, material);
  EXPECT_TRUE(v.ok()) << v.status().to_string();
  return *v;
}

TEST(ViewSet, StartsAsSky) {
  const View v = make(8, true);
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint16_t c : v.depth_face(face)) ASSERT_EQ(c, kLog16Sky);
    for (float c : v.colour_face(face)) ASSERT_EQ(c, 0.0f);
    const Material m = v.material_at(face, 7, 7);
    EXPECT_EQ(m.reflect, 0.0f);
    EXPECT_EQ(m.refract, 0.0f);
    EXPECT_EQ(m.ior, 1.0f);
  }
  EXPECT_FALSE(make(4, false).has_material());
  EXPECT_EQ(make(4, false).material_at(CubeFace::kPosY, 0, 0).ior, 1.0f);
}

TEST(ViewSet, RectWritesLandWhereTheySay) {
  View v = make(8, true);
  // A 3 x 2 rect at (4, 5) from a source with a padded stride of 5 codes.
  const std::vector<uint16_t> src = {1, 2, 3, 99, 99, 4, 5, 6};
  ASSERT_TRUE(v.write_depth_rect(CubeFace::kNegY, {4, 5, 3, 2}, src, 5).ok());
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 4, 5), 1);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 6, 5), 3);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 4, 6), 4);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 6, 6), 6);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 7, 6), kLog16Sky);
  EXPECT_EQ(v.depth_code_at(CubeFace::kPosY, 4, 5), kLog16Sky);
  const std::vector<float> rgb = {0.1f, 0.2f, 3.5f};  // HDR kept
  ASSERT_TRUE(v.write_colour_rect(CubeFace::kPosZ, {7, 0, 1, 1}, rgb).ok());
  EXPECT_EQ(v.colour_at(CubeFace::kPosZ, 7, 0)[2], 3.5f);
  const std::vector<float> mat = {0.25f, 0.5f, 1.5f};
  ASSERT_TRUE(v.write_material_rect(CubeFace::kNegX, {0, 7, 1, 1}, mat).ok());
  EXPECT_EQ(v.material_at(CubeFace::kNegX, 0, 7).ior, 1.5f);
}

TEST(ViewSet, RejectsBadViewsAndRects) {
  const LogDepthRange range = *LogDepthRange::make(1, 2);
  EXPECT_EQ(View::make({}, range, 0, false).status().id(), ErrorId::kPlayerViewSet);
  EXPECT_EQ(View::make({}, range, kMaxFaceSize + 1, false).status().id(), ErrorId::kPlayerViewSet);
  EXPECT_EQ(View::make({std::nan(""), 0, 0}, range, 4, false).status().id(),
            ErrorId::kPlayerViewSet);
  View v = make(8, false);
  const std::vector<uint16_t> codes(64, 7);
  const std::vector<float> rgb(3 * 64, 1);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {7, 0, 2, 1}, codes).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 0, 1}, codes).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0xFFFFFFFFu, 1, 2}, codes).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 4, 2}, codes, 3).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 8, 8}, std::span(codes).first(63)).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_colour_rect(static_cast<CubeFace>(6), {0, 0, 1, 1}, rgb).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_material_rect(CubeFace::kPosX, {0, 0, 1, 1}, rgb).id(),
            ErrorId::kPlayerNoMaterial);
  // Nothing was written by the failed calls.
  for (uint16_t c : v.depth_face(CubeFace::kPosX)) ASSERT_EQ(c, kLog16Sky);
}

// Unmixed colour (unmix_coverage_colour) on a synthetic vertical edge of +Z with known colours:
// columns 0..3 a near surface at depth 1 in colour A, columns 4..7 a far one at depth 4 in colour
// B. The edge crosses rows 0..3 at x = 3.75 and rows 4..7 at x = 4.25: there column 3's texels
// are a quarter far (their last cell column), here column 4's a quarter near (their first), each
// holding the anti-aliased mix of both colours; after unmixing each holds its own surface's
// colour. Row 0 of column 3 is only 1/16 its own surface: it takes A from its
// neighbour. A texel of sky beside a surface unmixes the same way.
TEST(ViewSet, UnmixingRecoversTheOwnColourOfEdgeTexels) {
  constexpr uint32_t n = 8;
  View v = make(n, false);
  const float a[3] = {0.8f, 0.6f, 0.2f}, b[3] = {0.1f, 0.2f, 0.9f};
  const LogDepthRange& range = v.range();
  std::vector<uint16_t> depth(n * n);
  std::vector<float> colour(3 * n * n), cov(3 * n * n);
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const size_t k = y * n + x;
      const bool near = x < 4;
      depth[k] = range.encode_unchecked(near ? 1.0f : 4.0f);
      float own = 1, near_share = 0, far_share = 0;
      uint32_t mask = 0xFFFF;
      if (x == 3 && y < 4) {
        far_share = 0.25f;
        mask = 0x7777;  // cells i = 0..2 of every row
        if (y == 0) far_share = 15 / 16.0f, mask = 0x0001;
      } else if (x == 4 && y >= 4) {
        near_share = 0.25f;
        mask = 0xEEEE;  // cells i = 1..3
      }
      own = 1 - near_share - far_share;
      for (int c = 0; c < 3; ++c) {
        const float mine = near ? a[c] : b[c], other = near ? b[c] : a[c];
        colour[3 * k + c] = own * mine + (1 - own) * other;
      }
      cov[3 * k] = near_share;
      cov[3 * k + 1] = far_share;
      cov[3 * k + 2] = static_cast<float>(mask);
    }
  }
  ASSERT_TRUE(v.write_depth_rect(CubeFace::kPosZ, {0, 0, n, n}, depth).ok());
  ASSERT_TRUE(v.write_colour_rect(CubeFace::kPosZ, {0, 0, n, n}, colour).ok());
  ASSERT_TRUE(v.write_coverage_rect(CubeFace::kPosZ, {0, 0, n, n}, cov).ok());
  // On -Z (all sky, colour B) texel (2, 2) is sky a quarter covered by a near surface in colour
  // A, texel (1, 2) beside it that surface (depth 2).
  std::vector<uint16_t> sky_depth(n * n, kLog16Sky);
  std::vector<float> sky_colour(3 * n * n), sky_cov(3 * n * n);
  for (size_t k = 0; k < n * n; ++k) {
    std::copy(b, b + 3, &sky_colour[3 * k]);
    sky_cov[3 * k + 2] = 65535;
  }
  const size_t s = 2 * n + 2, t = 2 * n + 1;
  sky_depth[t] = range.encode_unchecked(2.0f);
  std::copy(a, a + 3, &sky_colour[3 * t]);
  for (int c = 0; c < 3; ++c) sky_colour[3 * s + c] = 0.75f * b[c] + 0.25f * a[c];
  sky_cov[3 * s] = 0.25f;
  sky_cov[3 * s + 2] = 0xEEEE;
  ASSERT_TRUE(v.write_depth_rect(CubeFace::kNegZ, {0, 0, n, n}, sky_depth).ok());
  ASSERT_TRUE(v.write_colour_rect(CubeFace::kNegZ, {0, 0, n, n}, sky_colour).ok());
  ASSERT_TRUE(v.write_coverage_rect(CubeFace::kNegZ, {0, 0, n, n}, sky_cov).ok());

  capture::CoverageUnmixOptions options;
  options.min_share = 0.25;
  options.min_jump = 0.1;
  const Expected<uint64_t> changed = unmix_coverage_colour(&v, options);
  ASSERT_TRUE(changed.ok()) << changed.status().message();
  EXPECT_EQ(*changed, 9u);  // four texels on each side of the +Z edge, one on -Z
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const float* want = x < 4 ? a : b;
      const float* got = v.colour_at(CubeFace::kPosZ, x, y);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(got[c], want[c], 1e-5) << "texel (" << x << ", " << y << ") channel " << c;
      }
    }
  }
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(v.colour_at(CubeFace::kNegZ, 2, 2)[c], b[c], 1e-5);
    EXPECT_NEAR(v.colour_at(CubeFace::kNegZ, 1, 2)[c], a[c], 1e-5);
  }
}

// A view without coverage is left as it is.
TEST(ViewSet, UnmixingLeavesViewsWithoutCoverageAlone) {
  View v = make(4, false);
  std::vector<float> colour(3 * 16);
  for (size_t k = 0; k < colour.size(); ++k) colour[k] = 0.01f * k;
  ASSERT_TRUE(v.write_colour_rect(CubeFace::kPosX, {0, 0, 4, 4}, colour).ok());
  capture::CoverageUnmixOptions options;
  options.min_share = 0;
  const Expected<uint64_t> changed = unmix_coverage_colour(&v, options);
  ASSERT_TRUE(changed.ok());
  EXPECT_EQ(*changed, 0u);
  const std::span<const float> got = v.colour_face(CubeFace::kPosX);
  EXPECT_TRUE(std::equal(got.begin(), got.end(), colour.begin()));
}

// An option outside its range is an error, and the view keeps its colour.
TEST(ViewSet, UnmixingRefusesOptionsOutOfRange) {
  View v = make(4, false);
  v.add_coverage();
  std::vector<float> colour(3 * 16, 0.5f), cov(3 * 16);
  for (size_t k = 0; k < 16; ++k) cov[3 * k + 2] = 0x00FF;
  cov[0] = 0.5f;
  ASSERT_TRUE(v.write_colour_rect(CubeFace::kPosX, {0, 0, 4, 4}, colour).ok());
  ASSERT_TRUE(v.write_coverage_rect(CubeFace::kPosX, {0, 0, 4, 4}, cov).ok());
  capture::CoverageUnmixOptions share;
  share.min_share = 1.5;
  EXPECT_EQ(unmix_coverage_colour(&v, share).status().id(), ErrorId::kCoverageUnmixInput);
  capture::CoverageUnmixOptions jump;
  jump.min_jump = -1;
  EXPECT_EQ(unmix_coverage_colour(&v, jump).status().id(), ErrorId::kCoverageUnmixInput);
  const std::span<const float> got = v.colour_face(CubeFace::kPosX);
  EXPECT_TRUE(std::equal(got.begin(), got.end(), colour.begin()));
}

}  // namespace
}  // namespace calf::player
