// Unit tests of the BCn block decoders (calf/format/bc.h): hand-built blocks with known texels,
// reserved encodings, the image-level driver, half-float conversion, the BPTC tables, and
// frozen-output hashes that pin every decoder's exact behaviour on fixed pseudo-random blocks.
// Bit-exactness against an independent decoder is tested in tests/integration/bc_mesa_*.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "calf/format/bc.h"
#include "calf/format/bc_tables.h"

namespace calf::bc {
namespace {

// Writes fields LSB-first into a 16-byte block, for building BPTC blocks by hand.
struct Bits {
  uint8_t b[16] = {};
  int pos = 0;
  void put(uint32_t v, int n) {
    for (int i = 0; i < n; ++i, ++pos)
      if ((v >> i) & 1) b[pos / 8] = static_cast<uint8_t>(b[pos / 8] | (1 << (pos % 8)));
  }
};

TEST(BcHalf, KnownValues) {
  EXPECT_EQ(float_to_half(0.0f), 0x0000);
  EXPECT_EQ(float_to_half(-0.0f), 0x8000);
  EXPECT_EQ(float_to_half(1.0f), 0x3c00);
  EXPECT_EQ(float_to_half(-2.0f), 0xc000);
  EXPECT_EQ(float_to_half(65504.0f), 0x7bff);
  EXPECT_EQ(float_to_half(65519.0f), 0x7bff);  // below the midpoint to 65536
  EXPECT_EQ(float_to_half(65520.0f), 0x7c00);  // tie rounds to even: overflow to Inf
  EXPECT_EQ(float_to_half(std::numeric_limits<float>::infinity()), 0x7c00);
  EXPECT_EQ(float_to_half(0x1p-24f), 0x0001);  // smallest subnormal
  EXPECT_EQ(float_to_half(0x1p-25f), 0x0000);  // tie to even: 0
  EXPECT_EQ(float_to_half(0x1.8p-25f), 0x0001);
  EXPECT_EQ(float_to_half(0x1p-14f), 0x0400);         // smallest normal
  EXPECT_EQ(float_to_half(1.0f + 0x1p-11f), 0x3c00);  // tie to even
  EXPECT_EQ(float_to_half(1.0f + 0x1.8p-11f), 0x3c01);
  EXPECT_TRUE(std::isnan(half_to_float(float_to_half(std::nanf("")))));
  EXPECT_EQ(half_to_float(0x7bff), 65504.0f);
  EXPECT_EQ(half_to_float(0x0001), 0x1p-24f);
}

TEST(BcHalf, EveryHalfRoundTrips) {
  for (uint32_t h = 0; h < 0x10000; ++h) {
    const float f = half_to_float(static_cast<uint16_t>(h));
    if (std::isnan(f)) continue;
    ASSERT_EQ(float_to_half(f), h) << std::hex << h;
  }
}

TEST(BcDecode, Bc1FourAndThreeColourModes) {
  // c0 = pure red (0xf800) > c1 = pure blue (0x001f): 4 colours; texel i uses index i % 4.
  const uint8_t four[8] = {0x00, 0xf8, 0x1f, 0x00, 0xe4, 0xe4, 0xe4, 0xe4};
  uint8_t rgba[64];
  decode_bc1_block(four, rgba);
  const uint8_t want4[4][4] = {
      {255, 0, 0, 255}, {0, 0, 255, 255}, {170, 0, 85, 255}, {85, 0, 170, 255}};
  for (int i = 0; i < 16; ++i) {
    const int idx = (0xe4 >> (2 * (i % 4))) & 3;
    for (int c = 0; c < 4; ++c) EXPECT_EQ(rgba[4 * i + c], want4[idx][c]) << i << " " << c;
  }
  // Swapped endpoints: 3 colours + transparent black.
  const uint8_t three[8] = {0x1f, 0x00, 0x00, 0xf8, 0xe4, 0xe4, 0xe4, 0xe4};
  decode_bc1_block(three, rgba);
  const uint8_t want3[4][4] = {
      {0, 0, 255, 255}, {255, 0, 0, 255}, {127, 0, 127, 255}, {0, 0, 0, 0}};
  for (int i = 0; i < 16; ++i) {
    const int idx = (0xe4 >> (2 * (i % 4))) & 3;
    for (int c = 0; c < 4; ++c) EXPECT_EQ(rgba[4 * i + c], want3[idx][c]) << i << " " << c;
  }
}

TEST(BcDecode, Bc4BothModes) {
  // Selector of texel i = i % 8.
  uint8_t block[8] = {200, 60, 0, 0, 0, 0, 0, 0};
  uint64_t s = 0;
  for (int i = 0; i < 16; ++i) s |= uint64_t(i % 8) << (3 * i);
  for (int i = 0; i < 6; ++i) block[2 + i] = static_cast<uint8_t>(s >> (8 * i));
  uint8_t r[16];
  decode_bc4_block(block, r);
  const int want8[8] = {200, 60, 180, 160, 140, 120, 100, 80};
  for (int i = 0; i < 16; ++i) EXPECT_EQ(r[i], want8[i % 8]);
  block[0] = 60, block[1] = 200;  // 6 levels + 0 + 255
  decode_bc4_block(block, r);
  const int want6[8] = {60, 200, 88, 116, 144, 172, 0, 255};
  for (int i = 0; i < 16; ++i) EXPECT_EQ(r[i], want6[i % 8]);
  int8_t sr[16];
  block[0] = static_cast<uint8_t>(-100), block[1] = 100;
  decode_bc4s_block(block, sr);
  EXPECT_EQ(sr[0], -100);
  EXPECT_EQ(sr[1], 100);
  EXPECT_EQ(sr[6], -128);
  EXPECT_EQ(sr[7], 127);
}

TEST(BcDecode, Bc5IsTwoBc4Blocks) {
  uint8_t block[16];
  std::mt19937 rng(3);
  for (auto& b : block) b = static_cast<uint8_t>(rng());
  uint8_t rg[32], r[16], g[16];
  decode_bc5_block(block, rg);
  decode_bc4_block(block, r);
  decode_bc4_block(block + 8, g);
  for (int i = 0; i < 16; ++i) {
    EXPECT_EQ(rg[2 * i], r[i]);
    EXPECT_EQ(rg[2 * i + 1], g[i]);
  }
}

TEST(BcDecode, Bc7ReservedModeIsTransparentBlack) {
  uint8_t block[16];
  std::memset(block, 0xff, 16);
  block[0] = 0;
  uint8_t rgba[64];
  std::memset(rgba, 0x5a, 64);
  decode_bc7_block(block, rgba);
  for (int i = 0; i < 64; ++i) EXPECT_EQ(rgba[i], 0);
}

TEST(BcDecode, Bc7Mode6ConstantAndGradient) {
  // Mode 6: e0 = (10,20,30,127)+p0=1, e1 = (110,120,0,127)+p1=0; indices i (anchor 0: 3 bits).
  Bits w;
  w.put(1 << 6, 7);
  const int e[2][4] = {{10, 20, 30, 127}, {110, 120, 0, 127}};
  for (int c = 0; c < 4; ++c)
    for (int j = 0; j < 2; ++j) w.put(static_cast<uint32_t>(e[j][c]), 7);
  w.put(1, 1);
  w.put(0, 1);
  for (int i = 0; i < 16; ++i) w.put(static_cast<uint32_t>(i == 0 ? 0 : i), i == 0 ? 3 : 4);
  ASSERT_EQ(w.pos, 128);
  uint8_t rgba[64];
  decode_bc7_block(w.b, rgba);
  const int d0[4] = {21, 41, 61, 255}, d1[4] = {220, 240, 0, 254};  // (v<<1|p) in 8 bits
  for (int i = 0; i < 16; ++i) {
    const int wt = kWeights4[i];
    for (int c = 0; c < 4; ++c) {
      EXPECT_EQ(rgba[4 * i + c], ((64 - wt) * d0[c] + wt * d1[c] + 32) >> 6) << i << " " << c;
    }
  }
}

TEST(BcDecode, Bc7EveryModeDecodesWithoutTouchingOutsideMemory) {
  std::mt19937 rng(11);
  std::vector<uint8_t> guard(64 + 32, 0xcd);
  for (int k = 0; k < 4096; ++k) {
    uint8_t block[16];
    for (auto& b : block) b = static_cast<uint8_t>(rng());
    block[0] = static_cast<uint8_t>(block[0] << (k % 8) | (1 << (k % 8)));
    decode_bc7_block(block, guard.data() + 16);
    for (int i = 0; i < 16; ++i) {
      ASSERT_EQ(guard[i], 0xcd);
    }
    for (int i = 80; i < 96; ++i) {
      ASSERT_EQ(guard[i], 0xcd);
    }
  }
}

TEST(BcDecode, Bc6hReservedModesAreBlack) {
  for (int m : {19, 23, 27, 31}) {
    uint8_t block[16];
    std::memset(block, 0xa5, 16);
    block[0] = static_cast<uint8_t>((block[0] & ~31) | m);
    uint16_t rgb[48];
    std::memset(rgb, 0x77, sizeof rgb);
    decode_bc6h_block(block, false, rgb);
    for (uint16_t v : rgb) EXPECT_EQ(v, 0);
    decode_bc6h_block(block, true, rgb);
    for (uint16_t v : rgb) EXPECT_EQ(v, 0);
  }
}

TEST(BcDecode, Bc6hMode11Extremes) {
  // Mode 11 (5-bit value 3): e0 = max 10-bit, e1 = 0; index 0 everywhere -> 0xffff * 31/64.
  Bits w;
  w.put(3, 5);
  for (int c = 0; c < 3; ++c) w.put(1023, 10);
  for (int c = 0; c < 3; ++c) w.put(0, 10);
  uint16_t rgb[48];
  decode_bc6h_block(w.b, false, rgb);
  for (uint16_t v : rgb) EXPECT_EQ(v, 0x7bff);  // 65504
  decode_bc6h_block(w.b, true, rgb);            // signed: 1023 is -1 in 10 bits -> a tiny negative
  for (uint16_t v : rgb) EXPECT_EQ(v, ((((1 << 15) + 0x4000) >> 9) * 31 >> 5) | 0x8000);
}

TEST(BcDecode, Bc6hNeverProducesNanOrInf) {
  std::mt19937 rng(5);
  for (int k = 0; k < 20000; ++k) {
    uint8_t block[16];
    for (auto& b : block) b = static_cast<uint8_t>(rng());
    uint16_t rgb[48];
    const bool is_signed = k & 1;
    decode_bc6h_block(block, is_signed, rgb);
    for (uint16_t v : rgb) {
      ASSERT_LE(v & 0x7fff, 0x7bff);
      if (!is_signed) {
        ASSERT_EQ(v & 0x8000, 0);
      }
    }
  }
}

TEST(BcTables, AnchorsLieInTheirSubsets) {
  for (int p = 0; p < 64; ++p) {
    EXPECT_EQ(kPartition2[p][kAnchor2[p]], 1) << p;
    EXPECT_EQ(kPartition3[p][kAnchor3a[p]], 1) << p;
    EXPECT_EQ(kPartition3[p][kAnchor3b[p]], 2) << p;
    EXPECT_EQ(kPartition2[p][0], 0);
    EXPECT_EQ(kPartition3[p][0], 0);
  }
  for (int i = 0; i < 16; ++i) EXPECT_EQ(kWeights4[15 - i], 64 - kWeights4[i]);
}

TEST(BcTables, Bc6hLayoutsCoverEveryEndpointBitOnce) {
  for (int k = 0; k < 14; ++k) {
    const Bc6hMode& m = kBc6hModes[k];
    const Bc6hLayout& l = kBc6hLayouts[k];
    int seen[14][16] = {};
    for (int i = 0; i < l.count; ++i) {
      ++seen[l.field[i].var][l.field[i].bit];
    }
    const int regions = m.partition_bits ? 2 : 1;
    for (int e = 0; e < 2 * regions; ++e) {
      for (int c = 0; c < 3; ++c) {
        const int bits = (e == 0 || !m.transformed) ? m.endpoint_bits : m.delta_bits[c];
        for (int b = 0; b < 16; ++b) {
          EXPECT_EQ(seen[3 * e + c][b], b < bits ? 1 : 0) << k;
        }
      }
    }
    EXPECT_EQ(bc6h_mode_index(m.mode_value), k);
  }
}

TEST(BcImage, PartialBlocksWriteOnlyInsideTexels) {
  // 5x3 BC1 image: 2x1 blocks; the output buffer has stride 32 and sentinel bytes elsewhere.
  std::vector<uint8_t> blocks(*compressed_size(Format::kBc1, 5, 3));
  ASSERT_EQ(blocks.size(), 16u);
  std::mt19937 rng(9);
  for (auto& b : blocks) b = static_cast<uint8_t>(rng());
  const size_t stride = 32;
  std::vector<uint8_t> out(stride * 3, 0xee);
  ASSERT_TRUE(
      decode_image(Format::kBc1, blocks.data(), blocks.size(), 5, 3, out.data(), out.size(), stride)
          .ok());
  uint8_t b0[64], b1[64];
  decode_bc1_block(blocks.data(), b0);
  decode_bc1_block(blocks.data() + 8, b1);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 8; ++x) {
      const uint8_t* px = &out[y * stride + x * 4];
      if (x < 5) {
        const uint8_t* want = x < 4 ? &b0[(y * 4 + x) * 4] : &b1[(y * 4 + x - 4) * 4];
        EXPECT_EQ(std::memcmp(px, want, 4), 0) << x << "," << y;
      } else {
        for (int c = 0; c < 4; ++c) EXPECT_EQ(px[c], 0xee) << x << "," << y;
      }
    }
  }
}

TEST(BcImage, ArgumentErrors) {
  std::vector<uint8_t> blocks(64), out(1024);
  EXPECT_EQ(compressed_size(Format::kBc7, 0, 4).status().id(), ErrorId::kBcDimensions);
  EXPECT_EQ(compressed_size(Format::kBc7, 65537, 4).status().id(), ErrorId::kBcDimensions);
  EXPECT_EQ(*compressed_size(Format::kBc7, 65536, 1), 16384u * 16);
  EXPECT_EQ(decode_image(Format::kBc7, blocks.data(), 15, 4, 4, out.data(), out.size(), 16).id(),
            ErrorId::kBcBufferSize);
  EXPECT_EQ(decode_image(Format::kBc7, blocks.data(), 16, 4, 4, out.data(), out.size(), 15).id(),
            ErrorId::kBcStride);
  EXPECT_EQ(decode_image(Format::kBc7, blocks.data(), 16, 4, 4, out.data(), 63, 16).id(),
            ErrorId::kBcBufferSize);
  EXPECT_EQ(decode_image(Format::kBc7, nullptr, 16, 4, 4, out.data(), 64, 16).id(),
            ErrorId::kBcBufferSize);
  EXPECT_TRUE(decode_image(Format::kBc6hSigned, blocks.data(), 16, 3, 2, out.data(), 36, 18).ok());
}

// Frozen outputs: FNV-1a of the decoded texels of 4096 fixed pseudo-random blocks per format
// (mode bytes forced round-robin as in the Mesa cross-check). Any change to what a block means
// changes these; they were recorded when the decoders first agreed bit for bit with Mesa.
uint64_t decoded_hash(Format f) {
  std::mt19937_64 rng(0x5eed0000u + static_cast<unsigned>(f));
  uint64_t h = 0xcbf29ce484222325ull;
  for (int k = 0; k < 4096; ++k) {
    uint8_t block[16];
    for (auto& b : block) b = static_cast<uint8_t>(rng());
    if (f == Format::kBc7) block[0] = static_cast<uint8_t>(block[0] << (k % 8) | (1 << (k % 8)));
    uint8_t out[16 * 8];
    decode_block(f, block, out);
    for (int i = 0; i < 16 * texel_bytes(f); ++i) h = (h ^ out[i]) * 0x100000001b3ull;
  }
  return h;
}

TEST(BcDecode, FrozenOutputs) {
  const struct {
    Format f;
    uint64_t hash;
  } kFrozen[] = {
      {Format::kBc1, 0x4fdd27e4b1f47de0ull},        {Format::kBc4, 0xec0bd842aad6685aull},
      {Format::kBc5, 0xd1c482bd7d4ea69eull},        {Format::kBc4Signed, 0xc393d7dca353420bull},
      {Format::kBc5Signed, 0xa3e6abfd1bfc6dc6ull},  {Format::kBc6hUnsigned, 0x624058cb867d9826ull},
      {Format::kBc6hSigned, 0xd6b3d9f85fbe94b3ull}, {Format::kBc7, 0xe6a702e1c22c97baull},
  };
  for (const auto& fr : kFrozen) {
    EXPECT_EQ(decoded_hash(fr.f), fr.hash)
        << format_name(fr.f) << " 0x" << std::hex << decoded_hash(fr.f);
  }
}

}  // namespace
}  // namespace calf::bc
