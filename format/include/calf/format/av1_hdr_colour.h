// HDR AV1 colour (colour format 13, av1hdr; format/SPEC.md §11.1.12, container 1.4): AV1 colour
// of HDR captures, whose 10-bit codes stand for binary16 bit patterns on a per-cell curve stored
// at the head of each GOP chunk. Both directions of the chunk head and the curve; the GOP after
// the head is lightfield_layout.h's (parse_av1_gop, append_av1_gop).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "calf/format/container_types.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/status.h"

namespace calf::lf {

// A cell's curve: code c (0 … 1023) stands for the binary16 bits min(base + (c << shift), 0x7BFF).
struct Av1HdrCurve {
  uint16_t base = 0x0400;  // bits of code 0, ≤ 0x7BFF
  uint16_t shift = 0;      // ≤ 5
};

// The binary16 bits code `code` stands for: a finite, non-negative half float.
inline uint16_t av1_hdr_half_bits(Av1HdrCurve c, uint32_t code) {
  const uint32_t bits = uint32_t{c.base} + (code << c.shift);
  return static_cast<uint16_t>(bits < 0x7BFFu ? bits : 0x7BFFu);
}

// True for the four AV1 colour formats (av1, av1hdr, av1-444, av1hdr-444).
bool is_av1_colour(uint16_t colour_format);
// True for the HDR AV1 colour formats (av1hdr, av1hdr-444): 10-bit codes on a curve, each chunk
// headed by it.
bool is_av1_hdr_colour(uint16_t colour_format);
// True for the AV1 colour formats of 4:4:4 pictures (av1-444, av1hdr-444; container 1.5).
bool is_av1_chroma444(uint16_t colour_format);

// An AV1 colour chunk of any AV1 format: for av1hdr(-444) the head's curve (u16 base, u16 shift)
// is read into `curve` and the GOP after it parsed by parse_av1_gop; for av1(-444) the chunk is
// the GOP and `curve` keeps its default. Errors: CALF-E067 (kAv1Chunk) as parse_av1_gop, and for an
// av1hdr chunk shorter than its curve or whose curve has a base above 0x7BFF or a shift above 5.
Expected<Av1Gop> parse_av1_chunk(std::span<const uint8_t> raw, uint32_t frame_count,
                                 uint16_t colour_format, Av1HdrCurve* curve,
                                 const std::string& what);
// Appends av1hdr's curve head; append_av1_gop then appends the GOP.
void append_av1_hdr_curve(std::vector<uint8_t>& out, Av1HdrCurve curve);

}  // namespace calf::lf
