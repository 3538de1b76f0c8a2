// Depth format r16p (format/SPEC.md §11.1.8): the residuals of hand-computed examples, the
// region chunk's predicted payload decoded back to codes, and the inverse exact on any codes —
// random, sky beside finite depth, extremes, every rectangle shape down to one texel. Depth
// format r16pm (§11.1.9): its worked example, the masked inverse under any mask and tile state,
// and malformed masks and payloads (CALF-E202).
#include "calf/format/depth_predict.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "calf/format/container_fields.h"
#include "calf/format/lightfield_layout.h"

namespace calf::lf {
namespace {

// Residuals as the region chunk stores them (high plane, then low plane), decoded through the
// public inverse into codes.
std::vector<uint16_t> round_trip(const std::vector<uint16_t>& codes, uint32_t w, uint32_t h) {
  std::vector<uint16_t> e(codes.size());
  predict_depth_rect(codes.data(), w, h, w, e.data());
  std::vector<uint8_t> hi(e.size()), lo(e.size()), out(e.size() * 2);
  for (size_t i = 0; i < e.size(); ++i) {
    hi[i] = static_cast<uint8_t>(e[i] >> 8);
    lo[i] = static_cast<uint8_t>(e[i]);
  }
  reconstruct_depth_rect(hi.data(), lo.data(), w, h, out.data());
  std::vector<uint16_t> back(codes.size());
  for (size_t i = 0; i < back.size(); ++i)
    back[i] = static_cast<uint16_t>(out[2 * i] | out[2 * i + 1] << 8);
  return back;
}

TEST(DepthPredict, HandComputedResiduals) {
  // 2 x 2: (0,0) predicted 0 -> +10 -> 20; (1,0) from the left 10 -> +2 -> 4; (0,1) from above
  // 10 -> +1 -> 2; (1,1) the plane a + b - c = 11 + 12 - 10 = 13, 65535 - 13 = -14 as int16 -> 27.
  const std::vector<uint16_t> codes = {10, 12, 11, 65535};
  std::vector<uint16_t> e(4);
  predict_depth_rect(codes.data(), 2, 2, 2, e.data());
  EXPECT_EQ(e, (std::vector<uint16_t>{20, 4, 2, 27}));
  // A plane 1000 + 3x + 5y is predicted exactly inside; the first row steps by 3 (-> 6), the
  // first column by 5 (-> 10).
  std::vector<uint16_t> plane(4 * 3);
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 4; ++x) plane[y * 4 + x] = static_cast<uint16_t>(1000 + 3 * x + 5 * y);
  std::vector<uint16_t> pe(plane.size());
  predict_depth_rect(plane.data(), 4, 3, 4, pe.data());
  EXPECT_EQ(pe, (std::vector<uint16_t>{2000, 6, 6, 6, 10, 0, 0, 0, 10, 0, 0, 0}));
  // A stride wider than the rectangle reads only the rectangle's texels.
  std::vector<uint16_t> sub(2);
  predict_depth_rect(plane.data() + 5, 2, 1, 4, sub.data());
  EXPECT_EQ(sub, (std::vector<uint16_t>{2016, 6}));  // 1008 -> 2016, then +3
  // Sky runs predict sky: a row of sky under sky costs zeros after its first texel.
  const std::vector<uint16_t> sky(6, 65535);
  std::vector<uint16_t> se(6);
  predict_depth_rect(sky.data(), 3, 2, 3, se.data());
  EXPECT_EQ(se, (std::vector<uint16_t>{1, 0, 0, 0, 0, 0}));  // 65535 = -1 -> 1
  // Sky beside finite depth: (1, 0) from the sky on its left, 20000 - 65535 = 20001 (mod 65536)
  // -> 40002; (0, 1) sky from sky -> 0; (1, 1) has sky neighbours, so the median: c = 65535 >=
  // max(a, b) gives min = 20000 (the finite texel above), +7 -> 14.
  const std::vector<uint16_t> edge = {65535, 20000, 65535, 20007};
  std::vector<uint16_t> ee(4);
  predict_depth_rect(edge.data(), 2, 2, 2, ee.data());
  EXPECT_EQ(ee, (std::vector<uint16_t>{1, 40002, 0, 14}));
}

TEST(DepthPredict, InverseIsExactOnAnyCodes) {
  std::mt19937 rng(7);
  // Widths around the decoder's 8-texel prefix sums (a whole number of them, one more, one less).
  for (uint32_t w : {1u, 2u, 3u, 7u, 8u, 9u, 17u, 32u, 100u}) {
    for (uint32_t h : {1u, 2u, 5u, 32u}) {
      const size_t n = size_t{w} * h;
      std::vector<uint16_t> random(n), sky_edge(n), extremes(n), smooth(n), lone_sky(n);
      for (size_t i = 0; i < n; ++i) {
        const uint32_t x = i % w, y = static_cast<uint32_t>(i / w);
        random[i] = static_cast<uint16_t>(rng());
        // Finite depth with sky above a diagonal and single sky texels inside the surface.
        sky_edge[i] =
            x + y * 2 < w || rng() % 9 == 0 ? 65535 : static_cast<uint16_t>(20000 + 7 * x + 3 * y);
        extremes[i] = (x + y) % 2 == 0 ? 0 : (rng() % 2 ? 65535 : 65534);
        smooth[i] = static_cast<uint16_t>(65000 + 13 * x + 2 * y);  // wraps past 65535
        // A plane with one sky texel mid-row under a row without sky (a decoder that sums the
        // plane's residuals along such a row must notice the sky and use the median there), and
        // one in the last column (which no texel of its row predicts from).
        lone_sky[i] = (x == w / 2 && y == h / 2) || (x + 1 == w && y == h - 1)
                          ? 65535
                          : static_cast<uint16_t>(30000 + 11 * x - 5 * y);
      }
      for (const auto* codes : {&random, &sky_edge, &extremes, &smooth, &lone_sky}) {
        EXPECT_EQ(round_trip(*codes, w, h), *codes) << w << "x" << h;
      }
    }
  }
}

TEST(DepthPredict, SkyAtEveryColumnOfAPlaneRow) {
  // The decoder sums a row's residuals eight at a time where the row above has no sky; a sky code
  // it produces in any lane must send the lanes after it to the median. One sky texel per case,
  // at every column of the second row of a plane, and a run of sky ending at every column.
  for (uint32_t w : {16u, 24u}) {
    for (uint32_t k = 0; k < w; ++k) {
      std::vector<uint16_t> lone(size_t{w} * 3), run(size_t{w} * 3);
      for (uint32_t i = 0; i < lone.size(); ++i) {
        const uint32_t x = i % w, y = i / w;
        const auto plane = static_cast<uint16_t>(20000 + 37 * x + 11 * y);
        lone[i] = y == 1 && x == k ? 65535 : plane;
        run[i] = y >= 1 && x <= k ? 65535 : plane;
      }
      EXPECT_EQ(round_trip(lone, w, 3), lone) << w << " sky at " << k;
      EXPECT_EQ(round_trip(run, w, 3), run) << w << " sky to " << k;
    }
    // Under a row of sky, a surface that starts at column 0 and stays constant: its residuals
    // are 0 after the first (the median of a finite left code and sky above is the left code),
    // which is no sky block however long the row.
    std::vector<uint16_t> under(size_t{w} * 2, 65535);
    for (uint32_t x = 0; x < w; ++x) under[w + x] = 30000;
    EXPECT_EQ(round_trip(under, w, 2), under) << w << " surface under sky";
  }
}

TEST(DepthPredict, RegionChunkPayloadDecodesToCodes) {
  // An 8 x 4 tile, 2 frames: the keyframe (0, 0, 8, 4), then (3, 2, 2, 1); the payload is the
  // residuals of both rectangles, each predicted on its own, as two planes.
  std::vector<uint16_t> key(32), rect = {40000, 65535};
  for (uint32_t i = 0; i < 32; ++i)
    key[i] = i % 8 < 3 ? 65535 : static_cast<uint16_t>(30000 + 11 * i);
  std::vector<uint16_t> e(34);
  predict_depth_rect(key.data(), 8, 4, 8, e.data());
  predict_depth_rect(rect.data(), 2, 1, 2, e.data() + 32);
  // The second rectangle's residuals, by hand: 40000 = -25536 as int16 -> 51071; then
  // 65535 - 40000 = 25535 -> 51070.
  EXPECT_EQ(e[32], 51071);
  EXPECT_EQ(e[33], 51070);
  RegionHead head;
  head.rect_counts = {1, 1};
  head.rects = {{0, 0, 8, 4, 0}, {3, 2, 2, 1, 0}};
  std::vector<uint8_t> raw;
  ASSERT_TRUE(container::write_fields(head, raw).ok());
  for (uint16_t v : e) raw.push_back(static_cast<uint8_t>(v >> 8));
  for (uint16_t v : e) raw.push_back(static_cast<uint8_t>(v));
  auto depth = depth_coding(static_cast<uint16_t>(container::PixelFormat::kR16Predicted));
  ASSERT_TRUE(depth.ok());
  EXPECT_EQ(region_gpu_format(*depth), container::PixelFormat::kR16);
  auto c = parse_region_chunk(raw, 2, 8, 4, *depth, "tile");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  std::vector<uint8_t> out;
  region_rect_gpu_bytes(*c, 0, out);
  ASSERT_EQ(out.size(), 64u);
  for (size_t i = 0; i < 32; ++i) EXPECT_EQ(out[2 * i] | out[2 * i + 1] << 8, key[i]) << i;
  region_rect_gpu_bytes(*c, 1, out);
  EXPECT_EQ(out, (std::vector<uint8_t>{0x40, 0x9C, 0xFF, 0xFF}));
  // A payload one texel short is E202, as for r16.
  raw.pop_back();
  EXPECT_EQ(parse_region_chunk(raw, 2, 8, 4, *depth, "t").status().id(), ErrorId::kLightfieldChunk);
}

// Depth format r16pm (SPEC §11.1.9), the specification's worked example: a 3 x 2 tile, frame 0
// the keyframe 100 102 106 / 101 103 105 (r16p of the whole tile), frame 1 one rectangle, the
// whole tile, whose texels 1, 4 and 5 changed. Frame 1's codes are 100 103 106 / 101 65535 107; the
// unchanged texels 0, 2, 3 (100, 106, 101) are the decoder's tile state. Mask: bits 1, 4, 5 = 0x32.
// Residuals, by hand: texel 1 from its left 100: +3 -> 6; texel 4 the plane 101 + 103 - 100 = 104,
// 65535 - 104 = -105 -> 209; texel 5 has sky on its left: the median of a = 65535, b = 106, c = 103
// (c <= min) is max = 65535, and 107 - 65535 = 108 (mod 65536) -> 216.
struct MaskedExample {
  std::vector<uint16_t> key = {100, 102, 106, 101, 103, 105};
  std::vector<uint16_t> frame1 = {100, 103, 106, 101, 65535, 107};
  std::vector<uint8_t> raw;
  MaskedExample() {
    RegionHead head;
    head.rect_counts = {1, 1};
    head.rects = {{0, 0, 3, 2, 0}, {0, 0, 3, 2, 0}};
    EXPECT_TRUE(container::write_fields(head, raw).ok());
    std::vector<uint16_t> e(6);
    predict_depth_rect(key.data(), 3, 2, 3, e.data());
    EXPECT_EQ(e, (std::vector<uint16_t>{200, 4, 8, 2, 0, 3}));
    std::vector<uint16_t> changed;
    const uint8_t mask = 0x32;
    predict_depth_rect_masked(frame1.data(), 3, 2, 3, &mask, changed);
    EXPECT_EQ(changed, (std::vector<uint16_t>{6, 209, 216}));
    e.insert(e.end(), changed.begin(), changed.end());
    raw.push_back(mask);
    for (uint16_t v : e) raw.push_back(static_cast<uint8_t>(v >> 8));
    for (uint16_t v : e) raw.push_back(static_cast<uint8_t>(v));
  }
};

std::vector<uint16_t> codes_of(const std::vector<uint8_t>& gpu) {
  std::vector<uint16_t> c(gpu.size() / 2);
  for (size_t i = 0; i < c.size(); ++i)
    c[i] = static_cast<uint16_t>(gpu[2 * i] | gpu[2 * i + 1] << 8);
  return c;
}
std::vector<uint8_t> gpu_of(const std::vector<uint16_t>& codes) {
  std::vector<uint8_t> g;
  for (uint16_t c : codes) {
    g.push_back(static_cast<uint8_t>(c));
    g.push_back(static_cast<uint8_t>(c >> 8));
  }
  return g;
}

TEST(DepthPredictMasked, WorkedExampleDecodes) {
  const MaskedExample ex;
  // Head 4 + 2 x 4 + 2 x 8 = 28 bytes, then 1 mask byte and 2 x (6 + 3) plane bytes.
  ASSERT_EQ(ex.raw.size(), 28u + 1 + 18);
  // The payload as SPEC §11.1.9 prints it.
  EXPECT_EQ(std::vector<uint8_t>(ex.raw.begin() + 28, ex.raw.end()),
            (std::vector<uint8_t>{0x32, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xC8, 0x04, 0x08, 0x02, 0x00,
                                  0x03, 0x06, 0xD1, 0xD8}));
  auto depth = depth_coding(static_cast<uint16_t>(container::PixelFormat::kR16PredictedMasked));
  ASSERT_TRUE(depth.ok());
  EXPECT_EQ(*depth, RegionCoding::kR16PredictedMasked);
  EXPECT_EQ(region_gpu_format(*depth), container::PixelFormat::kR16);
  auto c = parse_region_chunk(ex.raw, 2, 3, 2, *depth, "tile");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  EXPECT_EQ(c->mask_bytes, 1u);
  EXPECT_EQ(c->units, 9u);
  EXPECT_FALSE(region_rect_reads_state(*c, 0));
  ASSERT_TRUE(region_rect_reads_state(*c, 1));
  std::vector<uint8_t> out;
  region_rect_gpu_bytes(*c, 0, out);
  EXPECT_EQ(codes_of(out), ex.key);
  // From the keyframe's state (frame 0), and from a state whose changed texels hold anything
  // (a decoder that came from another frame of the window): the same frame 1, because the
  // changed texels are predicted from frame-1 values only and the unchanged ones are kept.
  for (const std::vector<uint16_t>& state :
       {ex.key, std::vector<uint16_t>{100, 7, 106, 101, 65535, 0}}) {
    out = gpu_of(state);
    region_rect_gpu_bytes(*c, 1, out);
    EXPECT_EQ(codes_of(out), ex.frame1);
  }
  // A state whose unchanged texels differ from frame 1 breaks the stream's premise: those
  // texels stay, and the changed texels predicted from them come out different.
  std::vector<uint16_t> wrong = ex.key;
  wrong[0] = 50;  // texel 0: texel 1 is predicted from it
  out = gpu_of(wrong);
  region_rect_gpu_bytes(*c, 1, out);
  EXPECT_NE(codes_of(out), ex.frame1);
}

TEST(DepthPredictMasked, InverseIsExactUnderAnyMask) {
  std::mt19937 rng(11);
  // Masks: random texels, runs of 1-40 texels (the decoder sums each run of set bits on its own,
  // from the code on its left), every texel, none. Codes: sky in one texel of 5, sky rarely (most
  // runs are the plane's; a few must notice a sky code), no sky (every run is the plane's).
  enum class Mask { kRandom, kRuns, kAll, kNone };
  for (uint32_t w : {1u, 3u, 8u, 13u, 16u, 41u, 100u}) {
    for (uint32_t h : {1u, 2u, 9u}) {
      for (Mask kind : {Mask::kRandom, Mask::kRuns, Mask::kAll, Mask::kNone}) {
        for (uint32_t sky_one_in : {5u, 150u, 0u}) {
          const size_t n = size_t{w} * h;
          std::vector<uint16_t> codes(n), state(n);
          std::vector<uint8_t> mask(mask_bytes_of(w, h), 0);
          bool changed = false;
          size_t run_left = 0;
          for (size_t i = 0; i < n; ++i) {
            const bool sky = sky_one_in != 0 && rng() % sky_one_in == 0;
            codes[i] =
                sky ? 65535 : static_cast<uint16_t>(30000 + 9 * (i % w) - 4 * (i / w) + rng() % 4);
            switch (kind) {
              case Mask::kRandom:
                changed = rng() % 3 != 0;
                break;
              case Mask::kRuns:
                if (run_left == 0) {
                  changed = !changed;
                  run_left = 1 + rng() % 40;
                }
                --run_left;
                break;
              case Mask::kAll:
                changed = true;
                break;
              case Mask::kNone:
                changed = false;
                break;
            }
            if (changed) mask[i / 8] |= static_cast<uint8_t>(1u << (i % 8));
            state[i] = changed ? static_cast<uint16_t>(rng()) : codes[i];
          }
          std::vector<uint16_t> e;
          predict_depth_rect_masked(codes.data(), w, h, w, mask.data(), e);
          std::vector<uint8_t> hi, lo;
          for (uint16_t v : e) {
            hi.push_back(static_cast<uint8_t>(v >> 8));
            lo.push_back(static_cast<uint8_t>(v));
          }
          std::vector<uint8_t> out = gpu_of(state);
          reconstruct_depth_rect_masked(mask.data(), hi.data(), lo.data(), w, h, out.data());
          EXPECT_EQ(codes_of(out), codes)
              << w << "x" << h << " mask " << static_cast<int>(kind) << " sky 1/" << sky_one_in;
        }
      }
    }
  }
}

TEST(DepthPredictMasked, MalformedPayloadsAreE202) {
  const MaskedExample ex;
  auto depth = depth_coding(static_cast<uint16_t>(container::PixelFormat::kR16PredictedMasked));
  ASSERT_TRUE(depth.ok());
  auto id = [&](const std::vector<uint8_t>& raw) {
    return parse_region_chunk(raw, 2, 3, 2, *depth, "t").status().id();
  };
  ASSERT_EQ(id(ex.raw), ErrorId::kOk);
  const size_t mask_at = 28;
  std::vector<uint8_t> b = ex.raw;
  b[mask_at] |= 0x40;  // bit 6: past the rectangle's 6 texels
  EXPECT_EQ(id(b), ErrorId::kLightfieldChunk);
  b = ex.raw;
  b[mask_at] |= 0x01;  // one more changed texel, no residual for it
  EXPECT_EQ(id(b), ErrorId::kLightfieldChunk);
  b = ex.raw;
  b[mask_at] = 0x02;  // fewer changed texels than residuals
  EXPECT_EQ(id(b), ErrorId::kLightfieldChunk);
  b = ex.raw;
  b.pop_back();
  EXPECT_EQ(id(b), ErrorId::kLightfieldChunk);
  b.assign(ex.raw.begin(), ex.raw.begin() + mask_at);  // no room even for the mask
  EXPECT_EQ(id(b), ErrorId::kLightfieldChunk);
  // An empty mask is valid: the rectangle stores nothing and changes nothing.
  b = ex.raw;
  b[mask_at] = 0;
  b.erase(b.begin() + mask_at + 1 + 6, b.begin() + mask_at + 1 + 9);  // hi plane's 3
  b.resize(b.size() - 3);                                             // lo plane's 3
  auto c = parse_region_chunk(b, 2, 3, 2, *depth, "t");
  ASSERT_TRUE(c.ok()) << c.status().to_string();
  std::vector<uint8_t> out = gpu_of(ex.key);
  region_rect_gpu_bytes(*c, 1, out);
  EXPECT_EQ(codes_of(out), ex.key);
  // The 1.0 pixel formats stay as they were: a depth format past r16pm is E203.
  EXPECT_EQ(depth_coding(12).status().id(), ErrorId::kLightfieldFormat);
}

}  // namespace
}  // namespace calf::lf
