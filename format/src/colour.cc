#include "calf/format/colour.h"

#include <array>
#include <cmath>

namespace calf {

float srgb_from_linear(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

uint8_t srgb8_from_linear(float v) {
  return static_cast<uint8_t>(std::lround(srgb_from_linear(v) * 255.0f));
}

float linear_from_srgb8(uint8_t v) {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[i] = static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  return table[v];
}

float linear_from_srgb(float v) {
  if (!(v > 0.0f)) return 0.0f;
  const double c = v >= 1.0f ? 1.0 : v;
  return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

}  // namespace calf
