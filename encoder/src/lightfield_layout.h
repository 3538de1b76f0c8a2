// Byte-level helpers of the lightfield chunk layout (format/SPEC.md §11.1), writer side. The
// reader side lives in decoder/src/lightfield_reference.cc (the decoder may not link the encoder);
// tests/integration/lightfield_roundtrip_test.cc keeps the two in agreement.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace calf::lf {

inline void put_u16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v));
  out.push_back(static_cast<uint8_t>(v >> 8));
}
inline void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_u64(std::vector<uint8_t>& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_f32(std::vector<uint8_t>& out, float f) {
  uint32_t v;
  std::memcpy(&v, &f, 4);
  put_u32(out, v);
}
inline void put_f64(std::vector<uint8_t>& out, double f) {
  uint64_t v;
  std::memcpy(&v, &f, 8);
  put_u64(out, v);
}

// Appends `blocks` (whole BCn blocks) split into their endpoint part and their index part
// (§11.1 "Block split"): BC1 (8-byte blocks) = bytes 0-3 of every block, then bytes 4-7 of every
// block; BC5 (16-byte blocks, two BC4 halves) = bytes 0,1,8,9 of every block, then bytes 2-7,
// 10-15 of every block. Other formats are appended unchanged.
inline void append_block_split(std::vector<uint8_t>& out, std::span<const uint8_t> blocks,
                               size_t block_bytes, bool is_bc5) {
  if (block_bytes == 8) {
    const size_t n = blocks.size() / 8;
    for (size_t b = 0; b < n; ++b) out.insert(out.end(), &blocks[b * 8], &blocks[b * 8] + 4);
    for (size_t b = 0; b < n; ++b) out.insert(out.end(), &blocks[b * 8 + 4], &blocks[b * 8] + 8);
  } else if (is_bc5) {
    const size_t n = blocks.size() / 16;
    for (size_t b = 0; b < n; ++b) {
      const uint8_t* p = &blocks[b * 16];
      out.insert(out.end(), {p[0], p[1], p[8], p[9]});
    }
    for (size_t b = 0; b < n; ++b) {
      const uint8_t* p = &blocks[b * 16];
      out.insert(out.end(), p + 2, p + 8);
      out.insert(out.end(), p + 10, p + 16);
    }
  } else {
    out.insert(out.end(), blocks.begin(), blocks.end());
  }
}

// Appends `texels` of `bytes_per_texel` interleaved bytes as planes: byte 0 of every texel, then
// byte 1 of every texel, ... (§11.1 "Byte planes").
inline void append_planes(std::vector<uint8_t>& out, std::span<const uint8_t> texels,
                          size_t bytes_per_texel) {
  const size_t n = texels.size() / bytes_per_texel;
  for (size_t c = 0; c < bytes_per_texel; ++c) {
    for (size_t i = 0; i < n; ++i) out.push_back(texels[i * bytes_per_texel + c]);
  }
}

}  // namespace calf::lf
