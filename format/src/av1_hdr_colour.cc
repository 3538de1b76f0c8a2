#include "calf/format/av1_hdr_colour.h"

namespace calf::lf {

namespace {
bool is(uint16_t colour_format, container::PixelFormat f) {
  return colour_format == static_cast<uint16_t>(f);
}
}  // namespace

bool is_av1_colour(uint16_t colour_format) {
  using container::PixelFormat;
  return is(colour_format, PixelFormat::kAv1) || is(colour_format, PixelFormat::kAv1Hdr) ||
         is(colour_format, PixelFormat::kAv1Chroma444) ||
         is(colour_format, PixelFormat::kAv1HdrChroma444);
}

bool is_av1_hdr_colour(uint16_t colour_format) {
  return is(colour_format, container::PixelFormat::kAv1Hdr) ||
         is(colour_format, container::PixelFormat::kAv1HdrChroma444);
}

bool is_av1_chroma444(uint16_t colour_format) {
  return is(colour_format, container::PixelFormat::kAv1Chroma444) ||
         is(colour_format, container::PixelFormat::kAv1HdrChroma444);
}

Expected<Av1Gop> parse_av1_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                 uint16_t colour_format, Av1HdrCurve* curve,
                                 const std::string& what) {
  *curve = Av1HdrCurve{};
  if (!is_av1_hdr_colour(colour_format)) {
    return parse_av1_gop(raw, frame_count, what);
  }
  if (raw.size() < 4) {
    return Status(ErrorId::kAv1Chunk,
                  what + ": HDR AV1 chunk of " + std::to_string(raw.size()) + " bytes");
  }
  Av1HdrCurve c;
  c.base = static_cast<uint16_t>(raw[0] | raw[1] << 8);
  c.shift = static_cast<uint16_t>(raw[2] | raw[3] << 8);
  if (c.base > 0x7BFF || c.shift > 5) {
    return Status(ErrorId::kAv1Chunk, what + ": curve base " + std::to_string(c.base) + " shift " +
                                          std::to_string(c.shift) +
                                          " (base at most 31743, shift at most 5)");
  }
  CALF_ASSIGN_OR_RETURN(Av1Gop gop, parse_av1_gop(raw.subspan(4), frame_count, what));
  *curve = c;
  return gop;
}

void append_av1_hdr_curve(std::vector<uint8_t>& out, Av1HdrCurve curve) {
  for (const uint16_t v : {curve.base, curve.shift}) {
    out.push_back(static_cast<uint8_t>(v));
    out.push_back(static_cast<uint8_t>(v >> 8));
  }
}

}  // namespace calf::lf
