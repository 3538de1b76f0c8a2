// Depth P-frame regions (paper 002, Sec. 5.2, Alg. 3): which texels of a depth region changed, and
// the few tight rectangles that cover them.
//
// A P-frame of frame i stores the texels that differ from *any* of the previous W frames (the depth
// window): a decoder that starts at a keyframe K can then reach frame i by decoding K, K + W, ...,
// i instead of every frame (Sec. 7.1). The changed texels are covered by at most A non-overlapping
// axis-aligned rectangles, found by starting from the tight bounding box of the mask and splitting
// it, each step taking the split (over every box, every row and column) that removes the most
// uncovered texels after both halves are re-tightened — the "exhaustive search that starts with a
// single tight AABB and iteratively splits it" of the paper. Fewer rectangles mean fewer texture
// update calls; tighter ones fewer bytes.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/grid.h"
#include "calf/format/status.h"

namespace calf::encoder {

// One bit per texel, row-major, width x height; 1 = the texel must be updated.
struct ChangeMask {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> bits;  // one byte per texel (0 or 1): simple, and masks are small
  bool at(uint32_t x, uint32_t y) const { return bits[static_cast<size_t>(y) * width + x] != 0; }
};

// The mask of texels of `frames[current]` that differ by more than `epsilon` codes from the same
// texel in any of frames [current - window, current - 1] (clamped at 0). Frames are log-16 depth
// codes of one tile, each width * height values. current must be >= 1 and < frames.size(),
// window >= 1 (CALF-E001 otherwise).
Expected<ChangeMask> depth_change_mask(std::span<const std::span<const uint16_t>> frames,
                                       uint32_t width, uint32_t height, uint32_t current,
                                       uint32_t window, uint16_t epsilon = 0);

struct AabbOptions {
  // Most rectangles per P-frame (the paper's A; default 2 as in DESIGN.md / Fig. 7).
  uint32_t max_boxes = 2;
  // Rectangle corners are snapped outward to multiples of this (4 lets BC5 blocks be stored per
  // rectangle; 1 for raw 16-bit). Snapped boxes are clipped to the tile and never overlap.
  uint32_t alignment = 1;
};

// Non-overlapping rectangles covering every set texel of `mask`, at most options.max_boxes of them
// (none for an empty mask), in a deterministic order (top-to-bottom, then left-to-right). Errors:
// max_boxes == 0 or alignment == 0 (CALF-E001).
Expected<std::vector<PixelRect>> fit_change_boxes(const ChangeMask& mask,
                                                  const AabbOptions& options);

// Texels covered by the rectangles (their total area).
uint64_t covered_texels(std::span<const PixelRect> boxes);

}  // namespace calf::encoder
