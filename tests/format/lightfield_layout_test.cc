// The lightfield chunk records (format/SPEC.md §11.1.3, .4, .6) as declared with the fields
// visitor: hand-written chunk bytes parse to the documented values, the writer produces exactly
// those bytes, and each rule of the SPEC is a CALF-E202 naming what is wrong.
#include "calf/format/lightfield_layout.h"

#include "calf/format/av1_hdr_colour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace calf::lf {
namespace {

using Bytes = std::vector<uint8_t>;

// §11.1.3: version 1, position (1.5, -2, 0.25), z_near 0.5, z_far 64, flags 3, K 30, W 2, Q 38.
const Bytes kViewIndex = {
    0x01, 0x00, 0x00, 0x00,                          // layout version
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xF8, 0x3F,  // x = 1.5
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xC0,  // y = -2
    0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0xD0, 0x3F,  // z = 0.25
    0x00, 0x00, 0x00, 0x3F,                          // z_near = 0.5
    0x00, 0x00, 0x80, 0x42,                          // z_far = 64
    0x03, 0x00, 0x00, 0x00,                          // flags
    0x1E, 0x00, 0x00, 0x00,                          // K
    0x02, 0x00, 0x00, 0x00,                          // W
    0x00, 0x00, 0x18, 0x42,                          // Q = 38
};

TEST(LightfieldLayout, ViewIndexBytesAreTheDocumentedOnes) {
  ASSERT_EQ(kViewIndex.size(), kViewIndexBytes);
  auto v = parse_view_index(kViewIndex, "view 0 index");
  ASSERT_TRUE(v.ok()) << v.status().to_string();
  EXPECT_EQ(v->position.x, 1.5);
  EXPECT_EQ(v->position.y, -2.0);
  EXPECT_EQ(v->position.z, 0.25);
  EXPECT_EQ(v->z_near, 0.5f);
  EXPECT_EQ(v->z_far, 64.0f);
  EXPECT_TRUE(v->has_depth);
  EXPECT_TRUE(v->has_material);
  EXPECT_EQ(v->depth_keyframe_interval, 30u);
  EXPECT_EQ(v->depth_window, 2u);
  EXPECT_EQ(v->min_psnr_db, 38.0f);
  auto bytes = serialize_view_index(*v);
  ASSERT_TRUE(bytes.ok());
  EXPECT_EQ(*bytes, kViewIndex);
}

void expect_refused(Bytes b, const std::string& needle) {
  auto v = parse_view_index(b, "view 7 index");
  ASSERT_FALSE(v.ok()) << needle;
  EXPECT_EQ(v.status().id(), ErrorId::kLightfieldChunk) << v.status().to_string();
  EXPECT_NE(v.status().message().find(needle), std::string::npos) << v.status().to_string();
  EXPECT_EQ(v.status().message().rfind("view 7 index", 0), 0u) << v.status().to_string();
}

TEST(LightfieldLayout, ViewIndexRulesAreCorruptChunks) {
  Bytes b = kViewIndex;
  b[0] = 2;
  expect_refused(b, "layout version 2");
  b = kViewIndex;
  b[18] = 0xF8, b[19] = 0x7F;  // y = NaN
  expect_refused(b, "position[1] nan is not finite");
  b = kViewIndex;
  b[34] = 0x80, b[35] = 0x7F;  // z_far = +inf
  expect_refused(b, "z_far inf is not finite");
  b = kViewIndex;
  b[31] = 0x43;  // z_near = 128 > z_far
  expect_refused(b, "depth range [128, 64]");
  b = kViewIndex;
  b[36] = 4;  // a reserved flag bit
  expect_refused(b, "flags 4");
  b = kViewIndex;
  b[40] = 0;  // K = 0
  expect_refused(b, "depth_keyframe_interval 0");
  b = kViewIndex;
  b.pop_back();
  expect_refused(b, "51 bytes, expected 52");
  // Q is informative: any value reads.
  b = kViewIndex;
  b[50] = 0xC0, b[51] = 0x7F;
  EXPECT_TRUE(parse_view_index(b, "q").ok());
}

TEST(LightfieldLayout, WritingAViewIndexTheReaderRefusesIsMisuse) {
  ViewIndex v;
  v.position.z = std::numeric_limits<double>::infinity();
  EXPECT_EQ(serialize_view_index(v).status().id(), ErrorId::kContainerWriterMisuse);
  v = ViewIndex{};
  v.z_near = 3, v.z_far = 2;
  EXPECT_EQ(serialize_view_index(v).status().id(), ErrorId::kContainerWriterMisuse);
  v = ViewIndex{};
  v.depth_window = 0;
  EXPECT_EQ(serialize_view_index(v).status().id(), ErrorId::kContainerWriterMisuse);
}

// §11.1.4: K = 2 keyframes {0, 2}, then 4 t values.
const Bytes kTChunk = {0x02, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                       0x02, 0x00, 0x00, 0x00, 0x00, 0x80, 0x00, 0x00};

TEST(LightfieldLayout, TChunkRoundTrip) {
  auto tl = parse_t_chunk(kTChunk, 4, "cell");
  ASSERT_TRUE(tl.ok()) << tl.status().to_string();
  EXPECT_EQ(tl->keyframes, (std::vector<uint32_t>{0, 2}));
  EXPECT_EQ(tl->t, (Bytes{0, 0x80, 0, 0}));
  Bytes out;
  ASSERT_TRUE(container::write_fields(*tl, out).ok());
  EXPECT_EQ(out, kTChunk);
  // Another frame count, a keyframe count above it, a hostile count: E202.
  EXPECT_EQ(parse_t_chunk(kTChunk, 5, "cell").status().id(), ErrorId::kLightfieldChunk);
  EXPECT_EQ(parse_t_chunk(kTChunk, 1u << 24, "cell").status().id(), ErrorId::kLightfieldChunk);
  Bytes b = kTChunk;
  b[3] = 0xFF;
  EXPECT_EQ(parse_t_chunk(b, 4, "cell").status().id(), ErrorId::kLightfieldChunk);
  b = kTChunk;
  b[8] = 0;  // keyframes {0, 0}
  EXPECT_EQ(parse_t_chunk(b, 4, "cell").status().id(), ErrorId::kLightfieldChunk);
}

// §11.1.6: F = 2 frames of an 8 x 4 r16 tile: frame 0 the whole tile, frame 1 one 2 x 1 rect at
// (3, 2); then 2 x (32 + 2) payload bytes.
Bytes region_chunk() {
  const uint8_t head[28] = {0x02, 0x00, 0x00, 0x00,                           // F
                            0x01, 0x00, 0x00, 0x00,                           // R_0
                            0x01, 0x00, 0x00, 0x00,                           // R_1
                            0x00, 0x00, 0x00, 0x00, 0x08, 0x00, 0x04, 0x00,   // (0, 0, 8, 4)
                            0x03, 0x00, 0x02, 0x00, 0x02, 0x00, 0x01, 0x00};  // (3, 2, 2, 1)
  Bytes b(sizeof head + 2 * 34, 0x5A);
  std::copy(std::begin(head), std::end(head), b.begin());
  return b;
}

TEST(LightfieldLayout, RegionChunkHead) {
  const Bytes raw = region_chunk();
  auto c = parse_region_chunk(raw, 2, 8, 4, RegionCoding::kR16, "tile");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  EXPECT_EQ(c->first_rect, (std::vector<uint32_t>{0, 1, 2}));
  ASSERT_EQ(c->rects.size(), 2u);
  EXPECT_EQ(c->rects[1].x, 3);
  EXPECT_EQ(c->rects[1].y, 2);
  EXPECT_EQ(c->rects[1].w, 2);
  EXPECT_EQ(c->rects[1].h, 1);
  EXPECT_EQ(c->rects[1].first_unit, 32u);
  EXPECT_EQ(c->units, 34u);
  EXPECT_EQ(c->payload.size(), 68u);
  RegionHead head;
  head.rect_counts = {1, 1};
  head.rects = c->rects;
  Bytes out;
  ASSERT_TRUE(container::write_fields(head, out).ok());
  EXPECT_EQ(out, Bytes(raw.begin(), raw.begin() + 28));
  // A rect count that runs past the chunk, a rect leaving the tile, another key: E202.
  Bytes b = raw;
  b[8] = 0xFF, b[9] = 0xFF, b[10] = 0xFF;
  EXPECT_EQ(parse_region_chunk(b, 2, 8, 4, RegionCoding::kR16, "t").status().id(),
            ErrorId::kLightfieldChunk);
  b = raw;
  b[20] = 7;  // x = 7, w = 2 leaves the 8-wide tile
  EXPECT_EQ(parse_region_chunk(b, 2, 8, 4, RegionCoding::kR16, "t").status().id(),
            ErrorId::kLightfieldChunk);
  EXPECT_EQ(parse_region_chunk(raw, 3, 8, 4, RegionCoding::kR16, "t").status().id(),
            ErrorId::kLightfieldChunk);
  b = raw;
  b[0] = 0xFF, b[3] = 0xFF;  // F = 0xFF0000FF
  EXPECT_EQ(parse_region_chunk(b, 2, 8, 4, RegionCoding::kR16, "t").status().id(),
            ErrorId::kLightfieldChunk);
}

}  // namespace
}  // namespace calf::lf

namespace calf::lf {
namespace {

// SPEC §11.1.12: u32 F, F x u32 unit sizes, the units; written here byte by byte.
TEST(LightfieldLayout, Av1GopChunk) {
  const Bytes raw = {2, 0, 0, 0, 3, 0, 0, 0, 1, 0, 0, 0, 0x12, 0x00, 0xAA, 0xBB};
  auto gop = parse_av1_gop(raw, 2, "cell");
  ASSERT_TRUE(gop.ok()) << gop.status().to_string();
  ASSERT_EQ(gop->units.size(), 2u);
  EXPECT_EQ(Bytes(gop->units[0].begin(), gop->units[0].end()), (Bytes{0x12, 0x00, 0xAA}));
  EXPECT_EQ(Bytes(gop->units[1].begin(), gop->units[1].end()), (Bytes{0xBB}));
  Bytes out;
  const std::vector<Bytes> units = {{0x12, 0x00, 0xAA}, {0xBB}};
  append_av1_gop(out, units);
  EXPECT_EQ(out, raw);
  // Another frame count than the keys', a unit of 0 bytes, units past the chunk, a byte left
  // over, a head cut short: E067.
  EXPECT_EQ(parse_av1_gop(raw, 3, "c").status().id(), ErrorId::kAv1Chunk);
  Bytes b = raw;
  b[8] = 0;
  EXPECT_EQ(parse_av1_gop(b, 2, "c").status().id(), ErrorId::kAv1Chunk);
  b = raw;
  b[8] = 2;
  EXPECT_EQ(parse_av1_gop(b, 2, "c").status().id(), ErrorId::kAv1Chunk);
  b = raw;
  b.push_back(0);
  EXPECT_EQ(parse_av1_gop(b, 2, "c").status().id(), ErrorId::kAv1Chunk);
  EXPECT_EQ(parse_av1_gop(Bytes(raw.begin(), raw.begin() + 6), 2, "c").status().id(),
            ErrorId::kAv1Chunk);
  EXPECT_EQ(parse_av1_gop(Bytes{0, 0, 0, 0}, 0, "c").status().id(), ErrorId::kAv1Chunk);
  // AV1 is a colour format without keyframe payloads; the player gets rgba8 updates.
  EXPECT_TRUE(check_colour_format(static_cast<uint16_t>(container::PixelFormat::kAv1)).ok());
  Bytes gpu;
  EXPECT_EQ(colour_payload_gpu_bytes(12, raw, 4, 4, gpu, "c").id(), ErrorId::kLightfieldFormat);
  EXPECT_EQ(colour_gpu_format(12), container::PixelFormat::kRgba8);
  EXPECT_EQ(colour_gpu_format(4), container::PixelFormat::kBc1);
  // The 4:4:4 formats (1.5): av1-444 gives rgba8 as av1, av1hdr-444 rgba16f as av1hdr; 16 is no
  // colour format.
  EXPECT_TRUE(check_colour_format(14).ok());
  EXPECT_TRUE(check_colour_format(15).ok());
  EXPECT_EQ(check_colour_format(16).id(), ErrorId::kLightfieldFormat);
  EXPECT_EQ(colour_gpu_format(14), container::PixelFormat::kRgba8);
  EXPECT_EQ(colour_gpu_format(13), container::PixelFormat::kRgba16f);
  EXPECT_EQ(colour_gpu_format(15), container::PixelFormat::kRgba16f);
  EXPECT_STREQ(container::pixel_format_name(14), "av1-444");
  EXPECT_STREQ(container::pixel_format_name(15), "av1hdr-444");
  // Which AV1 formats are HDR (a curve heads each chunk) and which 4:4:4.
  for (uint16_t f = 0; f < 17; ++f) {
    EXPECT_EQ(is_av1_colour(f), f >= 12 && f <= 15) << f;
    EXPECT_EQ(is_av1_hdr_colour(f), f == 13 || f == 15) << f;
    EXPECT_EQ(is_av1_chroma444(f), f == 14 || f == 15) << f;
  }
  // av1hdr-444's chunk is headed by the curve as av1hdr's; av1-444's is the GOP alone.
  Bytes headed = {0x00, 0x3C, 0x02, 0x00};
  headed.insert(headed.end(), raw.begin(), raw.end());
  Av1HdrCurve curve;
  auto g15 = parse_av1_chunk(headed, 2, 15, &curve, "c");
  ASSERT_TRUE(g15.ok()) << g15.status().to_string();
  EXPECT_EQ(curve.base, 0x3C00);
  EXPECT_EQ(curve.shift, 2);
  EXPECT_EQ(g15->units.size(), 2u);
  EXPECT_TRUE(parse_av1_chunk(raw, 2, 14, &curve, "c").ok());
  EXPECT_EQ(parse_av1_chunk(raw, 2, 15, &curve, "c").status().id(), ErrorId::kAv1Chunk);
}

}  // namespace
}  // namespace calf::lf
