// The scrambled (0, 2)-sequence of calf/samples/pixel_samples.h.
#include "calf/samples/pixel_samples.h"

namespace calf::samples {

namespace {

// The radical inverse in base 2 as 32 fraction bits: bit k of `i` becomes bit 31 - k.
uint32_t reverse_bits(uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
  i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
  return i;
}

// Sobol's second coordinate (primitive polynomial x + 1): the generator matrix is Pascal's
// triangle mod 2, whose column k (the direction number of bit k) follows from column k - 1 as
// v ^ (v >> 1), starting at 1/2.
uint32_t sobol_second(uint32_t i) {
  uint32_t result = 0;
  for (uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1) {
    if (i & 1u) result ^= v;
  }
  return result;
}

float unit_float(uint32_t bits) {
  return static_cast<float>(bits >> 8) * (1.0f / 16777216.0f);
}

}  // namespace

SamplePoint scrambled_sequence_point(uint32_t index, uint32_t scramble_x, uint32_t scramble_y) {
  return {unit_float(reverse_bits(index) ^ scramble_x),
          unit_float(sobol_second(index) ^ scramble_y)};
}

}  // namespace calf::samples
