// Fuzz target: encode -> decode round trips of arbitrary pixels. The first 64 bytes are a 4x4
// RGBA8 block (zero-padded), byte 64 the quality; the same bytes reinterpreted as 48 floats
// (NaN, Inf, negatives, subnormals included) are a BC6H block. Asserts that every encoder is
// deterministic (two runs give the same bytes), that BC6H never decodes to NaN/Inf, and that a
// constant LDR block stays within the documented error.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"

namespace {

void check_same(const uint8_t* a, const uint8_t* b, size_t n) {
  if (std::memcmp(a, b, n) != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf::bc;
  uint8_t raw[192] = {};
  std::memcpy(raw, data, size < sizeof raw ? size : sizeof raw);
  const int quality = size > 64 ? data[64] % 3 : 0;
  const uint8_t* rgba = raw;

  uint8_t a[16], b[16], texels[64];
  encode_bc7_block(rgba, a, {quality, 1});
  encode_bc7_block(rgba, b, {quality, 1});
  check_same(a, b, 16);
  decode_bc7_block(a, texels);

  encode_bc1_block(rgba, a, {quality, (quality & 1) != 0, 1});
  encode_bc1_block(rgba, b, {quality, (quality & 1) != 0, 1});
  check_same(a, b, 8);
  decode_bc1_block(a, texels);

  uint8_t red[16];
  for (int i = 0; i < 16; ++i) red[i] = rgba[4 * i];
  encode_bc4_block(red, a, {quality & 1, 1});
  encode_bc4_block(red, b, {quality & 1, 1});
  check_same(a, b, 8);
  decode_bc4_block(a, texels);

  float px[48];
  std::memcpy(px, raw, sizeof px);
  for (bool is_signed : {false, true}) {
    Bc6hOptions o;
    o.quality = quality;
    o.is_signed = is_signed;
    encode_bc6h_block(px, a, o);
    encode_bc6h_block(px, b, o);
    check_same(a, b, 16);
    uint16_t rgb[48];
    decode_bc6h_block(a, is_signed, rgb);
    for (uint16_t v : rgb) {
      if ((v & 0x7fff) > 0x7bff) std::abort();
      if (!is_signed && (v & 0x8000)) std::abort();
    }
  }

  // A constant block made of the first texel must come back nearly exact in BC7.
  uint8_t flat[64];
  for (int i = 0; i < 16; ++i) std::memcpy(flat + 4 * i, rgba, 4);
  encode_bc7_block(flat, a, {quality, 1});
  decode_bc7_block(a, texels);
  for (int i = 0; i < 64; ++i) {
    if (std::abs(texels[i] - flat[i]) > 1) std::abort();
  }
  return 0;
}
