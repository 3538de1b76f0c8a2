// Private to calf_format: a little-endian bit reader over one 128-bit BPTC block.
#pragma once

#include <cstdint>

namespace calf::bc {

// Reads fields LSB-first from a 16-byte block, as BC6H/BC7 store them. Reading past bit 127
// yields zeros (only possible through a table bug; never undefined behaviour).
class BitReader {
 public:
  explicit BitReader(const uint8_t* block) {
    for (int i = 0; i < 8; ++i) lo_ |= uint64_t{block[i]} << (8 * i);
    for (int i = 0; i < 8; ++i) hi_ |= uint64_t{block[8 + i]} << (8 * i);
  }
  // The next `n` bits (0 <= n <= 32) as an unsigned value.
  uint32_t read(int n) {
    if (n == 0) return 0;
    uint64_t v;
    if (pos_ >= 128) {
      v = 0;
    } else if (pos_ >= 64) {
      v = hi_ >> (pos_ - 64);
    } else if (pos_ + n <= 64) {
      v = lo_ >> pos_;
    } else {
      v = (lo_ >> pos_) | (hi_ << (64 - pos_));  // pos_ > 32 here, so both shifts are < 64
    }
    pos_ += n;
    return static_cast<uint32_t>(v & ((uint64_t{1} << n) - 1));
  }
  void skip(int n) { pos_ += n; }
  int position() const { return pos_; }

 private:
  uint64_t lo_ = 0, hi_ = 0;
  int pos_ = 0;
};

}  // namespace calf::bc
