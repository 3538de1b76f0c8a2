// BC1 (S3TC DXT1) and BC4/BC5 (RGTC) block decoders.
//
// Rounding follows Mesa (src/util/format and mesa/main/texcompress_*): truncating integer
// division of the 8-bit expanded endpoints. The D3D specification only bounds the error of these
// interpolants, so GPUs differ in the last bit; docs/BLOCK_CODECS.md gives the bounds.
#include <cstring>

#include "calf/format/bc.h"

namespace calf::bc {
namespace {

uint32_t load_u16(const uint8_t* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8;
}
uint32_t load_u32(const uint8_t* p) {
  return load_u16(p) | load_u16(p + 2) << 16;
}

// 5:6:5 -> 8:8:8 by replicating the top bits into the low ones.
void expand565(uint32_t c, int* rgb) {
  const int r = static_cast<int>((c >> 11) & 31), g = static_cast<int>((c >> 5) & 63),
            b = static_cast<int>(c & 31);
  rgb[0] = (r << 3) | (r >> 2);
  rgb[1] = (g << 2) | (g >> 4);
  rgb[2] = (b << 3) | (b >> 2);
}

// The 8 levels of one BC4 block as ints; `is_signed` reads the endpoints as int8.
void bc4_palette(const uint8_t* block, bool is_signed, int* level) {
  const int a = is_signed ? static_cast<int8_t>(block[0]) : block[0];
  const int b = is_signed ? static_cast<int8_t>(block[1]) : block[1];
  level[0] = a;
  level[1] = b;
  if (a > b) {
    for (int i = 2; i < 8; ++i) level[i] = (a * (8 - i) + b * (i - 1)) / 7;
  } else {
    for (int i = 2; i < 6; ++i) level[i] = (a * (6 - i) + b * (i - 1)) / 5;
    level[6] = is_signed ? -128 : 0;
    level[7] = is_signed ? 127 : 255;
  }
}

// 16 three-bit selectors, little-endian from byte 2 of the block.
uint64_t bc4_selectors(const uint8_t* block) {
  uint64_t s = 0;
  for (int i = 0; i < 6; ++i) s |= uint64_t{block[2 + i]} << (8 * i);
  return s;
}

template <typename T>
void decode_bc4_into(const uint8_t* block, bool is_signed, T* out, int stride) {
  int level[8];
  bc4_palette(block, is_signed, level);
  const uint64_t s = bc4_selectors(block);
  for (int i = 0; i < 16; ++i) out[i * stride] = static_cast<T>(level[(s >> (3 * i)) & 7]);
}

}  // namespace

void decode_bc1_block(const uint8_t* block, uint8_t* rgba) {
  const uint32_t c0 = load_u16(block), c1 = load_u16(block + 2);
  const uint32_t idx = load_u32(block + 4);
  int p[4][4];
  expand565(c0, p[0]);
  expand565(c1, p[1]);
  p[0][3] = p[1][3] = p[2][3] = p[3][3] = 255;
  for (int c = 0; c < 3; ++c) {
    if (c0 > c1) {
      p[2][c] = (2 * p[0][c] + p[1][c]) / 3;
      p[3][c] = (p[0][c] + 2 * p[1][c]) / 3;
    } else {
      p[2][c] = (p[0][c] + p[1][c]) / 2;
      p[3][c] = 0;  // transparent black
    }
  }
  if (c0 <= c1) p[3][3] = 0;
  for (int i = 0; i < 16; ++i) {
    const int* q = p[(idx >> (2 * i)) & 3];
    for (int c = 0; c < 4; ++c) rgba[4 * i + c] = static_cast<uint8_t>(q[c]);
  }
}

void decode_bc4_block(const uint8_t* block, uint8_t* r) {
  decode_bc4_into(block, false, r, 1);
}
void decode_bc4s_block(const uint8_t* block, int8_t* r) {
  decode_bc4_into(block, true, r, 1);
}

void decode_bc5_block(const uint8_t* block, uint8_t* rg) {
  decode_bc4_into(block, false, rg, 2);
  decode_bc4_into(block + 8, false, rg + 1, 2);
}
void decode_bc5s_block(const uint8_t* block, int8_t* rg) {
  decode_bc4_into(block, true, rg, 2);
  decode_bc4_into(block + 8, true, rg + 1, 2);
}

}  // namespace calf::bc
