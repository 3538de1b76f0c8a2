// Log-16 depth (paper 002, Sec. 5.3, Eq. 13): the one place where calf maps a radial depth to a
// 16-bit code and back. Encoder, decoder, CPU renderer and GLSL renderer all use this mapping.
//
// Depth is the radial distance from the viewpoint centre along the texel's ray, in scene units.
// Each viewpoint has its own range [z_near, z_far], measured from its data. Codes are
//
//   code(z) = round(kLog16MaxFinite * ln(z / z_near) / ln(z_far / z_near))   for z in [near, far]
//   z(code) = z_near * exp(code * ln(z_far / z_near) / kLog16MaxFinite)     for code <= 65534
//
// with code 0 exactly z_near and code 65534 exactly z_far. Code 65535 (kLog16Sky) is reserved for
// sky / no hit and never stands for a finite depth. Eq. 13 in the paper scales by 2^16 - 1; calf
// scales by 2^16 - 2 because it keeps the top code for sky, so one code step is a relative depth
// step of ln(z_far / z_near) / 65534 (e.g. 3.5e-4, i.e. 0.035 %, for near 1e-4 and far 1e6; 1.1e-4
// for near 0.1 and far 100). Rounding to the nearest code keeps every finite depth within half a
// step: |z(code(z)) / z - 1| <= exp(step / 2) - 1.
//
// Input depths are classified before coding:
//   +inf                    sky (no hit): kLog16Sky
//   finite, z > 0           coded; must lie in [z_near, z_far] (a value within one code step
//                           outside is clamped: float rounding of a measured min/max)
//   NaN, -inf, z <= 0, -0   invalid: an error, never silently a finite depth
#pragma once

#include <cstdint>

#include "calf/format/status.h"

namespace calf {

inline constexpr uint16_t kLog16Sky = 0xFFFF;
inline constexpr uint16_t kLog16MaxFinite = 0xFFFE;

enum class DepthClass : uint8_t { kFinite, kSky, kInvalid };
// +inf is sky; NaN, -inf and values <= 0 are invalid; every other value is finite.
DepthClass classify_depth(float z);

// A validated per-viewpoint depth range with the constants of the mapping precomputed.
class LogDepthRange {
 public:
  // z_near and z_far must be finite, 0 < z_near < z_far, and ln(z_far / z_near) finite.
  // Errors (CALF-E020) name the offending value.
  static Expected<LogDepthRange> make(float z_near, float z_far);
  // A range covering measured depths [min_depth, max_depth] (both finite, > 0). When
  // min == max (a flat view: every surface at one distance) the range is widened upward by
  // 1/1024 of the depth so that it is valid and the depth still codes to exactly z_near.
  static Expected<LogDepthRange> covering(float min_depth, float max_depth);

  float z_near() const { return near_; }
  float z_far() const { return far_; }
  // ln(z_far / z_near) / 65534: the relative depth step between consecutive codes.
  double relative_step() const { return step_; }

  // The code for a depth (see the classification above). Errors: CALF-E021 for an invalid value,
  // CALF-E022 for a finite depth outside the range.
  Expected<uint16_t> encode(float z) const;
  // The code for a depth the caller knows is finite and inside the range (or +inf); out-of-range
  // values are clamped, NaN codes as sky. For inner loops over validated data.
  uint16_t encode_unchecked(float z) const;
  // The depth a code stands for: +inf for kLog16Sky, z_near exactly for 0, z_far exactly for
  // kLog16MaxFinite.
  float decode(uint16_t code) const;

  // The continuous form used by ray marching (Alg. 4, nonlin() / lin()):
  // x = ln(z / z_near) / ln(z_far / z_near), 0 at z_near and 1 at z_far.
  double normalized_from_depth(double z) const;
  double depth_from_normalized(double x) const;

 private:
  LogDepthRange(float z_near, float z_far);
  float near_ = 1, far_ = 2;
  double log_near_ = 0, log_ratio_ = 1, step_ = 1, inv_step_ = 1;
};

}  // namespace calf
