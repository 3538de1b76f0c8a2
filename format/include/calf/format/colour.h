// The sRGB transfer function (IEC 61966-2-1): the one place calf converts between linear colour
// and sRGB-encoded values. 8-bit colour formats in a clip hold sRGB-encoded values (SPEC §11.1);
// the GPU's sRGB texture formats and every CPU path decode them with the same curve.
#pragma once

#include <cstdint>

namespace calf {

// Linear -> sRGB-encoded, clamped to [0, 1] (NaN and values <= 0 give 0, values >= 1 give 1).
float srgb_from_linear(float linear);
// Linear -> nearest sRGB byte.
uint8_t srgb8_from_linear(float linear);
// sRGB byte -> linear, exact to float (a 256-entry table).
float linear_from_srgb8(uint8_t encoded);
// sRGB-encoded value in [0, 1] -> linear (values outside are clamped to [0, 1] first; NaN gives 0).
// The same curve as linear_from_srgb8, for encoded values that are not bytes (a premultiplied
// texel divided by its alpha).
float linear_from_srgb(float encoded);

}  // namespace calf
