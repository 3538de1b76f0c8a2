// The lightfield coverage stream's chunk layout (format/SPEC.md §11.1.11,
// calf/format/lightfield_layout.h): the worked example byte for byte, every rule a parser checks,
// and the GPU bytes a decoder gets.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/lightfield_layout.h"

namespace calf::lf {
namespace {

// A one-frame chunk of a w x h tile: the head (F = 1, R_0 = 1, the whole tile), then `payload`.
std::vector<uint8_t> one_frame_chunk(uint16_t w, uint16_t h, const std::vector<uint8_t>& payload) {
  RegionHead head;
  head.rect_counts = {1};
  head.rects.push_back({0, 0, w, h});
  std::vector<uint8_t> raw;
  EXPECT_TRUE(container::write_fields(head, raw, "head").ok());
  raw.insert(raw.end(), payload.begin(), payload.end());
  return raw;
}

// SPEC §11.1.11's worked example: a 4 x 2 tile, texel (1, 0) mask 0x0033 near 12, texel (3, 1)
// mask 0xfff0 near 0, the others plain.
std::vector<CoverageTexel> example_texels() {
  std::vector<CoverageTexel> t(8);
  t[1] = {0x0033, 12};
  t[7] = {0xfff0, 0};
  return t;
}

TEST(LightfieldCoverage, WorkedExampleOfTheSpecification) {
  const std::vector<CoverageTexel> texels = example_texels();
  const CoverageRect rect{4, 2, texels};
  std::vector<uint8_t> payload;
  append_coverage_payload(payload, std::span(&rect, 1));
  // The bytes as SPEC §11.1.11 writes them out.
  EXPECT_EQ(payload, (std::vector<uint8_t>{0x82, 0x00, 0xff, 0x33, 0xf0, 0x0c, 0x00}));
  const std::vector<uint8_t> raw = one_frame_chunk(4, 2, payload);
  EXPECT_EQ(raw.size(), 23u);
  auto chunk = parse_region_chunk(raw, 1, 4, 2, RegionCoding::kCoverage, "tile");
  ASSERT_TRUE(chunk.ok()) << chunk.status().to_string();
  EXPECT_EQ(chunk->units, 2u);  // edge texels
  EXPECT_FALSE(region_rect_reads_state(*chunk, 0));
  EXPECT_EQ(region_gpu_format(RegionCoding::kCoverage), container::PixelFormat::kRgba8);
  std::vector<uint8_t> gpu;
  region_rect_gpu_bytes(*chunk, 0, gpu);
  ASSERT_EQ(gpu.size(), 8 * kCoverageGpuBytes);
  for (size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(coverage_from_gpu(&gpu[i * kCoverageGpuBytes]), texels[i]) << i;
  }
  // Far counts: 16 - 12 - 4 = 0 and 16 - 0 - 12 = 4; a plain texel has none.
  EXPECT_EQ(gpu[1 * kCoverageGpuBytes + 3], 0);
  EXPECT_EQ(gpu[7 * kCoverageGpuBytes + 3], 4);
  EXPECT_EQ(gpu[0 * kCoverageGpuBytes + 3], 0);
  EXPECT_EQ(gpu[0], 0xff);
  EXPECT_EQ(gpu[1], 0xff);
}

TEST(LightfieldCoverage, FlatContentCostsOneBitPerTexel) {
  const std::vector<CoverageTexel> plain(64 * 64);
  const CoverageRect rect{64, 64, plain};
  std::vector<uint8_t> payload;
  append_coverage_payload(payload, std::span(&rect, 1));
  EXPECT_EQ(payload.size(), 64u * 64 / 8);
  for (uint8_t b : payload) EXPECT_EQ(b, 0);
}

TEST(LightfieldCoverage, PFrameRectanglesReplaceTheirTexels) {
  // Two frames of a 3 x 3 tile: the keyframe plain, frame 1 one 2 x 1 rectangle at (1, 2) whose
  // second texel is an edge texel (a bitmap of its own, after the keyframe's).
  RegionHead head;
  head.rect_counts = {1, 1};
  head.rects.push_back({0, 0, 3, 3});
  head.rects.push_back({1, 2, 2, 1});
  std::vector<uint8_t> raw;
  ASSERT_TRUE(container::write_fields(head, raw, "head").ok());
  const std::vector<CoverageTexel> key(9), p = {{}, {0x00ff, 3}};
  const CoverageRect rects[2] = {{3, 3, key}, {2, 1, p}};
  append_coverage_payload(raw, rects);
  auto chunk = parse_region_chunk(raw, 2, 3, 3, RegionCoding::kCoverage, "tile");
  ASSERT_TRUE(chunk.ok()) << chunk.status().to_string();
  std::vector<uint8_t> gpu;
  region_rect_gpu_bytes(*chunk, 1, gpu);
  ASSERT_EQ(gpu.size(), 2 * kCoverageGpuBytes);
  EXPECT_TRUE(coverage_from_gpu(&gpu[0]).plain());
  EXPECT_EQ(coverage_from_gpu(&gpu[kCoverageGpuBytes]), (CoverageTexel{0x00ff, 3}));
  EXPECT_EQ(gpu[kCoverageGpuBytes + 3], 16 - 3 - 8);
}

// Payload of one edge texel (texel 0 of a 2 x 1 tile) with mask `mask` and near count `near`.
std::vector<uint8_t> one_edge(uint16_t mask, uint8_t near) {
  return one_frame_chunk(2, 1,
                         {0x01, static_cast<uint8_t>(mask >> 8), static_cast<uint8_t>(mask), near});
}

TEST(LightfieldCoverage, EdgeTexelsBreakingTheirCountsAreE065) {
  EXPECT_TRUE(parse_region_chunk(one_edge(0x0000, 16), 1, 2, 1, RegionCoding::kCoverage, "t").ok());
  EXPECT_TRUE(parse_region_chunk(one_edge(0x00ff, 8), 1, 2, 1, RegionCoding::kCoverage, "t").ok());
  for (const auto& [mask, near] : std::vector<std::pair<uint16_t, uint8_t>>{
           {0x0000, 17},  // near over 16
           {0x00ff, 9},   // 8 own cells + 9 nearer > 16
           {0xffff, 1},   // 16 own cells + 1 nearer
           {0xffff, 0},   // a plain texel marked as an edge
       }) {
    auto c = parse_region_chunk(one_edge(mask, near), 1, 2, 1, RegionCoding::kCoverage, "t");
    ASSERT_FALSE(c.ok()) << mask << " " << int{near};
    EXPECT_EQ(c.status().id(), ErrorId::kCoverageChunk) << c.status().to_string();
  }
}

TEST(LightfieldCoverage, BitmapBitsPastTheRectangleAreE065AndSizesE202) {
  // A 2 x 1 tile has 2 bitmap bits: bit 2 set is past it.
  auto c = parse_region_chunk(one_frame_chunk(2, 1, {0x04, 0x00, 0x00, 0x01}), 1, 2, 1,
                              RegionCoding::kCoverage, "t");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.status().id(), ErrorId::kCoverageChunk) << c.status().to_string();
  // One edge texel but planes for none, or for two: the payload size is §11.1.6's error.
  for (const std::vector<uint8_t>& payload :
       {std::vector<uint8_t>{0x01}, std::vector<uint8_t>{0x01, 0, 0, 0, 0, 1, 1},
        std::vector<uint8_t>{}}) {
    auto d =
        parse_region_chunk(one_frame_chunk(2, 1, payload), 1, 2, 1, RegionCoding::kCoverage, "t");
    ASSERT_FALSE(d.ok()) << payload.size();
    EXPECT_EQ(d.status().id(), ErrorId::kLightfieldChunk) << d.status().to_string();
  }
}

TEST(LightfieldCoverage, TexelRules) {
  EXPECT_TRUE((CoverageTexel{}).plain());
  EXPECT_TRUE((CoverageTexel{}).valid());
  EXPECT_EQ((CoverageTexel{}).far(), 0);
  EXPECT_EQ((CoverageTexel{0x0000, 0}).far(), 16);
  EXPECT_EQ((CoverageTexel{0x0f0f, 2}).far(), 6);
  EXPECT_FALSE((CoverageTexel{0x0f0f, 9}).valid());
}

}  // namespace
}  // namespace calf::lf
