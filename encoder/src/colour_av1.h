// AV1 colour (format/SPEC.md §11.1.12): one cell's frames, as sRGB-encoded RGBA8 or HDR codes,
// encoded into closed GOPs of temporal units: 4:2:0 by SVT-AV1, 4:4:4 by libaom
// (Av1ColourOptions::chroma444). Private to the light-field encoder.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/encoder/lightfield_encode.h"
#include "calf/format/av1_hdr_colour.h"
#include "calf/format/status.h"

namespace calf::encoder::av1_internal {

// The temporal units of one GOP: unit i shows frame i of the GOP; unit 0 is a key frame with its
// sequence header.
using Gop = std::vector<std::vector<uint8_t>>;

// Encodes `frames` frames of a w x h cell (`rgba`: frame after frame, row-major, 4 bytes a texel,
// alpha ignored) as GOPs of options.keyframe_interval frames (the last may be shorter), each by a
// fresh single-threaded encoder (SVT-AV1 for 4:2:0, libaom for 4:4:4), so that the bytes depend
// on the pictures and the options only. Pictures narrower or lower than 64 texels (SVT-AV1's least)
// or not a multiple of 8 are padded by repeating the last column and row. Errors: CALF-E256
// (kEncoderAv1).
Expected<std::vector<Gop>> encode_cell(std::span<const uint8_t> rgba, uint32_t w, uint32_t h,
                                       uint32_t frames, uint32_t fps_numerator,
                                       uint32_t fps_denominator, const Av1ColourOptions& options);

// HDR AV1 colour (format av1hdr, §11.1.12): the curve of a cell from its binary16 texels (`half`,
// R, G, B bits of every texel of every frame): base = the least value's bits, but at least 0x0400
// (2^-14, the floor of log2-PSNR), shift = the least that reaches the greatest value's bits.
// Negative values count as 0, infinities and NaN as 65504.
lf::Av1HdrCurve hdr_curve(std::span<const uint16_t> half);
// The 10-bit code nearest to binary16 bits `h` (clamped as above) on `curve`'s scale of bits.
uint16_t hdr_code(lf::Av1HdrCurve curve, uint16_t h);

// A cell's HDR AV1 colour: the curve every one of its chunks starts with, and the GOPs.
struct HdrCell {
  lf::Av1HdrCurve curve;
  std::vector<Gop> gops;
};
// As encode_cell, for binary16 linear RGB (`half`: frame after frame, row-major, 3 values a
// texel): each channel through hdr_code, then 10-bit 4:2:0 (or 4:4:4) pictures. Errors:
// CALF-E256.
Expected<HdrCell> encode_cell_hdr(std::span<const uint16_t> half, uint32_t w, uint32_t h,
                                  uint32_t frames, uint32_t fps_numerator, uint32_t fps_denominator,
                                  const Av1ColourOptions& options);

// The encoder's colour conversion (BT.709, full range, chroma as the mean of each 2 x 2 block):
// the inverse, up to rounding, of the decoder's (§11.1.12). `y` is W x H, `cb` and `cr`
// W / 2 x H / 2; W and H even. `rgba` is W x H.
void rgba_to_ycbcr420(std::span<const uint8_t> rgba, uint32_t W, uint32_t H, uint8_t* y,
                      uint8_t* cb, uint8_t* cr);
// The same for 10-bit codes (`rgb`: 3 a texel, 0 … 1023; chroma centred on 512).
void rgb10_to_ycbcr420(std::span<const uint16_t> rgb, uint32_t W, uint32_t H, uint16_t* y,
                       uint16_t* cb, uint16_t* cr);
// The 4:4:4 conversions: every plane W x H, chroma of each texel its own.
void rgba_to_ycbcr444(std::span<const uint8_t> rgba, uint32_t W, uint32_t H, uint8_t* y,
                      uint8_t* cb, uint8_t* cr);
void rgb10_to_ycbcr444(std::span<const uint16_t> rgb, uint32_t W, uint32_t H, uint16_t* y,
                       uint16_t* cb, uint16_t* cr);

}  // namespace calf::encoder::av1_internal
