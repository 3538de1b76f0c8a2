// Tests of the BCn encoders (calf/encoder/bc_encode.h): extreme blocks (constant, two-colour,
// alpha; HDR NaN / Inf / negatives / 65504 / tiny values), argument errors, determinism across
// thread counts, and two-sided quality pins on a small fixed synthetic set — a pin fails when
// quality drops below its floor, and also when it rises well above it (tighten the pin then).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"

namespace calf::bc {
namespace {

constexpr uint32_t kSize = 64;

// The fixed LDR test set: smooth gradient, sines, hard edges, noise (64x64 RGBA each).
std::vector<std::vector<uint8_t>> ldr_set() {
  std::vector<std::vector<uint8_t>> set(4, std::vector<uint8_t>(kSize * kSize * 4, 255));
  std::mt19937 rng(1234);
  for (uint32_t y = 0; y < kSize; ++y) {
    for (uint32_t x = 0; x < kSize; ++x) {
      const size_t p = (y * kSize + x) * 4;
      set[0][p] = static_cast<uint8_t>(x * 4), set[0][p + 1] = static_cast<uint8_t>(y * 4);
      set[0][p + 2] = static_cast<uint8_t>(255 - (x + y) * 2);
      for (int c = 0; c < 3; ++c) {
        set[1][p + c] = static_cast<uint8_t>(127.5 + 120 * std::sin(0.11 * x * (c + 1) + 0.07 * y));
      }
      const bool a = (x * 3 + y * 5) % 37 < 18, b = (x / 8 + y / 8) % 2 == 0;
      set[2][p] = a ? 230 : 20, set[2][p + 1] = b ? 200 : 40, set[2][p + 2] = a != b ? 255 : 0;
      for (int c = 0; c < 3; ++c) set[3][p + c] = static_cast<uint8_t>(rng());
    }
  }
  return set;
}

double psnr_from_mse(double mse) {
  return mse <= 0 ? 99.0 : 10 * std::log10(255.0 * 255.0 / mse);
}

// PSNR over the channels [0, nc) of decoded `f` blocks against 4-channel source pixels.
double psnr(Format f, const std::vector<uint8_t>& blocks, const std::vector<uint8_t>& src, int nc) {
  const int tb = texel_bytes(f);
  std::vector<uint8_t> out(kSize * kSize * tb);
  EXPECT_TRUE(decode_image(f, blocks.data(), blocks.size(), kSize, kSize, out.data(), out.size(),
                           kSize * tb)
                  .ok());
  double se = 0;
  for (size_t i = 0; i < kSize * kSize; ++i)
    for (int c = 0; c < nc; ++c) se += std::pow(double(out[i * tb + c]) - src[i * 4 + c], 2);
  return psnr_from_mse(se / (kSize * kSize * nc));
}

std::vector<uint8_t> encode8(Format f, const std::vector<uint8_t>& src, int quality,
                             int threads = 1) {
  std::vector<uint8_t> blocks(encode_bound(f, kSize, kSize));
  const Image8 img{src.data(), kSize, kSize, kSize * 4, 4};
  Status st;
  switch (f) {
    case Format::kBc1:
      st = encode_bc1(img, blocks.data(), blocks.size(), {quality, false, threads});
      break;
    case Format::kBc4:
      st = encode_bc4(img, blocks.data(), blocks.size(), {quality, threads});
      break;
    case Format::kBc5:
      st = encode_bc5(img, blocks.data(), blocks.size(), {quality, threads});
      break;
    default:
      st = encode_bc7(img, blocks.data(), blocks.size(), {quality, threads});
      break;
  }
  EXPECT_TRUE(st.ok()) << st.to_string();
  return blocks;
}

// Mean PSNR over the LDR set.
double mean_psnr(Format f, int quality) {
  double sum = 0;
  const int nc = f == Format::kBc4 ? 1 : f == Format::kBc5 ? 2 : 3;
  for (const auto& img : ldr_set()) sum += psnr(f, encode8(f, img, quality), img, nc);
  return sum / 4;
}

// Two-sided pin: fails below `floor`, and reminds to tighten when more than `slack` dB above.
void expect_pinned(double value, double floor, const char* what, double slack = 1.5) {
  std::printf("%-28s %.2f dB (pin %.2f)\n", what, value, floor);
  EXPECT_GE(value, floor) << what << " got worse";
  EXPECT_LE(value, floor + slack) << what << " improved: raise its pin to " << value - 0.2;
}

TEST(BcQuality, LdrPins) {
  expect_pinned(mean_psnr(Format::kBc1, 0), 30.4, "BC1 range fit");
  expect_pinned(mean_psnr(Format::kBc1, 1), 31.5, "BC1 cluster fit");
  expect_pinned(mean_psnr(Format::kBc4, 0), 56.2, "BC4 squish");
  expect_pinned(mean_psnr(Format::kBc4, 1), 67.6, "BC4 refined");
  expect_pinned(mean_psnr(Format::kBc5, 0), 55.5, "BC5 squish");
  expect_pinned(mean_psnr(Format::kBc7, 0), 38.8, "BC7 q0");
  expect_pinned(mean_psnr(Format::kBc7, 1), 39.3, "BC7 q1");
  expect_pinned(mean_psnr(Format::kBc7, 2), 39.8, "BC7 q2");
}

// BC1's least-squares refinement (Bc1Options::refine): on the fixed set it lands between range
// and cluster fit (pinned), and no block comes out worse than the range fit made it, by the
// decoder's reckoning, with the random-noise image too.
TEST(BcQuality, Bc1RefineImprovesOnRangeFitAndNeverWorsensABlock) {
  double sum = 0;
  size_t better = 0, blocks = 0;
  for (const auto& img : ldr_set()) {
    std::vector<uint8_t> range(encode_bound(Format::kBc1, kSize, kSize));
    std::vector<uint8_t> refined(range.size());
    const Image8 src{img.data(), kSize, kSize, kSize * 4, 4};
    ASSERT_TRUE(encode_bc1(src, range.data(), range.size(), {}).ok());
    Bc1Options o;
    o.refine = true;
    ASSERT_TRUE(encode_bc1(src, refined.data(), refined.size(), o).ok());
    sum += psnr(Format::kBc1, refined, img, 3);
    for (size_t b = 0; b < range.size() / 8; ++b, ++blocks) {
      const uint32_t bx = static_cast<uint32_t>(b % (kSize / 4)),
                     by = static_cast<uint32_t>(b / (kSize / 4));
      uint8_t a[64], r[64];
      decode_bc1_block(&range[8 * b], a);
      decode_bc1_block(&refined[8 * b], r);
      long ea = 0, er = 0;
      for (int i = 0; i < 16; ++i) {
        const size_t p = ((by * 4 + i / 4) * kSize + bx * 4 + i % 4) * 4;
        for (int c = 0; c < 3; ++c) {
          ea += (a[4 * i + c] - img[p + c]) * (a[4 * i + c] - img[p + c]);
          er += (r[4 * i + c] - img[p + c]) * (r[4 * i + c] - img[p + c]);
        }
      }
      ASSERT_LE(er, ea) << "block " << b;
      better += er < ea;
    }
  }
  expect_pinned(sum / 4, 31.5, "BC1 range fit refined");
  EXPECT_LT(sum / 4, mean_psnr(Format::kBc1, 1));  // cluster fit stays ahead
  EXPECT_GT(better * 4, blocks);                   // more than a quarter of the blocks gain
}

TEST(BcQuality, Bc7AtLeast3dBAboveBc1RangeFit) {
  EXPECT_GE(mean_psnr(Format::kBc7, 1) - mean_psnr(Format::kBc1, 0), 3.0);
  EXPECT_GE(mean_psnr(Format::kBc7, 0) - mean_psnr(Format::kBc1, 0), 3.0);
}

// ---- HDR ----

// The HDR set: 64x64 RGB float images spanning 2^-10..2^14.
std::vector<std::vector<float>> hdr_set() {
  std::vector<std::vector<float>> set(3, std::vector<float>(kSize * kSize * 3));
  std::mt19937 rng(99);
  std::uniform_real_distribution<float> u(-10, 14);
  for (uint32_t y = 0; y < kSize; ++y) {
    for (uint32_t x = 0; x < kSize; ++x) {
      const size_t p = (y * kSize + x) * 3;
      for (int c = 0; c < 3; ++c) {
        set[0][p + c] = std::exp2(-10.0f + 24.0f * x / kSize + 0.5f * c) * (1 + y / 64.0f);
        set[1][p + c] = ((x / 5 + y / 7) % 2) ? 2000.0f * (c + 1) : 0.01f * (3 - c);
        set[2][p + c] = std::exp2(u(rng));
      }
    }
  }
  return set;
}

// PSNR on log2 values (floored at 2^-14), with the reference's log2 range as the peak: an
// error of one stop over a 24-stop image is about 27.6 dB. Named "log2-PSNR" in reports.
double log2_psnr(const std::vector<float>& ref, const std::vector<uint16_t>& halves,
                 bool is_signed) {
  double lo = 1e9, hi = -1e9, se = 0;
  auto l2 = [](float v) { return std::log2(std::max(std::fabs(v), 0x1p-14f)); };
  for (float v : ref) lo = std::min(lo, double(l2(v))), hi = std::max(hi, double(l2(v)));
  for (size_t i = 0; i < ref.size(); ++i) {
    const float d = half_to_float(halves[i]);
    se += std::pow(l2(d) - l2(ref[i]), 2) + ((d < 0) != (ref[i] < 0) && is_signed ? 1.0 : 0.0);
  }
  const double mse = se / ref.size();
  return mse <= 0 ? 99.0 : 10 * std::log10((hi - lo) * (hi - lo) / mse);
}

std::vector<uint16_t> roundtrip_hdr(const std::vector<float>& img, const Bc6hOptions& o) {
  const Format f = o.is_signed ? Format::kBc6hSigned : Format::kBc6hUnsigned;
  std::vector<uint8_t> blocks(encode_bound(f, kSize, kSize));
  const Status st =
      encode_bc6h({img.data(), kSize, kSize, kSize * 3, 3}, blocks.data(), blocks.size(), o);
  EXPECT_TRUE(st.ok()) << st.to_string();
  std::vector<uint16_t> out(kSize * kSize * 3);
  EXPECT_TRUE(decode_image(f, blocks.data(), blocks.size(), kSize, kSize, out.data(),
                           out.size() * 2, kSize * 6)
                  .ok());
  return out;
}

TEST(BcQuality, HdrPins) {
  for (int q = 0; q <= 2; ++q) {
    double sum = 0;
    for (const auto& img : hdr_set()) {
      Bc6hOptions o;
      o.quality = q;
      sum += log2_psnr(img, roundtrip_hdr(img, o), false);
    }
    const double pins[3] = {49.2, 49.3, 49.3};
    char what[64];
    std::snprintf(what, sizeof what, "BC6H_UF16 q%d log2-PSNR", q);
    expect_pinned(sum / 3, pins[q], what);
  }
}

TEST(BcHdr, ExtremesClampAsDocumented) {
  const float inf = std::numeric_limits<float>::infinity();
  const float values[] = {std::nanf(""), inf, -inf, -5.0f, 65504.0f, 1e6f, 0x1p-24f, 1e-10f};
  // unsigned: NaN->0, +Inf->65504, -Inf->0, -5->0, 65504, 1e6->65504, 2^-24 kept, 1e-10 -> 0
  const uint16_t want_u[] = {0, 0x7bff, 0, 0, 0x7bff, 0x7bff, 0x0001, 0};
  const uint16_t want_s[] = {0, 0x7bff, 0xfbff, 0xc500, 0x7bff, 0x7bff, 0x0001, 0};
  for (size_t i = 0; i < std::size(values); ++i) {
    EXPECT_EQ(bc6h_clamp_to_half(values[i], false), want_u[i]) << i;
    EXPECT_EQ(bc6h_clamp_to_half(values[i], true), want_s[i]) << i;
  }
  // A constant block of each extreme: the decoded value is the clamped one, within 1 ulp-ish
  // (BC6H cannot hit every half exactly: the stored endpoint is 10..16 bits).
  for (bool is_signed : {false, true}) {
    for (size_t i = 0; i < std::size(values); ++i) {
      float px[48];
      std::fill(px, px + 48, values[i]);
      Bc6hOptions o;
      o.is_signed = is_signed;
      uint8_t block[16];
      encode_bc6h_block(px, block, o);
      uint16_t rgb[48];
      decode_bc6h_block(block, is_signed, rgb);
      const uint16_t want = is_signed ? want_s[i] : want_u[i];
      for (uint16_t h : rgb) {
        const int a = (want & 0x8000) ? -(want & 0x7fff) : want;
        const int b = (h & 0x8000) ? -(h & 0x7fff) : h;
        EXPECT_LE(std::abs(a - b), 1) << "value " << values[i] << " signed " << is_signed;
      }
    }
  }
}

TEST(BcHdr, RejectPolicyNamesThePixel) {
  std::vector<float> img(8 * 8 * 3, 1.0f);
  std::vector<uint8_t> out(64);
  Bc6hOptions o;
  o.policy = HdrPolicy::kReject;
  EXPECT_TRUE(encode_bc6h({img.data(), 8, 8, 24, 3}, out.data(), out.size(), o).ok());
  img[(3 * 8 + 5) * 3 + 1] = std::nanf("");
  Status st = encode_bc6h({img.data(), 8, 8, 24, 3}, out.data(), out.size(), o);
  EXPECT_EQ(st.id(), ErrorId::kBcNonFinite);
  EXPECT_NE(st.message().find("pixel (5, 3) channel 1"), std::string::npos) << st.message();
  img[(3 * 8 + 5) * 3 + 1] = -1.0f;
  EXPECT_EQ(encode_bc6h({img.data(), 8, 8, 24, 3}, out.data(), out.size(), o).id(),
            ErrorId::kBcOutOfRange);
  o.is_signed = true;
  EXPECT_TRUE(encode_bc6h({img.data(), 8, 8, 24, 3}, out.data(), out.size(), o).ok());
  img[0] = 70000.0f;
  EXPECT_EQ(encode_bc6h({img.data(), 8, 8, 24, 3}, out.data(), out.size(), o).id(),
            ErrorId::kBcOutOfRange);
}

TEST(BcHdr, SignedKeepsNegatives) {
  float px[48];
  for (int i = 0; i < 16; ++i)
    for (int c = 0; c < 3; ++c)
      px[3 * i + c] = (i % 2 ? -1.0f : 1.0f) * std::exp2(float(i - 8 + c));
  Bc6hOptions o;
  o.is_signed = true;
  o.quality = 2;
  uint8_t block[16];
  encode_bc6h_block(px, block, o);
  uint16_t rgb[48];
  decode_bc6h_block(block, true, rgb);
  for (int i = 0; i < 48; ++i) {
    EXPECT_EQ(half_to_float(rgb[i]) < 0, px[i] < 0) << i;
  }
}

// ---- LDR extremes ----

TEST(BcLdr, ConstantBlocks) {
  std::mt19937 rng(77);
  for (int k = 0; k < 200; ++k) {
    uint8_t px[64];
    const uint8_t col[4] = {static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()),
                            static_cast<uint8_t>(rng()), 255};
    for (int i = 0; i < 16; ++i) std::copy(col, col + 4, px + 4 * i);
    uint8_t b7[16], b1[8], b4[8], out[64], r[16];
    encode_bc7_block(px, b7, {});
    decode_bc7_block(b7, out);
    for (int i = 0; i < 64; ++i) EXPECT_LE(std::abs(out[i] - px[i]), 1) << "BC7 " << i;
    encode_bc1_block(px, b1, {});
    decode_bc1_block(b1, out);
    // BC1: 5:6:5 endpoints and thirds: at most 4 levels off per channel for a constant colour.
    for (int i = 0; i < 64; ++i) EXPECT_LE(std::abs(out[i] - px[i]), 4) << "BC1 " << i;
    uint8_t red[16];
    for (int i = 0; i < 16; ++i) red[i] = col[0];
    encode_bc4_block(red, b4, {});
    decode_bc4_block(b4, r);
    for (int i = 0; i < 16; ++i) EXPECT_EQ(r[i], col[0]) << "BC4";
  }
}

TEST(BcLdr, TwoColourBlocksAreNearExactInBc7) {
  std::mt19937 rng(5);
  for (int k = 0; k < 100; ++k) {
    uint8_t a[4] = {static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()),
                    static_cast<uint8_t>(rng()), 255};
    uint8_t b[4] = {static_cast<uint8_t>(rng()), static_cast<uint8_t>(rng()),
                    static_cast<uint8_t>(rng()), 255};
    uint8_t px[64];
    for (int i = 0; i < 16; ++i)
      std::copy((i % 4) < 2 ? a : b, ((i % 4) < 2 ? a : b) + 4, px + 4 * i);
    uint8_t blk[16], out[64];
    encode_bc7_block(px, blk, {});
    decode_bc7_block(blk, out);
    for (int i = 0; i < 64; ++i) EXPECT_LE(std::abs(out[i] - px[i]), 2) << k << " " << i;
  }
}

TEST(BcLdr, AlphaIsKeptByBc7AndPunchedThroughByBc1) {
  uint8_t px[64];
  for (int i = 0; i < 16; ++i) {
    px[4 * i] = 200, px[4 * i + 1] = 100, px[4 * i + 2] = 50;
    px[4 * i + 3] = static_cast<uint8_t>(i * 17);
  }
  for (int q = 0; q <= 2; ++q) {
    uint8_t blk[16], out[64];
    encode_bc7_block(px, blk, {q, 1});
    decode_bc7_block(blk, out);
    for (int i = 0; i < 16; ++i) EXPECT_LE(std::abs(out[4 * i + 3] - px[4 * i + 3]), 3) << q;
  }
  uint8_t b1[8], out[64];
  encode_bc1_block(px, b1, {0, true, 1});
  decode_bc1_block(b1, out);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(out[4 * i + 3], px[4 * i + 3] < 128 ? 0 : 255) << i;
  encode_bc1_block(px, b1, {0, false, 1});
  decode_bc1_block(b1, out);
  for (int i = 0; i < 16; ++i) EXPECT_EQ(out[4 * i + 3], 255) << i;
}

// ---- API ----

TEST(BcApi, DeterministicAcrossThreadCounts) {
  const auto img = ldr_set()[1];
  for (Format f : {Format::kBc1, Format::kBc4, Format::kBc5, Format::kBc7}) {
    const auto one = encode8(f, img, 1, 1);
    EXPECT_EQ(one, encode8(f, img, 1, 2)) << format_name(f);
    EXPECT_EQ(one, encode8(f, img, 1, 0)) << format_name(f);
  }
  const auto hdr = hdr_set()[2];
  Bc6hOptions o;
  const auto a = roundtrip_hdr(hdr, o);
  o.threads = 3;
  EXPECT_EQ(a, roundtrip_hdr(hdr, o));
}

TEST(BcApi, ArgumentErrors) {
  std::vector<uint8_t> px(8 * 8 * 4), out(256);
  const Image8 img{px.data(), 8, 8, 32, 4};
  EXPECT_TRUE(encode_bc7(img, out.data(), 64, {}).ok());
  EXPECT_EQ(encode_bc7(img, out.data(), 63, {}).id(), ErrorId::kBcBufferSize);
  EXPECT_EQ(encode_bc7({px.data(), 8, 8, 31, 4}, out.data(), 64, {}).id(), ErrorId::kBcStride);
  EXPECT_EQ(encode_bc7({px.data(), 0, 8, 32, 4}, out.data(), 64, {}).id(), ErrorId::kBcDimensions);
  EXPECT_EQ(encode_bc7(img, out.data(), 64, {3, 1}).id(), ErrorId::kBcOptions);
  EXPECT_EQ(encode_bc1(img, out.data(), 64, {0, false, -1}).id(), ErrorId::kBcOptions);
  EXPECT_EQ(encode_bc5({px.data(), 8, 8, 8, 1}, out.data(), 64, {}).id(), ErrorId::kBcOptions);
  EXPECT_EQ(encode_bc7({nullptr, 8, 8, 32, 4}, out.data(), 64, {}).id(), ErrorId::kBcBufferSize);
  EXPECT_EQ(encode_bound(Format::kBc1, 5, 5), 32u);
  EXPECT_EQ(encode_bound(Format::kBc7, 0, 5), 0u);
}

TEST(BcApi, PartialBlocksClampToTheEdge) {
  // A 5x5 image whose last column and row are a different colour: the edge blocks must
  // reproduce it (they see only copies of it in their missing texels).
  std::vector<uint8_t> px(5 * 5 * 4, 0);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 5; ++x) {
      uint8_t* p = &px[(y * 5 + x) * 4];
      p[0] = (x == 4 || y == 4) ? 250 : 10, p[1] = 128, p[2] = 30, p[3] = 255;
    }
  std::vector<uint8_t> blocks(encode_bound(Format::kBc7, 5, 5)), out(5 * 5 * 4);
  ASSERT_TRUE(encode_bc7({px.data(), 5, 5, 20, 4}, blocks.data(), blocks.size(), {}).ok());
  ASSERT_TRUE(
      decode_image(Format::kBc7, blocks.data(), blocks.size(), 5, 5, out.data(), out.size(), 20)
          .ok());
  for (size_t i = 0; i < px.size(); ++i) EXPECT_LE(std::abs(px[i] - out[i]), 2) << i;
}

}  // namespace
}  // namespace calf::bc
