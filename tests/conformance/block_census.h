// Which BCn block shapes a stream holds, read from the blocks' own bits by format/SPEC.md
// §11.1.10's layout: the crafted-clip tests count them to show a clip exercises every mode and
// partition it claims to.
#pragma once

#include <cstddef>
#include <cstdint>
#include <set>
#include <utility>

namespace calf::conformance {

// The n bits of a 16-byte block starting at bit pos, least significant first.
inline uint32_t block_bits(const uint8_t* block, int pos, int n) {
  uint32_t v = 0;
  for (int i = 0; i < n; ++i) v |= uint32_t{(block[(pos + i) / 8] >> ((pos + i) % 8)) & 1u} << i;
  return v;
}

// Adds the (mode, shape) of every BC7 block of data to seen: shape is the partition (modes 0-3,
// 7), rotation + 4 index selection (mode 4), rotation (mode 5) or 0 (mode 6); the reserved mode
// is (-1, 0).
inline void add_bc7_shapes(const uint8_t* data, size_t size, std::set<std::pair<int, int>>& seen) {
  for (size_t b = 0; b + 16 <= size; b += 16) {
    const uint8_t* block = data + b;
    int mode = 0;
    while (mode < 8 && !((block[0] >> mode) & 1)) ++mode;
    if (mode == 8) {
      seen.insert({-1, 0});
      continue;
    }
    const int shape = mode == 4   ? static_cast<int>(block_bits(block, 5, 3))
                      : mode == 5 ? static_cast<int>(block_bits(block, 6, 2))
                      : mode == 6
                          ? 0
                          : static_cast<int>(block_bits(block, mode + 1, mode == 0 ? 4 : 6));
    seen.insert({mode, shape});
  }
}

}  // namespace calf::conformance
