// Shared by bc_mesa_reference_test.cc and bc_mesa_llvmpipe_test.cc: cross-check of calf's CPU
// block decoders against an independent decoder, Mesa's, through OSMesa. Blocks are uploaded
// with glCompressedTexImage2D and read back with glGetTexImage (which Mesa implements as a blit,
// i.e. by sampling the texture with the selected Gallium driver).
//
// Each format is checked on 100 000 random blocks (half uniformly random bytes, half with the
// mode field forced so that every BC6H/BC7 mode is exercised equally), on extreme blocks (every
// first byte over constant fills) and on blocks produced by calf's encoders.
//
// The including test defines CALF_GALLIUM_DRIVER and kTolerance(Format) before including this.
#pragma once
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"

namespace calf::bc {
namespace {

constexpr int kRandomBlocks = 100000;

class MesaContext {
 public:
  MesaContext() {
    // The Gallium driver is chosen when OSMesa creates its screen (the first context).
    setenv("GALLIUM_DRIVER", CALF_GALLIUM_DRIVER, 1);
    const int attribs[] = {
        OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_COMPAT_PROFILE, 0};
    ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx_) return;
    buffer_.resize(16 * 16 * 4);
    ok_ = OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, 16, 16);
    if (ok_) renderer_ = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  }
  const std::string& renderer() const { return renderer_; }
  ~MesaContext() {
    if (ctx_) OSMesaDestroyContext(ctx_);
  }
  bool ok() const { return ok_; }

 private:
  OSMesaContext ctx_ = nullptr;
  std::vector<unsigned char> buffer_;
  bool ok_ = false;
  std::string renderer_;
};

MesaContext& context() {
  static MesaContext ctx;
  return ctx;
}

GLenum gl_format_of(Format f) {
  switch (f) {
    case Format::kBc1:
      return GL_COMPRESSED_RGBA_S3TC_DXT1_EXT;
    case Format::kBc4:
      return GL_COMPRESSED_RED_RGTC1;
    case Format::kBc5:
      return GL_COMPRESSED_RG_RGTC2;
    case Format::kBc4Signed:
      return GL_COMPRESSED_SIGNED_RED_RGTC1;
    case Format::kBc5Signed:
      return GL_COMPRESSED_SIGNED_RG_RGTC2;
    case Format::kBc6hUnsigned:
      return GL_COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT;
    case Format::kBc6hSigned:
      return GL_COMPRESSED_RGB_BPTC_SIGNED_FLOAT;
    case Format::kBc7:
      return GL_COMPRESSED_RGBA_BPTC_UNORM;
  }
  return 0;
}

// Uploads `blocks` (n blocks, laid out 256 blocks per row) and reads the texels back in the
// decoder's own output type: RGBA8 / R8 / RG8 / RGB half; signed RGTC as float.
struct Readback {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> bytes;  // unorm formats and BC6H halves
  std::vector<float> floats;   // signed RGTC, and BC6H as float
};

Readback mesa_decode(Format f, const std::vector<uint8_t>& blocks) {
  const size_t bb = block_bytes(f);
  const size_t n = blocks.size() / bb;
  const uint32_t bw = static_cast<uint32_t>(std::min<size_t>(n, 256));
  const uint32_t bh = static_cast<uint32_t>((n + bw - 1) / bw);
  std::vector<uint8_t> padded(size_t{bw} * bh * bb, 0);
  std::memcpy(padded.data(), blocks.data(), blocks.size());
  Readback rb;
  rb.width = bw * 4;
  rb.height = bh * 4;
  GLuint tex = 0;
  glGenTextures(1, &tex);
  glBindTexture(GL_TEXTURE_2D, tex);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glCompressedTexImage2D(GL_TEXTURE_2D, 0, gl_format_of(f), static_cast<GLsizei>(rb.width),
                         static_cast<GLsizei>(rb.height), 0, static_cast<GLsizei>(padded.size()),
                         padded.data());
  const size_t texels = size_t{rb.width} * rb.height;
  switch (f) {
    case Format::kBc1:
    case Format::kBc7:
      rb.bytes.resize(texels * 4);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, rb.bytes.data());
      break;
    case Format::kBc4:
      rb.bytes.resize(texels);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_UNSIGNED_BYTE, rb.bytes.data());
      break;
    case Format::kBc5:
      rb.bytes.resize(texels * 2);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RG, GL_UNSIGNED_BYTE, rb.bytes.data());
      break;
    case Format::kBc4Signed:
      rb.floats.resize(texels);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_FLOAT, rb.floats.data());
      break;
    case Format::kBc5Signed:
      rb.floats.resize(texels * 2);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RG, GL_FLOAT, rb.floats.data());
      break;
    case Format::kBc6hUnsigned:
    case Format::kBc6hSigned:
      rb.bytes.resize(texels * 6);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RGB, GL_HALF_FLOAT, rb.bytes.data());
      rb.floats.resize(texels * 3);
      glGetTexImage(GL_TEXTURE_2D, 0, GL_RGB, GL_FLOAT, rb.floats.data());
      break;
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR)) << format_name(f);
  glDeleteTextures(1, &tex);
  return rb;
}

// Decodes every block on the CPU and compares texel by texel with Mesa, allowing values to differ
// by up to kTolerance(f) (in units of the last place: 8-bit steps, or 1/127 for signed RGTC).
// Returns the number of blocks beyond that; prints the first few. `max_diff` gets the largest
// difference seen.
int compare_with_mesa(Format f, const std::vector<uint8_t>& blocks, int* max_diff = nullptr) {
  const int tol = kTolerance(f);
  int worst = 0;
  const Readback rb = mesa_decode(f, blocks);
  const size_t bb = block_bytes(f);
  const int tb = texel_bytes(f), nc = channels(f);
  const uint32_t bw = rb.width / 4;
  int bad_blocks = 0;
  for (size_t b = 0; b * bb < blocks.size(); ++b) {
    uint8_t cpu[16 * 8];
    decode_block(f, blocks.data() + b * bb, cpu);
    const size_t bx = b % bw, by = b / bw;
    bool bad = false;
    for (int i = 0; i < 16 && !bad; ++i) {
      const size_t t = (by * 4 + i / 4) * rb.width + bx * 4 + i % 4;
      if (f == Format::kBc4Signed || f == Format::kBc5Signed) {
        for (int c = 0; c < nc; ++c) {
          const float want = std::max(static_cast<int8_t>(cpu[i * nc + c]) / 127.0f, -1.0f);
          const int d =
              static_cast<int>(std::lround(std::fabs(rb.floats[t * nc + c] - want) * 127));
          worst = std::max(worst, d);
          if (d > tol || (tol == 0 && rb.floats[t * nc + c] != want)) bad = true;
        }
      } else if (f == Format::kBc6hUnsigned || f == Format::kBc6hSigned) {
        uint16_t h[3];
        std::memcpy(h, cpu + i * tb, 6);
        for (int c = 0; c < 3; ++c) {
          uint16_t mesa_half;
          std::memcpy(&mesa_half, rb.bytes.data() + t * 6 + 2 * c, 2);
          if (mesa_half != h[c] || rb.floats[t * 3 + c] != half_to_float(h[c])) bad = true;
        }
      } else {
        for (int c = 0; c < tb; ++c) {
          const int d = std::abs(int{cpu[i * tb + c]} - int{rb.bytes[t * tb + c]});
          worst = std::max(worst, d);
          if (d > tol) bad = true;
        }
      }
    }
    if (bad && ++bad_blocks <= 3) {
      std::string hex;
      for (size_t k = 0; k < bb; ++k) {
        char s[4];
        std::snprintf(s, sizeof s, "%02x", blocks[b * bb + k]);
        hex += s;
      }
      ADD_FAILURE() << format_name(f) << " block " << b << " (" << hex << ") differs from Mesa";
    }
  }
  if (max_diff) *max_diff = worst;
  return bad_blocks;
}

// 100 000 blocks: even ones uniformly random, odd ones with the mode forced round-robin.
std::vector<uint8_t> random_blocks(Format f, uint64_t seed) {
  std::mt19937_64 rng(seed);
  const size_t bb = block_bytes(f);
  std::vector<uint8_t> out(kRandomBlocks * bb);
  for (auto& b : out) b = static_cast<uint8_t>(rng());
  for (int k = 1; k < kRandomBlocks; k += 2) {
    uint8_t& b0 = out[k * bb];
    const int r = (k / 2);
    if (f == Format::kBc7) {
      const int mode = r % 9;  // 8 = the reserved all-zero mode byte
      b0 = mode == 8 ? 0 : static_cast<uint8_t>(((b0 << (mode + 1)) | (1u << mode)) & 0xff);
    } else if (f == Format::kBc6hUnsigned || f == Format::kBc6hSigned) {
      static const uint8_t kModes[] = {0,  1, 2, 6,  10, 14, 18, 22, 26,
                                       30, 3, 7, 11, 15, 19, 23, 27, 31};
      const uint8_t m = kModes[r % 18];
      b0 = static_cast<uint8_t>(m < 2 ? ((b0 & ~3u) | m) : ((b0 & ~31u) | m));
    } else if (f == Format::kBc1) {
      // Force both colour orders and the equal-endpoint case.
      if (r % 3 == 2) std::memcpy(&out[k * bb + 2], &out[k * bb], 2);
    } else {
      // BC4/BC5: force equal endpoints now and then.
      if (r % 4 == 3) out[k * bb + 1] = out[k * bb];
    }
  }
  return out;
}

class BcMesaTest : public ::testing::TestWithParam<Format> {
 protected:
  void SetUp() override {
    if (!context().ok()) GTEST_SKIP() << "no OSMesa context";
    // Make sure the driver asked for is the one running (Mesa falls back silently otherwise).
    ASSERT_NE(context().renderer().find(CALF_GALLIUM_DRIVER), std::string::npos)
        << context().renderer();
  }
};

TEST_P(BcMesaTest, RandomBlocksAgree) {
  const Format f = GetParam();
  int max_diff = 0;
  EXPECT_EQ(compare_with_mesa(f, random_blocks(f, 0xca1f0000u + static_cast<int>(f)), &max_diff),
            0);
  std::printf("%s vs Mesa %s: largest difference %d (allowed %d)\n", format_name(f),
              CALF_GALLIUM_DRIVER, max_diff, kTolerance(f));
}

TEST_P(BcMesaTest, ExtremeBlocksAgree) {
  const Format f = GetParam();
  const size_t bb = block_bytes(f);
  std::vector<uint8_t> blocks;
  for (int pattern : {0x00, 0xff, 0x55, 0xaa, 0x80, 0x7f, 0x01, 0xfe}) {
    blocks.insert(blocks.end(), bb, static_cast<uint8_t>(pattern));
    // and with every possible first byte (all BC6H/BC7 modes, both BC1 orders)
    for (int first = 0; first < 256; ++first) {
      std::vector<uint8_t> b(bb, static_cast<uint8_t>(pattern));
      b[0] = static_cast<uint8_t>(first);
      blocks.insert(blocks.end(), b.begin(), b.end());
    }
  }
  EXPECT_EQ(compare_with_mesa(f, blocks), 0);
}

TEST_P(BcMesaTest, EncodedBlocksAgree) {
  const Format f = GetParam();
  if (f == Format::kBc4Signed || f == Format::kBc5Signed) GTEST_SKIP() << "no signed encoder";
  // A 64x64 synthetic image: gradients, noise, hard edges, flat areas; then encoded.
  const uint32_t w = 64, h = 64;
  std::mt19937 rng(7);
  std::vector<uint8_t> rgba(w * h * 4);
  std::vector<float> rgbf(w * h * 3);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      uint8_t* p = &rgba[(y * w + x) * 4];
      const int region = (x / 16) + 4 * (y / 32);
      for (int c = 0; c < 4; ++c) {
        int v;
        switch (region % 4) {
          case 0:
            v = static_cast<int>((x * 4 + c * 40 + y) & 255);
            break;
          case 1:
            v = static_cast<int>(rng() & 255);
            break;
          case 2:
            v = ((x + y) % 8 < 4) ? 250 : 10;
            break;
          default:
            v = 128;
            break;
        }
        p[c] = static_cast<uint8_t>(c == 3 && region < 4 ? 255 : v);
      }
      for (int c = 0; c < 3; ++c) {
        rgbf[(y * w + x) * 3 + c] = std::exp2((p[c] - 128) / 16.0f) *
                                    (f == Format::kBc6hSigned && region == 5 ? -1.f : 1.f);
      }
    }
  }
  std::vector<uint8_t> blocks(*compressed_size(f, w, h));
  Status st;
  switch (f) {
    case Format::kBc1:
      st = encode_bc1({rgba.data(), w, h, w * 4, 4}, blocks.data(), blocks.size(), {});
      break;
    case Format::kBc4:
      st = encode_bc4({rgba.data(), w, h, w * 4, 4}, blocks.data(), blocks.size(), {});
      break;
    case Format::kBc5:
      st = encode_bc5({rgba.data(), w, h, w * 4, 4}, blocks.data(), blocks.size(), {});
      break;
    case Format::kBc7:
      st = encode_bc7({rgba.data(), w, h, w * 4, 4}, blocks.data(), blocks.size(), {});
      break;
    default: {
      Bc6hOptions o;
      o.is_signed = f == Format::kBc6hSigned;
      st = encode_bc6h({rgbf.data(), w, h, w * 3, 3}, blocks.data(), blocks.size(), o);
    }
  }
  ASSERT_TRUE(st.ok()) << st.to_string();
  EXPECT_EQ(compare_with_mesa(f, blocks), 0);
}

INSTANTIATE_TEST_SUITE_P(
    AllFormats, BcMesaTest,
    ::testing::Values(Format::kBc1, Format::kBc4, Format::kBc5, Format::kBc4Signed,
                      Format::kBc5Signed, Format::kBc6hUnsigned, Format::kBc6hSigned, Format::kBc7),
    [](const ::testing::TestParamInfo<Format>& p) { return std::string(format_name(p.param)); });

}  // namespace
}  // namespace calf::bc
