// Fuzz target: the BCn decoders on arbitrary bytes. Byte 0 picks the format, bytes 1-2 the image
// size (1..64 each), the rest are the blocks (often too few: decode_image must then refuse with
// kBcBufferSize, never read past the end). Every whole block in the input is also decoded alone.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "calf/format/bc.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace calf::bc;
  if (size < 3) return 0;
  const Format f = static_cast<Format>(1 + data[0] % 8);
  const uint32_t w = 1 + data[1] % 64, h = 1 + data[2] % 64;
  const uint8_t* blocks = data + 3;
  const size_t n = size - 3;
  const size_t tb = static_cast<size_t>(texel_bytes(f));
  std::vector<uint8_t> out(size_t{w} * h * tb);
  const calf::Status st = decode_image(f, blocks, n, w, h, out.data(), out.size(), w * tb);
  const size_t need = *compressed_size(f, w, h);
  if (st.ok() != (n >= need)) std::abort();  // refuses exactly when the input is short
  uint8_t texels[16 * 8];
  for (size_t off = 0; off + block_bytes(f) <= n; off += block_bytes(f)) {
    decode_block(f, blocks + off, texels);
    if (f == Format::kBc6hUnsigned || f == Format::kBc6hSigned) {
      for (int i = 0; i < 48; ++i) {
        const uint16_t v = static_cast<uint16_t>(texels[2 * i] | texels[2 * i + 1] << 8);
        if ((v & 0x7fff) > 0x7bff) std::abort();  // never Inf or NaN
        if (f == Format::kBc6hUnsigned && (v & 0x8000)) std::abort();
      }
    }
  }
  return 0;
}
