// A contact sheet for judging a playback against ground truth at a glance: one row per pose,
// three tiles per row, left to right: ground truth | calf's frame | error heat map (the ramp and
// scale of write_heat_map_png). Tiles keep the frames' own size; rows and columns are separated by
// a `gap` of the background grey. Used by `calf-play --contact-sheet` and the README demo.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include "calf/format/status.h"
#include "calf/player/image_compare.h"

namespace calf::player {

struct ContactSheetRow {
  RgbImageRef ground_truth;
  RgbImageRef rendered;  // same size as ground_truth
};

struct ContactSheetOptions {
  uint32_t gap = 4;              // pixels between tiles and around the sheet, 0..64
  uint8_t background = 48;       // grey level of the gaps
  double heat_full_scale = 0.1;  // per-pixel error shown as red, as write_heat_map_png
};

// An 8-bit sRGB image, row-major from the top row, 3 bytes per pixel.
struct Rgb8Image {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};

// Composes the sheet. Rows may differ in size (the sheet is as wide as the widest row; narrower
// rows leave background on the right). Errors: CALF-E431 for no rows or a row whose images are
// empty, differ in size or have short buffers (naming the row); CALF-E432 for an option outside
// its range or a sheet above 16384 pixels on a side.
Expected<Rgb8Image> compose_contact_sheet(std::span<const ContactSheetRow> rows,
                                          const ContactSheetOptions& options = {});

// Indices of at most `rows` poses out of `poses`, evenly spread and always including the first
// and the last (all of them when poses <= rows), ascending. rows = 0 gives none.
std::vector<size_t> contact_sheet_poses(size_t poses, size_t rows);

// Writes an 8-bit sRGB image as a PNG, whole or not at all (CALF-E004).
Status write_png_rgb8(const std::filesystem::path& path, const Rgb8Image& image);

}  // namespace calf::player
