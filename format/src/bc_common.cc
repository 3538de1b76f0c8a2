// BCn shared pieces: sizes, the image-level decode driver, half-float conversion.
#include <algorithm>
#include <bit>
#include <cstring>
#include <string>

#include "calf/format/bc.h"

namespace calf::bc {

const char* format_name(Format f) {
  switch (f) {
    case Format::kBc1:
      return "BC1";
    case Format::kBc4:
      return "BC4";
    case Format::kBc5:
      return "BC5";
    case Format::kBc4Signed:
      return "BC4_SNORM";
    case Format::kBc5Signed:
      return "BC5_SNORM";
    case Format::kBc6hUnsigned:
      return "BC6H_UF16";
    case Format::kBc6hSigned:
      return "BC6H_SF16";
    case Format::kBc7:
      return "BC7";
  }
  return "BC?";
}

Expected<size_t> compressed_size(Format f, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0 || width > kMaxDimension || height > kMaxDimension) {
    return Status(ErrorId::kBcDimensions, std::string(format_name(f)) + " image " +
                                              std::to_string(width) + "x" + std::to_string(height) +
                                              ": expected 1..65536");
  }
  return size_t{blocks_along(width)} * blocks_along(height) * block_bytes(f);
}

void decode_block(Format f, const uint8_t* block, void* out) {
  switch (f) {
    case Format::kBc1:
      decode_bc1_block(block, static_cast<uint8_t*>(out));
      return;
    case Format::kBc4:
      decode_bc4_block(block, static_cast<uint8_t*>(out));
      return;
    case Format::kBc5:
      decode_bc5_block(block, static_cast<uint8_t*>(out));
      return;
    case Format::kBc4Signed:
      decode_bc4s_block(block, static_cast<int8_t*>(out));
      return;
    case Format::kBc5Signed:
      decode_bc5s_block(block, static_cast<int8_t*>(out));
      return;
    case Format::kBc6hUnsigned:
      decode_bc6h_block(block, false, static_cast<uint16_t*>(out));
      return;
    case Format::kBc6hSigned:
      decode_bc6h_block(block, true, static_cast<uint16_t*>(out));
      return;
    case Format::kBc7:
      decode_bc7_block(block, static_cast<uint8_t*>(out));
      return;
  }
  // An enum value outside the list: the caller's bug; decode as zeros rather than leave garbage.
  std::memset(out, 0, 16 * size_t{4});
}

Status decode_image(Format f, const uint8_t* blocks, size_t blocks_size, uint32_t width,
                    uint32_t height, void* out, size_t out_size, size_t out_row_stride) {
  CALF_ASSIGN_OR_RETURN(const size_t need, compressed_size(f, width, height));
  const std::string name = format_name(f);
  if (blocks == nullptr || blocks_size < need) {
    return Status(ErrorId::kBcBufferSize, name + ": " + std::to_string(blocks_size) +
                                              " block bytes given, " + std::to_string(need) +
                                              " needed for " + std::to_string(width) + "x" +
                                              std::to_string(height));
  }
  const size_t tb = static_cast<size_t>(texel_bytes(f));
  const size_t row = size_t{width} * tb;
  if (out_row_stride < row) {
    return Status(ErrorId::kBcStride, name + ": output stride " + std::to_string(out_row_stride) +
                                          " < row of " + std::to_string(row) + " bytes");
  }
  const size_t out_need = (size_t{height} - 1) * out_row_stride + row;
  if (out == nullptr || out_size < out_need) {
    return Status(ErrorId::kBcBufferSize, name + ": output holds " + std::to_string(out_size) +
                                              " bytes, " + std::to_string(out_need) + " needed");
  }
  const uint32_t bw = blocks_along(width), bh = blocks_along(height);
  const size_t bb = block_bytes(f);
  uint8_t texels[16 * 8];  // 16 texels of up to 8 bytes (BC6H: 6)
  auto* dst = static_cast<uint8_t*>(out);
  for (uint32_t by = 0; by < bh; ++by) {
    for (uint32_t bx = 0; bx < bw; ++bx) {
      decode_block(f, blocks + (size_t{by} * bw + bx) * bb, texels);
      // Copy the rows and columns of this block that lie inside the image.
      const uint32_t nx = std::min<uint32_t>(4, width - bx * 4);
      const uint32_t ny = std::min<uint32_t>(4, height - by * 4);
      for (uint32_t y = 0; y < ny; ++y) {
        std::memcpy(dst + (size_t{by} * 4 + y) * out_row_stride + size_t{bx} * 4 * tb,
                    texels + y * 4 * tb, nx * tb);
      }
    }
  }
  return Status::Ok();
}

float half_to_float(uint16_t h) {
  const uint32_t sign = uint32_t{h & 0x8000u} << 16;
  const uint32_t exp = (h >> 10) & 0x1f;
  const uint32_t man = h & 0x3ffu;
  uint32_t bits;
  if (exp == 0) {
    // Zero or subnormal: value = man * 2^-24, exact in float.
    const float v = static_cast<float>(man) * 0x1p-24f;
    return sign ? -v : v;
  } else if (exp == 31) {
    bits = sign | 0x7f800000u | (man << 13);  // Inf or NaN (payload kept)
  } else {
    bits = sign | ((exp + 112) << 23) | (man << 13);
  }
  return std::bit_cast<float>(bits);
}

uint16_t float_to_half(float f) {
  const uint32_t bits = std::bit_cast<uint32_t>(f);
  const uint16_t sign = static_cast<uint16_t>((bits >> 16) & 0x8000u);
  const uint32_t abs = bits & 0x7fffffffu;
  if (abs >= 0x7f800000u) {  // Inf or NaN
    return static_cast<uint16_t>(sign | 0x7c00u | (abs > 0x7f800000u ? 0x200u : 0u));
  }
  if (abs >= 0x477ff000u) return static_cast<uint16_t>(sign | 0x7c00u);  // rounds past 65504
  if (abs < 0x38800000u) {
    // Result is subnormal (or zero): round abs * 2^24 to the nearest integer, ties to even.
    if (abs < 0x33000000u) return sign;  // below half the smallest subnormal: +-0
    const uint32_t e = abs >> 23;        // 102..112
    const uint32_t m = (abs & 0x7fffffu) | 0x800000u;
    const uint32_t shift = 126 - e;  // value = m * 2^(e-150); want m * 2^(e-150+24)
    uint32_t r = m >> shift;
    const uint32_t rem = m & ((1u << shift) - 1);
    const uint32_t half = 1u << (shift - 1);
    if (rem > half || (rem == half && (r & 1))) ++r;
    return static_cast<uint16_t>(sign | r);
  }
  // Normal: rebias the exponent, round the 13 dropped mantissa bits to nearest even.
  uint32_t h = ((abs >> 13) - (112u << 10));
  const uint32_t rem = abs & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1))) ++h;  // may carry into the exponent: fine
  return static_cast<uint16_t>(sign | h);
}

}  // namespace calf::bc
