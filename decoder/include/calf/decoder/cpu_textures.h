// The CPU image of a renderer's texture state: what a GPU holds after applying the
// LightfieldDecoder's updates (lightfield_decoder.h), with every block format decoded as the GPU
// would (calf/format/bc.h). The CPU reference renderer reads it (through the player's ViewSet), and
// the decoder tests use it to compare the state reached by different paths (seeking vs playing, one
// viewer vs several, the reference full-frame decoder).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/decoder/lightfield_decoder.h"
#include "calf/format/container_types.h"
#include "calf/format/lightfield_layout.h"
#include "calf/format/status.h"

namespace calf::decoder {

// GPU-ready update bytes (lightfield_decoder.h formats) of a w x h rect, decoded:
// colour -> linear RGB float (3 per texel; sRGB formats through calf/format/colour.h);
// depth -> log-16 codes; material -> 3 codes per texel (reflect, refract, ior).
// Errors: CALF-E202 for bytes of the wrong size, CALF-E203 for a format the target lacks.
Status decode_gpu_colour(container::PixelFormat format, std::span<const uint8_t> bytes,
                         uint32_t width, uint32_t height, std::span<float> rgb);
Status decode_gpu_depth(container::PixelFormat format, std::span<const uint8_t> bytes,
                        uint32_t width, uint32_t height, std::span<uint16_t> codes);
Status decode_gpu_material(container::PixelFormat format, std::span<const uint8_t> bytes,
                           uint32_t width, uint32_t height, std::span<uint8_t> codes);

class CpuTextures {
 public:
  // Every view starts as after LightfieldDecoder::reset(): colour slots 0, t = 0, a_slot = 0, depth
  // all sky, material codes 0.
  CpuTextures(const container::LightfieldTrackHeader& header,
              std::span<const LightfieldViewInfo> views);

  // Applies the frame's updates in order and records the visible cells' (t, a_slot).
  // Errors: CALF-E300 for an update outside the state (view, face, slot, rect), plus the decode
  // errors above. Stops at the first error.
  Status apply(const LightfieldFrameUpdates& frame);

  uint32_t face_size() const { return face_size_; }
  // The colour cell grid of every face.
  const FaceGrid& cells() const { return cells_; }

  // Linear RGB of `face` of `view` as the renderer shows it: per cell mix(slot a, slot 1 - a,
  // t / 255) with the cell's last (t, a_slot). 3 floats per texel, row-major.
  std::vector<float> colour(uint32_t view, CubeFace face) const;
  // The same for one colour cell only (cell < cells().cell_count(), unchecked): its rect's texels,
  // 3 floats each, rows packed (rect width * 3 floats a row), into `rgb` (resized). Bit for bit
  // the cell's part of colour(), for consumers that refresh only the cells that changed.
  void colour_cell(uint32_t view, CubeFace face, uint32_t cell, std::vector<float>* rgb) const;
  std::span<const float> colour_slot(uint32_t view, CubeFace face, uint32_t slot) const;
  std::span<const uint16_t> depth(uint32_t view, CubeFace face) const;
  std::span<const uint8_t> material(uint32_t view, CubeFace face) const;  // empty without
  // The coverage texels (row-major) of a view that received coverage updates (its faces start
  // plain with the first); empty before.
  std::span<const lf::CoverageTexel> coverage(uint32_t view, CubeFace face) const;
  CellParams cell(uint32_t view, CubeFace face, uint32_t cell) const;

 private:
  struct ViewState {
    std::array<std::array<std::vector<float>, 2>, kCubeFaceCount> slots;
    std::array<std::vector<uint16_t>, kCubeFaceCount> depth;
    std::array<std::vector<uint8_t>, kCubeFaceCount> material;
    std::array<std::vector<lf::CoverageTexel>, kCubeFaceCount> coverage;
    std::array<std::vector<CellParams>, kCubeFaceCount> cells;
  };
  uint32_t face_size_ = 0;
  FaceGrid cells_ = *FaceGrid::with_cell_size(1, 1);
  std::vector<ViewState> views_;
};

}  // namespace calf::decoder
