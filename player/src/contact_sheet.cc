// Contact sheets: ground truth | rendered | heat map, one row per pose.
#include "calf/player/contact_sheet.h"

#include <algorithm>
#include <string>

#include "calf/format/colour.h"

namespace calf::player {

namespace {

constexpr uint32_t kMaxGap = 64;
constexpr uint64_t kMaxSide = 16384;

// Copies a w x h tile of 8-bit pixels into the sheet at (x0, y0).
void blit(Rgb8Image& sheet, uint32_t x0, uint32_t y0, uint32_t w, uint32_t h,
          const std::vector<uint8_t>& tile) {
  for (uint32_t y = 0; y < h; ++y) {
    std::copy_n(tile.begin() + size_t{3} * w * y, size_t{3} * w,
                sheet.rgb.begin() + 3 * (size_t{y0 + y} * sheet.width + x0));
  }
}

std::vector<uint8_t> srgb8_tile(const RgbImageRef& image) {
  std::vector<uint8_t> out(size_t{3} * image.width * image.height);
  for (size_t i = 0; i < out.size(); ++i) out[i] = srgb8_from_linear(image.rgb[i]);
  return out;
}

}  // namespace

Expected<Rgb8Image> compose_contact_sheet(std::span<const ContactSheetRow> rows,
                                          const ContactSheetOptions& options) {
  if (rows.empty()) return Status(ErrorId::kImageCompare, "contact sheet: no rows");
  if (options.gap > kMaxGap || !(options.heat_full_scale > 0 && options.heat_full_scale <= 1)) {
    return Status(ErrorId::kImageCompareOption,
                  "contact sheet: gap " + std::to_string(options.gap) + " (0.." +
                      std::to_string(kMaxGap) + ") or heat-map full scale " +
                      std::to_string(options.heat_full_scale) + " (in (0, 1]) out of range");
  }
  // error_map validates each pair (empty, short buffer, size mismatch); compute them first so
  // that nothing is allocated for a sheet that cannot be made.
  std::vector<std::vector<float>> errors;
  errors.reserve(rows.size());
  uint64_t width = 0, height = options.gap;
  for (size_t r = 0; r < rows.size(); ++r) {
    Expected<std::vector<float>> e = error_map(rows[r].ground_truth, rows[r].rendered);
    if (!e.ok()) {
      return std::move(e).status().with_context("contact sheet row " + std::to_string(r));
    }
    errors.push_back(std::move(*e));
    width = std::max<uint64_t>(width, 3 * uint64_t{rows[r].ground_truth.width} + 4 * options.gap);
    height += uint64_t{rows[r].ground_truth.height} + options.gap;
  }
  if (width > kMaxSide || height > kMaxSide) {
    return Status(ErrorId::kImageCompareOption,
                  "contact sheet of " + std::to_string(width) + " x " + std::to_string(height) +
                      " pixels exceeds " + std::to_string(kMaxSide) + " on a side; use fewer rows");
  }
  Rgb8Image sheet;
  sheet.width = static_cast<uint32_t>(width);
  sheet.height = static_cast<uint32_t>(height);
  sheet.rgb.assign(size_t{3} * sheet.width * sheet.height, options.background);
  uint32_t y = options.gap;
  for (size_t r = 0; r < rows.size(); ++r) {
    const uint32_t w = rows[r].ground_truth.width, h = rows[r].ground_truth.height;
    std::vector<uint8_t> heat(size_t{3} * w * h);
    for (size_t i = 0; i < errors[r].size(); ++i) {
      const std::array<uint8_t, 3> c = heat_colour(errors[r][i] / options.heat_full_scale);
      std::copy(c.begin(), c.end(), heat.begin() + 3 * i);
    }
    blit(sheet, options.gap, y, w, h, srgb8_tile(rows[r].ground_truth));
    blit(sheet, 2 * options.gap + w, y, w, h, srgb8_tile(rows[r].rendered));
    blit(sheet, 3 * options.gap + 2 * w, y, w, h, heat);
    y += h + options.gap;
  }
  return sheet;
}

std::vector<size_t> contact_sheet_poses(size_t poses, size_t rows) {
  std::vector<size_t> out;
  if (rows == 0 || poses == 0) return out;
  if (poses <= rows) {
    for (size_t i = 0; i < poses; ++i) out.push_back(i);
    return out;
  }
  if (rows == 1) return {0};
  // Row k shows pose round(k (poses - 1) / (rows - 1)); with poses > rows these are distinct.
  for (size_t k = 0; k < rows; ++k) out.push_back((k * (poses - 1) + (rows - 1) / 2) / (rows - 1));
  return out;
}

}  // namespace calf::player
