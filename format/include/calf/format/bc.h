// BCn texture block decoders: BC1, BC4, BC5, BC6H, BC7 — the meaning of the bits.
//
// These decoders define what a calf block means on the CPU (the reference renderer, quality
// measurement on what the viewer will see, machines without GL). They are pure scalar C++, have
// no global state, never allocate, never fail on any 8- or 16-byte pattern, and are bit-exact
// with Mesa's decoders (checked in tests/integration/bc_mesa_test.cc; docs/BLOCK_CODECS.md
// lists where other decoders (llvmpipe's JIT sampler, GPUs) may legitimately differ, and by how
// much).
//
// Conventions shared by every function here:
//  - A block covers 4x4 texels. Decoded texels are written row-major (texel i = 4*y + x), each
//    texel as `channels(format)` consecutive values of `sample type`:
//        BC1, BC7        4 x uint8  (RGBA, unorm)
//        BC4 / BC4S      1 x uint8 / int8   (R, unorm / snorm)
//        BC5 / BC5S      2 x uint8 / int8   (RG, unorm / snorm)
//        BC6H, BC6H_SF   3 x uint16 (RGB, IEEE half-float bit patterns; alpha is implicitly 1)
//  - Blocks are stored row by row, ceil(w/4) blocks per row, ceil(h/4) rows, no padding.
//  - Images whose width or height is not a multiple of 4: the last block column/row is only
//    partly inside the image. decode_image() decodes such blocks whole and writes only the
//    texels inside width x height; the others are never written (the caller's memory outside the
//    image is untouched). Encoders fill the missing texels by clamping to the image edge.
//  - Reserved encodings decode as the specification says: a BC7 block whose first byte is 0
//    gives transparent black (0,0,0,0) for all 16 texels; a BC6H block with a reserved mode
//    (5-bit modes 19, 23, 27, 31) gives (0,0,0) (alpha 1).
//
// Rounding (where the specifications leave freedom, calf follows Mesa exactly):
//  - BC1 colours 2 and 3 are (2*c0 + c1) / 3 and (c0 + 2*c1) / 3 on the 8-bit expanded endpoints
//    with truncating division; 3-colour mode's colour 2 is (c0 + c1) / 2 truncated.
//  - BC4/BC5 interpolants are (a*(7-i) + b*i) / 7 (resp. / 5) truncated.
//  - BC6H and BC7 are bit-exact by specification (no freedom).
#pragma once

#include <cstddef>
#include <cstdint>

#include "calf/format/status.h"

namespace calf::bc {

// The block formats calf stores. The numeric values are stable (they may be written to files).
enum class Format : uint8_t {
  kBc1 = 1,           // RGB 5:6:5 endpoints + 2-bit indices, 1-bit alpha (8 bytes/block)
  kBc4 = 2,           // one unsigned channel (8 bytes/block)
  kBc5 = 3,           // two unsigned channels: a BC4 block for R, then one for G (16 bytes)
  kBc4Signed = 4,     // one signed channel (8 bytes)
  kBc5Signed = 5,     // two signed channels (16 bytes)
  kBc6hUnsigned = 6,  // HDR RGB, non-negative half floats (16 bytes)
  kBc6hSigned = 7,    // HDR RGB, signed half floats (16 bytes)
  kBc7 = 8,           // RGBA, 8 modes (16 bytes)
};

// Largest image width or height accepted by the image-level functions (kBcDimensions above).
inline constexpr uint32_t kMaxDimension = 65536;

// Bytes of one compressed 4x4 block: 8 for BC1/BC4, 16 for the others.
constexpr size_t block_bytes(Format f) {
  return (f == Format::kBc1 || f == Format::kBc4 || f == Format::kBc4Signed) ? 8 : 16;
}
// Values per decoded texel (see the table above).
constexpr int channels(Format f) {
  switch (f) {
    case Format::kBc4:
    case Format::kBc4Signed:
      return 1;
    case Format::kBc5:
    case Format::kBc5Signed:
      return 2;
    case Format::kBc6hUnsigned:
    case Format::kBc6hSigned:
      return 3;
    default:
      return 4;
  }
}
// Bytes per decoded value: 2 for BC6H (half floats), else 1.
constexpr int sample_bytes(Format f) {
  return (f == Format::kBc6hUnsigned || f == Format::kBc6hSigned) ? 2 : 1;
}
// Bytes per decoded texel.
constexpr int texel_bytes(Format f) {
  return channels(f) * sample_bytes(f);
}
// Blocks along a dimension of `pixels` texels: ceil(pixels / 4).
constexpr uint32_t blocks_along(uint32_t pixels) {
  return (pixels + 3) / 4;
}
// Short name, e.g. "BC6H_UF16"; for messages and benchmark tables.
const char* format_name(Format f);

// Bytes of a whole compressed image; kBcDimensions when width or height is 0 or > kMaxDimension.
Expected<size_t> compressed_size(Format f, uint32_t width, uint32_t height);

// ---- Single blocks. `block` points to block_bytes(f) bytes; `out` to 16 texels. ----

// BC1 with 1-bit alpha: c0 > c1 selects 4 colours; c0 <= c1 selects 3 colours plus index 3 =
// transparent black (0,0,0,0). All other texels have alpha 255.
void decode_bc1_block(const uint8_t* block, uint8_t* rgba);
// BC4 unsigned: 16 x uint8. r0 > r1 selects 8 levels, else 6 levels plus 0 and 255.
void decode_bc4_block(const uint8_t* block, uint8_t* r);
// BC4 signed: 16 x int8, as Mesa decodes it: endpoints are int8 as stored (-128 included) and
// the 6-level mode's extremes are -128 and 127. As snorm, -128 and -127 both mean -1.0.
void decode_bc4s_block(const uint8_t* block, int8_t* r);
// BC5 unsigned: two BC4 blocks (R then G) -> 16 x {R, G}.
void decode_bc5_block(const uint8_t* block, uint8_t* rg);
// BC5 signed -> 16 x {R, G} int8.
void decode_bc5s_block(const uint8_t* block, int8_t* rg);
// BC7, all 8 modes, every rotation / index-selection variant -> 16 x RGBA8.
void decode_bc7_block(const uint8_t* block, uint8_t* rgba);
// BC6H, all 14 modes, unsigned (is_signed = false) or signed -> 16 x RGB half-float bits. The
// result is always finite: at most 65504 in magnitude, never NaN or Inf, never negative for
// unsigned blocks.
void decode_bc6h_block(const uint8_t* block, bool is_signed, uint16_t* rgb_half);
// Any format: `out` receives 16 * texel_bytes(f) bytes.
void decode_block(Format f, const uint8_t* block, void* out);

// ---- Whole images. ----

// Decodes `width` x `height` texels from `blocks` (compressed_size() bytes at least, else
// kBcBufferSize) into `out`, whose rows are `out_row_stride` bytes apart (at least
// width * texel_bytes(f), else kBcStride); `out_size` is the bytes available at `out`
// ((height - 1) * stride + width * texel_bytes(f) needed, else kBcBufferSize).
// Texels outside width x height in partial blocks are not written.
Status decode_image(Format f, const uint8_t* blocks, size_t blocks_size, uint32_t width,
                    uint32_t height, void* out, size_t out_size, size_t out_row_stride);

// ---- BC6H endpoint arithmetic, shared with the encoder's endpoint search ----

// Unquantises a `bits`-bit endpoint value (already sign-extended when `is_signed`) to the 16-bit
// interpolation domain, as the specification's pseudocode does.
int bc6h_unquantize(int x, int bits, bool is_signed);

// ---- Half floats (IEEE 754 binary16), as BC6H stores and decodes them. ----

// Exact conversion of a half bit pattern to float (subnormals, Inf and NaN included).
float half_to_float(uint16_t h);
// Round-to-nearest-even conversion; overflow gives +-Inf, NaN stays NaN (quiet).
uint16_t float_to_half(float f);

}  // namespace calf::bc
