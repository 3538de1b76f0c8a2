// Tests of depth change masks and change-box fitting (encoder/include/calf/encoder/depth_aabb.h).
#include "calf/encoder/depth_aabb.h"

#include <gtest/gtest.h>

#include <random>

namespace calf {
namespace {

encoder::ChangeMask make_mask(uint32_t w, uint32_t h) {
  return encoder::ChangeMask{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h, 0)};
}
void set_rect(encoder::ChangeMask& m, uint32_t x, uint32_t y, uint32_t w, uint32_t h) {
  for (uint32_t j = y; j < y + h; ++j)
    for (uint32_t i = x; i < x + w; ++i) m.bits[j * m.width + i] = 1;
}

std::vector<PixelRect> fit(const encoder::ChangeMask& m, uint32_t max_boxes,
                           uint32_t alignment = 1) {
  auto r = encoder::fit_change_boxes(m, {max_boxes, alignment});
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  return *r;
}

// Every set texel covered, boxes inside the tile, pairwise disjoint, at most max_boxes.
void expect_valid_cover(const encoder::ChangeMask& m, const std::vector<PixelRect>& boxes,
                        uint32_t max_boxes) {
  ASSERT_LE(boxes.size(), max_boxes);
  std::vector<int> owner(m.bits.size(), -1);
  for (size_t b = 0; b < boxes.size(); ++b) {
    const PixelRect& r = boxes[b];
    ASSERT_GT(r.width * r.height, 0u);
    ASSERT_LE(r.x + r.width, m.width);
    ASSERT_LE(r.y + r.height, m.height);
    for (uint32_t y = r.y; y < r.y + r.height; ++y)
      for (uint32_t x = r.x; x < r.x + r.width; ++x) {
        ASSERT_EQ(owner[y * m.width + x], -1) << "boxes overlap";
        owner[y * m.width + x] = static_cast<int>(b);
      }
  }
  for (size_t i = 0; i < m.bits.size(); ++i) {
    if (m.bits[i]) {
      ASSERT_NE(owner[i], -1) << "set texel " << i << " not covered";
    }
  }
}

TEST(DepthAabbTest, EmptyMaskNeedsNoBox) {
  EXPECT_TRUE(fit(make_mask(16, 16), 2).empty());
}

TEST(DepthAabbTest, OneBlobGivesItsTightBox) {
  encoder::ChangeMask m = make_mask(32, 16);
  set_rect(m, 5, 3, 7, 4);
  EXPECT_EQ(fit(m, 4), (std::vector<PixelRect>{{5, 3, 7, 4}}));
}

TEST(DepthAabbTest, TwoBlobsGiveTwoTightBoxesInOrder) {
  encoder::ChangeMask m = make_mask(64, 64);
  set_rect(m, 40, 2, 10, 5);  // top right
  set_rect(m, 3, 30, 6, 20);  // bottom left
  EXPECT_EQ(fit(m, 2), (std::vector<PixelRect>{{40, 2, 10, 5}, {3, 30, 6, 20}}));
  // With A = 1 the single box encloses both.
  EXPECT_EQ(fit(m, 1), (std::vector<PixelRect>{{3, 2, 47, 48}}));
}

TEST(DepthAabbTest, MoreBoxesNeverCoverMoreTexels) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    encoder::ChangeMask m = make_mask(40, 30);
    for (int blob = 0; blob < 5; ++blob)
      set_rect(m, rng() % 35, rng() % 25, 1 + rng() % 5, 1 + rng() % 5);
    uint64_t previous = UINT64_MAX;
    for (uint32_t a = 1; a <= 8; ++a) {
      const auto boxes = fit(m, a);
      expect_valid_cover(m, boxes, a);
      const uint64_t area = encoder::covered_texels(boxes);
      EXPECT_LE(area, previous);
      previous = area;
    }
  }
}

// Naive reference: for A = 2 the greedy search is exhaustive over single guillotine cuts, so its
// area must equal the best cut found by brute force with naive tightening.
TEST(DepthAabbTest, TwoBoxesMatchBruteForceBestCut) {
  const auto tight_area = [](const encoder::ChangeMask& m, uint32_t x0, uint32_t y0, uint32_t x1,
                             uint32_t y1) -> uint64_t {
    uint32_t a = UINT32_MAX, b = UINT32_MAX, c = 0, d = 0;
    for (uint32_t y = y0; y < y1; ++y)
      for (uint32_t x = x0; x < x1; ++x)
        if (m.at(x, y)) {
          a = std::min(a, x);
          b = std::min(b, y);
          c = std::max(c, x + 1);
          d = std::max(d, y + 1);
        }
    return a == UINT32_MAX ? 0 : static_cast<uint64_t>(c - a) * (d - b);
  };
  std::mt19937 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    encoder::ChangeMask m = make_mask(12, 10);
    for (auto& bit : m.bits) bit = (rng() % 9) == 0;
    uint64_t best = tight_area(m, 0, 0, 12, 10);
    for (uint32_t s = 1; s < 12; ++s)
      best = std::min(best, tight_area(m, 0, 0, s, 10) + tight_area(m, s, 0, 12, 10));
    for (uint32_t s = 1; s < 10; ++s)
      best = std::min(best, tight_area(m, 0, 0, 12, s) + tight_area(m, 0, s, 12, 10));
    const auto boxes = fit(m, 2);
    expect_valid_cover(m, boxes, 2);
    EXPECT_EQ(encoder::covered_texels(boxes), best) << "trial " << trial;
  }
}

TEST(DepthAabbTest, AlignedBoxesSnapToBlocksAndClipToTheTile) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    encoder::ChangeMask m = make_mask(30, 22);  // not a multiple of 4: edge boxes are clipped
    for (int blob = 0; blob < 4; ++blob)
      set_rect(m, rng() % 28, rng() % 20, 1 + rng() % 3, 1 + rng() % 3);
    const auto boxes = fit(m, 3, 4);
    expect_valid_cover(m, boxes, 3);
    for (const auto& b : boxes) {
      EXPECT_EQ(b.x % 4, 0u);
      EXPECT_EQ(b.y % 4, 0u);
      EXPECT_TRUE((b.x + b.width) % 4 == 0 || b.x + b.width == 30);
      EXPECT_TRUE((b.y + b.height) % 4 == 0 || b.y + b.height == 22);
    }
  }
}

TEST(DepthAabbTest, ChangeMaskUsesTheWholeWindow) {
  // Texel 0 changes between frames 0 and 1 and goes back at frame 2; texel 1 changes at frame 2.
  const std::vector<uint16_t> f0 = {10, 20, 30, 40}, f1 = {11, 20, 30, 40}, f2 = {10, 25, 30, 40};
  const std::vector<std::span<const uint16_t>> frames = {f0, f1, f2};
  auto w1 = encoder::depth_change_mask(frames, 2, 2, 2, 1);
  ASSERT_TRUE(w1.ok());
  EXPECT_EQ(w1->bits, (std::vector<uint8_t>{1, 1, 0, 0}));  // differs from frame 1 at texel 0
  auto w2 = encoder::depth_change_mask(frames, 2, 2, 2, 2);
  EXPECT_EQ(w2->bits, (std::vector<uint8_t>{1, 1, 0, 0}));
  // A texel equal to frame i-1 but not to frame i-2 is still marked with W = 2.
  const std::vector<uint16_t> g0 = {1, 1}, g1 = {2, 1}, g2 = {2, 1};
  const std::vector<std::span<const uint16_t>> g = {g0, g1, g2};
  EXPECT_EQ(encoder::depth_change_mask(g, 2, 1, 2, 1)->bits, (std::vector<uint8_t>{0, 0}));
  EXPECT_EQ(encoder::depth_change_mask(g, 2, 1, 2, 2)->bits, (std::vector<uint8_t>{1, 0}));
  // Epsilon tolerates small code differences.
  EXPECT_EQ(encoder::depth_change_mask(frames, 2, 2, 1, 1, 1)->bits,
            (std::vector<uint8_t>{0, 0, 0, 0}));
}

TEST(DepthAabbTest, BadArgumentsAreErrors) {
  const std::vector<uint16_t> f0(4), f1(3);
  const std::vector<std::span<const uint16_t>> frames = {f0, f1};
  EXPECT_EQ(encoder::depth_change_mask(frames, 2, 2, 1, 1).status().id(),
            ErrorId::kInvalidArgument);
  EXPECT_FALSE(encoder::depth_change_mask(frames, 2, 2, 0, 1).ok());
  EXPECT_FALSE(encoder::depth_change_mask(frames, 2, 2, 2, 1).ok());
  EXPECT_FALSE(encoder::fit_change_boxes(make_mask(4, 4), {0, 1}).ok());
  EXPECT_FALSE(encoder::fit_change_boxes(make_mask(4, 4), {2, 0}).ok());
}

}  // namespace
}  // namespace calf
