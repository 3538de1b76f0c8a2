// Private to samples/: what the procedural built-in scenes of the visible-set mode (city, blades,
// spheres) share: a counter-based hash for reproducible random choices, and shorthands.
//
// Why a hash and not <random>: std::uniform_*_distribution is not specified bit for bit, so the
// same seed gives different scenes with different standard libraries. Here every random number is
// a pure function of (stream, index), written out below, so a scene is the same on every machine
// and any part of it can be generated alone, in any order.
#pragma once

#include <cstdint>
#include <string>

#include "calf/samples/scene.h"

namespace calf::samples::procedural {

// splitmix64's finaliser (Steele et al.), a bijective 64-bit mix.
inline uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The random word `index` of stream `stream`: mix64(mix64(stream) + (index + 1) * golden ratio).
inline uint64_t word(uint64_t stream, uint64_t index) {
  return mix64(mix64(stream) + (index + 1) * 0x9E3779B97F4A7C15ull);
}

// Uniform in [0, 1): the word's top 24 bits over 2^24 (exact in float).
inline float unit(uint64_t stream, uint64_t index) {
  return static_cast<float>(word(stream, index) >> 40) * (1.0f / 16777216.0f);
}

// Uniform in [lo, hi).
inline float uniform(uint64_t stream, uint64_t index, float lo, float hi) {
  return lo + (hi - lo) * unit(stream, index);
}

// Uniform in {0, ..., n - 1} (n >= 1): the top 32 bits scaled by n (Lemire's multiply-shift).
inline uint32_t pick(uint64_t stream, uint64_t index, uint32_t n) {
  return static_cast<uint32_t>(((word(stream, index) >> 32) * n) >> 32);
}

// A stream key from up to three small integers (a scene part and its coordinates).
inline uint64_t stream_of(uint64_t a, uint64_t b = 0, uint64_t c = 0) {
  return mix64(mix64(mix64(a) ^ b) ^ c);
}

inline Material diffuse(float r, float g, float b) {
  Material m;
  m.albedo = {r, g, b};
  return m;
}

// "1,234,567": how descriptions print triangle counts.
inline std::string with_thousands(uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out.push_back(',');
    out.push_back(digits[i]);
  }
  return out;
}

}  // namespace calf::samples::procedural
