// Spatial prediction of log-16 depth codes (format/SPEC.md §11.1.8, depth format 10 "r16p"):
// the lossless-image-coder step before supercompression. Each rectangle of a region chunk is
// coded on its own (so a decoder needs nothing but the rectangle's own residuals: per-tile random
// access is unchanged) as the residual of every code against a prediction from its left, upper
// and upper-left neighbours, mapped to an unsigned value so that small errors of either sign are
// small numbers, which the payload's 16-bit planes then hand to zstd / LZMA2 as a high plane of
// zeros and a low plane of small values.
//
// Prediction of texel (x, y) of a w x h rectangle from a = (x-1, y), b = (x, y-1), c = (x-1, y-1):
//   x = 0, y = 0: 0
//   y = 0:        a
//   x = 0:        b
//   otherwise:    the plane a + b - c (mod 65536) when none of a, b, c is sky (65535); else the
//                 median edge detector of LOCO-I / JPEG-LS: min(a, b) if c >= max(a, b),
//                 max(a, b) if c <= min(a, b), else a + b - c.
// Why the plane and not LOCO-I's median everywhere: log-16 depth of a surface is smooth with large
// gradients (hundreds of codes per texel at 64-texel faces), where the median picks a neighbour
// and leaves the whole smaller gradient as residual, while the plane leaves only the curvature
// (measured: 30 % fewer depth bytes on interior, 23 % on mirror-box, docs/ENCODER.md). Beside sky
// the plane would mix 65535 into a finite estimate; the median picks a neighbour there, so a sky
// run predicts sky (residual 0) and a finite texel under sky predicts from its finite neighbour.
//
// The residual is e = zigzag((code - pred) mod 65536), reading the difference as a signed 16-bit
// value d: zigzag(d) = 2d for d >= 0, -2d - 1 for d < 0. Every step is a bijection on 16-bit
// values, so any 16-bit residuals decode to some codes (no decoder check is needed) and the sky
// code 65535 survives exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "calf/format/log_depth.h"

namespace calf::lf {

// LOCO-I's median edge detector from the left (a), upper (b) and upper-left (c) neighbours.
inline uint16_t med_predict(uint16_t a, uint16_t b, uint16_t c) {
  const uint16_t lo = a < b ? a : b, hi = a < b ? b : a;
  if (c >= hi) return lo;
  if (c <= lo) return hi;
  return static_cast<uint16_t>(a + b - c);  // lo < c < hi: the sum stays in [lo, hi]
}

// The prediction of an inner texel (x > 0 and y > 0), as the table above says.
inline uint16_t depth_predict_inner(uint16_t a, uint16_t b, uint16_t c) {
  if (a == kLog16Sky || b == kLog16Sky || c == kLog16Sky) return med_predict(a, b, c);
  return static_cast<uint16_t>(a + b - c);
}

// The residual's unsigned form, and its inverse.
inline uint16_t zigzag16(uint16_t code, uint16_t pred) {
  const auto d = static_cast<int16_t>(static_cast<uint16_t>(code - pred));
  return static_cast<uint16_t>(d >= 0 ? 2 * d : -2 * d - 1);
}
inline uint16_t unzigzag16(uint16_t e, uint16_t pred) {
  const uint16_t d =
      (e & 1) != 0 ? static_cast<uint16_t>(~(e >> 1)) : static_cast<uint16_t>(e >> 1);
  return static_cast<uint16_t>(pred + d);
}

// Residuals of a w x h rectangle of codes (row-major, `stride` codes between rows) into
// `residuals` (w * h values, row-major).
void predict_depth_rect(const uint16_t* codes, uint32_t w, uint32_t h, size_t stride,
                        uint16_t* residuals);

// The inverse: w * h codes from residuals given as two byte planes (the high byte of residual i at
// hi[i], the low byte at lo[i], as the region chunk stores them), written as little-endian u16
// (the decoder's GPU-ready bytes, 2 * w * h bytes at `out`).
void reconstruct_depth_rect(const uint8_t* hi, const uint8_t* lo, uint32_t w, uint32_t h,
                            uint8_t* out);

// Depth format r16pm (SPEC §11.1.9): a P-frame rectangle's change mask, bit i (row-major texel
// i of the w x h rectangle) = bit (i mod 8) of mask[i / 8], least significant first; ceil(w h / 8)
// bytes, the unused high bits of the last byte 0.
inline bool mask_bit(const uint8_t* mask, size_t i) {
  return (mask[i >> 3] >> (i & 7) & 1) != 0;
}
inline size_t mask_bytes_of(uint32_t w, uint32_t h) {
  return (size_t{w} * h + 7) / 8;
}
// Residuals of the texels of a w x h rectangle whose mask bit is set, in row-major order, into
// `residuals` (resized); the prediction is r16p's over the whole rectangle at this frame (an
// unchanged neighbour's code is this frame's, which the decoder holds as its tile state).
void predict_depth_rect_masked(const uint16_t* codes, uint32_t w, uint32_t h, size_t stride,
                               const uint8_t* mask, std::vector<uint16_t>& residuals);
// The inverse: `inout` holds the rectangle's codes in the decoder's tile state (little-endian u16,
// row-major, 2 w h bytes) on entry; every texel whose mask bit is set becomes prediction +
// residual, taking the residuals from hi[k] / lo[k] in order (k counts set bits). Texels whose bit
// is clear are left: in a valid stream they already hold this frame's codes.
void reconstruct_depth_rect_masked(const uint8_t* mask, const uint8_t* hi, const uint8_t* lo,
                                   uint32_t w, uint32_t h, uint8_t* inout);

}  // namespace calf::lf
