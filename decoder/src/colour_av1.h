// AV1 colour (format/SPEC.md §11.1.12): one cell's AV1 stream decoded with dav1d, a temporal unit
// at a time, and its pictures converted to the sRGB-encoded RGBA8 texels the rgba8 colour path
// yields. Private to the decoder: LightfieldDecoder and LightfieldReference both decode through it.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "calf/format/av1_hdr_colour.h"
#include "calf/format/status.h"

namespace calf::decoder {

class Av1CellDecoder {
 public:
  // One dav1d context: one thread, a frame delay of 1 (a picture out for every unit in), no film
  // grain, no logging. Errors: CALF-E301 when dav1d cannot open.
  static Expected<Av1CellDecoder> create();
  Av1CellDecoder(Av1CellDecoder&&) noexcept;
  Av1CellDecoder& operator=(Av1CellDecoder&&) noexcept;
  ~Av1CellDecoder();

  // Forgets the stream: the next unit must start a new one (a key frame with its sequence header).
  void reset();
  // Decodes one temporal unit, which must yield exactly one picture (kept as the last picture).
  // Errors: CALF-E301 (`what` names cell and frame); after one, reset() before the next unit.
  Status decode(std::span<const uint8_t> unit, const std::string& what);
  // The top-left w x h texels of the last picture as RGBA8 (§11.1.12's integer conversion,
  // alpha 255), row-major; chroma of 4:2:0 pictures (`chroma444` false) is taken at (x/2, y/2),
  // of 4:4:4 pictures at (x, y). Errors: CALF-E302 for no picture, a picture that is not 8-bit of
  // that subsampling or is smaller than w x h.
  Status rgba8(uint32_t w, uint32_t h, bool chroma444, std::vector<uint8_t>& out,
               const std::string& what) const;
  // HDR AV1 colour (formats 13 and 15): the top-left w x h texels of the last picture as RGBA16F
  // (§11.1.12: the 10-bit conversion, each code through `curve`, alpha 1.0), little-endian
  // halves, row-major. Errors: CALF-E302 for no picture, a picture that is not 10-bit of the
  // subsampling `chroma444` says or is smaller than w x h.
  Status rgba16f(uint32_t w, uint32_t h, bool chroma444, lf::Av1HdrCurve curve,
                 std::vector<uint8_t>& out, const std::string& what) const;
  // The last picture as the colour format's GPU bytes: rgba8 for av1 and av1-444, rgba16f for
  // av1hdr and av1hdr-444.
  Status gpu_bytes(uint16_t colour_format, uint32_t w, uint32_t h, lf::Av1HdrCurve curve,
                   std::vector<uint8_t>& out, const std::string& what) const;

 private:
  struct Impl;
  explicit Av1CellDecoder(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// §11.1.12's conversion of one 8-bit Y, Cb, Cr sample triple to sRGB-encoded R, G, B.
void av1_ycbcr_to_rgb(uint8_t y, uint8_t cb, uint8_t cr, uint8_t rgb[3]);
// The same conversion of one 10-bit triple (0 … 1023, chroma centred on 512) to R, G, B codes.
void av1_ycbcr10_to_rgb(uint16_t y, uint16_t cb, uint16_t cr, uint16_t rgb[3]);

}  // namespace calf::decoder
