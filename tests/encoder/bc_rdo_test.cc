// Tests of the colour RDO pass (calf/encoder/bc_rdo.h), BC1 / BC6H / BC7: off means untouched, on
// means smaller once zstd-compressed, each block's added error bounded by what the cost rule
// allows, argument errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "calf/encoder/bc_encode.h"
#include "calf/encoder/bc_rdo.h"
#include "calf/format/bc.h"
#include "calf/format/container_codec.h"

namespace calf::bc {
namespace {

constexpr uint32_t kW = 64, kH = 48;

// A smooth gradient with mild noise and a flat band: content with near-repeating blocks, as a
// rendered cell has.
std::vector<uint8_t> ldr_image() {
  std::vector<uint8_t> img(kW * kH * 4, 255);
  std::mt19937 rng(7);
  for (uint32_t y = 0; y < kH; ++y) {
    for (uint32_t x = 0; x < kW; ++x) {
      uint8_t* p = &img[(y * kW + x) * 4];
      const bool band = y >= 16 && y < 28;
      for (int c = 0; c < 3; ++c) {
        const int base = band ? 90 + 20 * c : static_cast<int>(x * 2 + y + 30 * c);
        p[c] = static_cast<uint8_t>(std::clamp(base + static_cast<int>(rng() % 5) - 2, 0, 255));
      }
    }
  }
  return img;
}

std::vector<uint8_t> bc7_of(const std::vector<uint8_t>& img) {
  std::vector<uint8_t> blocks(encode_bound(Format::kBc7, kW, kH));
  Bc7Options o;
  o.quality = 0;
  EXPECT_TRUE(encode_bc7({img.data(), kW, kH, kW * 4, 4}, blocks.data(), blocks.size(), o).ok());
  return blocks;
}

size_t zstd_size(const std::vector<uint8_t>& bytes) {
  auto c = container::compress_chunk(bytes, container::Compression::kZstd);
  EXPECT_TRUE(c.ok());
  return c.ok() ? c->bytes.size() : 0;
}

// Squared 8-bit RGBA error of block k of the image, decoded by `decode` (BC7 or BC1).
double block_error(void (*decode)(const uint8_t*, uint8_t*), const uint8_t* block,
                   const std::vector<uint8_t>& img, uint32_t k) {
  uint8_t out[16 * 4];
  decode(block, out);
  const uint32_t bx = k % (kW / 4), by = k / (kW / 4);
  double e = 0;
  for (int i = 0; i < 16; ++i) {
    const uint8_t* p = &img[((by * 4 + i / 4) * kW + bx * 4 + i % 4) * 4];
    for (int c = 0; c < 4; ++c) e += std::pow(double(out[4 * i + c]) - p[c], 2);
  }
  return e;
}

TEST(BcRdo, LambdaZeroLeavesTheBlocksUntouched) {
  const std::vector<uint8_t> img = ldr_image();
  const std::vector<uint8_t> before = bc7_of(img);
  std::vector<uint8_t> blocks = before;
  BcRdoStats s;
  ASSERT_TRUE(rdo_bc7(img.data(), kW, kH, blocks.data(), blocks.size(), {}, &s).ok());
  EXPECT_EQ(blocks, before);
  EXPECT_EQ(s.changed, 0u);
  EXPECT_EQ(s.blocks, uint64_t{kW / 4 * kH / 4});
}

TEST(BcRdo, Bc7SmallerOnceCompressedAndEachBlocksErrorBounded) {
  const std::vector<uint8_t> img = ldr_image();
  const std::vector<uint8_t> before = bc7_of(img);
  std::vector<uint8_t> blocks = before;
  BcRdoOptions o;
  o.lambda = 4;
  BcRdoStats s;
  ASSERT_TRUE(rdo_bc7(img.data(), kW, kH, blocks.data(), blocks.size(), o, &s).ok());
  EXPECT_GT(s.changed, 0u);
  EXPECT_LT(zstd_size(blocks), zstd_size(before) * 9 / 10);
  // A block is replaced only when D + lambda R falls; R is at most 128 bits (16 literals) and at
  // least 24 (one match), so no block may gain more than lambda * 104 of squared error.
  for (uint32_t k = 0; k < blocks.size() / 16; ++k) {
    const double d0 = block_error(decode_bc7_block, &before[k * 16], img, k);
    const double d1 = block_error(decode_bc7_block, &blocks[k * 16], img, k);
    EXPECT_LT(d1 - d0, o.lambda * 104 + 1e-9) << "block " << k;
  }
  // Every block still decodes as BC7 (a standard block): the whole image decodes.
  std::vector<uint8_t> out(kW * kH * 4);
  EXPECT_TRUE(decode_image(Format::kBc7, blocks.data(), blocks.size(), kW, kH, out.data(),
                           out.size(), kW * 4)
                  .ok());
}

std::vector<uint8_t> bc1_of(const std::vector<uint8_t>& img) {
  std::vector<uint8_t> blocks(encode_bound(Format::kBc1, kW, kH));
  EXPECT_TRUE(encode_bc1({img.data(), kW, kH, kW * 4, 4}, blocks.data(), blocks.size(), {}).ok());
  return blocks;
}

// BC1 as calf stores it: endpoint halves, then index halves (SPEC §7).
std::vector<uint8_t> block_split(const std::vector<uint8_t>& bc1) {
  std::vector<uint8_t> out;
  for (int side : {0, 4})
    for (size_t b = 0; b < bc1.size() / 8; ++b)
      out.insert(out.end(), bc1.begin() + b * 8 + side, bc1.begin() + b * 8 + side + 4);
  return out;
}

TEST(BcRdo, Bc1SmallerOnceSplitAndCompressedEachBlocksErrorBoundedRepeatable) {
  const std::vector<uint8_t> img = ldr_image();
  const std::vector<uint8_t> before = bc1_of(img);
  std::vector<uint8_t> blocks = before;
  BcRdoStats s;
  ASSERT_TRUE(rdo_bc1(img.data(), kW, kH, blocks.data(), blocks.size(), {}, &s).ok());
  EXPECT_EQ(blocks, before);  // lambda 0: untouched
  EXPECT_EQ(s.changed, 0u);
  BcRdoOptions o;
  o.lambda = 4;
  std::vector<uint8_t> again = before;
  s = {};
  ASSERT_TRUE(rdo_bc1(img.data(), kW, kH, blocks.data(), blocks.size(), o, &s).ok());
  ASSERT_TRUE(rdo_bc1(img.data(), kW, kH, again.data(), again.size(), o).ok());
  EXPECT_EQ(blocks, again);  // deterministic
  EXPECT_GT(s.changed, 0u);
  EXPECT_EQ(s.blocks, uint64_t{kW / 4 * kH / 4});
  EXPECT_LT(zstd_size(block_split(blocks)), zstd_size(block_split(before)) * 9 / 10);
  // Replaced only when D + lambda R falls, R in [4, 64] bits: no block gains more than
  // lambda * 60 of squared error, by the decoder's own reckoning.
  double d0 = 0, d1 = 0;
  for (uint32_t k = 0; k < blocks.size() / 8; ++k) {
    const double a = block_error(decode_bc1_block, &before[k * 8], img, k);
    const double b = block_error(decode_bc1_block, &blocks[k * 8], img, k);
    EXPECT_LT(b - a, o.lambda * 60 + 1e-9) << "block " << k;
    d0 += a;
    d1 += b;
  }
  EXPECT_DOUBLE_EQ(s.error_before, d0);
  EXPECT_DOUBLE_EQ(s.error_after, d1);
  // An image that is not a multiple of 4 (edge blocks' outside texels do not count), and errors.
  std::vector<uint8_t> edge(encode_bound(Format::kBc1, kW - 1, kH - 3));
  ASSERT_TRUE(
      encode_bc1({img.data(), kW - 1, kH - 3, kW * 4, 4}, edge.data(), edge.size(), {}).ok());
  std::vector<uint8_t> packed;  // the same texels, rows (kW - 1) * 4 apart
  for (uint32_t y = 0; y < kH - 3; ++y)
    packed.insert(packed.end(), img.begin() + y * kW * 4, img.begin() + (y * kW + kW - 1) * 4);
  EXPECT_TRUE(rdo_bc1(packed.data(), kW - 1, kH - 3, edge.data(), edge.size(), o).ok());
  EXPECT_EQ(rdo_bc1(img.data(), kW, kH, blocks.data(), blocks.size() - 1, o).id(),
            ErrorId::kBcBufferSize);
  o.lambda = std::nan("");
  EXPECT_EQ(rdo_bc1(img.data(), kW, kH, blocks.data(), blocks.size(), o).id(), ErrorId::kBcOptions);
}

TEST(BcRdo, Bc6hSmallerOnceCompressedAndRepeatable) {
  std::vector<float> rgb(kW * kH * 3);
  std::vector<uint16_t> half(rgb.size());
  std::mt19937 rng(3);
  for (uint32_t y = 0; y < kH; ++y) {
    for (uint32_t x = 0; x < kW; ++x) {
      for (int c = 0; c < 3; ++c) {
        const size_t i = (y * kW + x) * 3 + c;
        rgb[i] = (0.2f + 0.01f * x + 0.3f * c) * (1.0f + 0.02f * (rng() % 100) / 100.0f) *
                 (y > 30 ? 4.0f : 1.0f);
        half[i] = float_to_half(rgb[i]);
        rgb[i] = half_to_float(half[i]);  // the encoder's input is half floats
      }
    }
  }
  std::vector<uint8_t> before(encode_bound(Format::kBc6hUnsigned, kW, kH));
  Bc6hOptions eo;
  eo.quality = 0;
  ASSERT_TRUE(encode_bc6h({rgb.data(), kW, kH, kW * 3, 3}, before.data(), before.size(), eo).ok());
  BcRdoOptions o;
  o.lambda = 3;
  std::vector<uint8_t> a = before, b = before;
  BcRdoStats s;
  ASSERT_TRUE(rdo_bc6h(half.data(), kW, kH, a.data(), a.size(), o, &s).ok());
  ASSERT_TRUE(rdo_bc6h(half.data(), kW, kH, b.data(), b.size(), o).ok());
  EXPECT_EQ(a, b);  // deterministic
  EXPECT_GT(s.changed, 0u);
  EXPECT_GE(s.error_after, s.error_before);
  EXPECT_LT(zstd_size(a), zstd_size(before));
  // The decoded image stays close: mean relative error per channel below 3 %.
  std::vector<uint16_t> out(kW * kH * 3);
  ASSERT_TRUE(decode_image(Format::kBc6hUnsigned, a.data(), a.size(), kW, kH, out.data(),
                           out.size() * 2, kW * 6)
                  .ok());
  double rel = 0;
  for (size_t i = 0; i < out.size(); ++i) rel += std::fabs(half_to_float(out[i]) / rgb[i] - 1);
  EXPECT_LT(rel / out.size(), 0.03);
}

TEST(BcRdo, RefusesBadOptionsAndBuffers) {
  const std::vector<uint8_t> img = ldr_image();
  std::vector<uint8_t> blocks = bc7_of(img);
  BcRdoOptions o;
  o.lambda = -1;
  EXPECT_EQ(rdo_bc7(img.data(), kW, kH, blocks.data(), blocks.size(), o).id(), ErrorId::kBcOptions);
  o.lambda = 1;
  o.window = 0;
  EXPECT_EQ(rdo_bc7(img.data(), kW, kH, blocks.data(), blocks.size(), o).id(), ErrorId::kBcOptions);
  o.window = 8;
  EXPECT_EQ(rdo_bc7(img.data(), kW, kH, blocks.data(), blocks.size() - 1, o).id(),
            ErrorId::kBcBufferSize);
  EXPECT_EQ(rdo_bc6h(nullptr, kW, kH, blocks.data(), blocks.size(), o).id(),
            ErrorId::kBcBufferSize);
}

}  // namespace
}  // namespace calf::bc
