// Atlas packing and the tile set (paper 000 Sec. 5): square tile textures sorted from largest to
// smallest and packed greedily into shelves (levels, as Lodi et al.), each with a one-texel pad
// that repeats its edge texels so that nearest and bilinear filtering never read a neighbour.
// The atlas height is rounded up to a multiple of 4 (whole BC7 blocks).
#include <algorithm>
#include <cmath>
#include <numeric>

#include "calf/format/colour.h"
#include "tiles_internal.h"

namespace calf::encoder::tiles {

bool pack_atlas(const std::vector<uint32_t>& sides, uint32_t max_size,
                std::vector<AtlasPlacement>* placements, uint32_t* width, uint32_t* height) {
  std::vector<uint32_t> order(sides.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return sides[a] > sides[b]; });
  uint64_t area = 0;
  uint32_t largest = 0;
  for (uint32_t s : sides) {
    area += uint64_t{s + 2} * (s + 2);
    largest = std::max(largest, s + 2);
  }
  uint32_t w = 4;
  while (w < largest || uint64_t{w} * w < area) w *= 2;
  placements->assign(sides.size(), {});
  for (; w <= max_size; w *= 2) {
    uint32_t x = 0, y = 0, shelf = 0;
    for (uint32_t k : order) {
      const uint32_t p = sides[k] + 2;
      if (x + p > w) {
        y += shelf;
        x = 0;
        shelf = 0;
      }
      if (shelf == 0) shelf = p;
      (*placements)[k] = {x + 1, y + 1};
      x += p;
    }
    const uint32_t h = (y + shelf + 3) / 4 * 4;
    if (h <= max_size) {
      *width = w;
      *height = std::max<uint32_t>(h, 4);
      return true;
    }
  }
  return false;
}

TileSet write_tile_set(const Frame& f, const Box3& view_volume, const Selection& selection,
                       const std::vector<TileTexture>& textures,
                       const std::vector<AtlasPlacement>& placements, uint32_t width,
                       uint32_t height, double dilation) {
  TileSet set;
  set.view_volume = view_volume;
  set.atlas_width = width;
  set.atlas_height = height;
  set.atlas_rgba.assign(size_t{width} * height * 4, 0);
  set.tiles.resize(selection.tiles.size());
  const int axis_of_face[6] = {0, 0, 1, 1, 2, 2};
  for (size_t k = 0; k < selection.tiles.size(); ++k) {
    const Selected& sel = selection.tiles[k];
    const TileTexture& tex = textures[k];
    const AtlasPlacement& at = placements[k];
    const std::array<Vec3, 4> c = tile_corners(sel, dilation);
    // The projective weight of a corner is its distance along the face's axis: texture
    // coordinates are affine in the face coordinates (s, t), which are that axis's perspective
    // division of scene positions.
    std::array<double, 4> w;
    double w_max = 0;
    for (int i = 0; i < 4; ++i) {
      w[i] = std::abs(component(c[i], axis_of_face[sel.cell.face]));
      w_max = std::max(w_max, w[i]);
    }
    const double ab[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    std::array<TileCorner, 4> corners;
    for (int i = 0; i < 4; ++i) {
      const Vec3 p = f.origin + c[i];
      const double u = (at.x + ab[i][0] * (tex.side - 1) + 0.5) / width;
      const double v = (at.y + ab[i][1] * (tex.side - 1) + 0.5) / height;
      const double wi = w[i] / w_max;
      corners[i].position = {static_cast<float>(p.x), static_cast<float>(p.y),
                             static_cast<float>(p.z)};
      corners[i].uvw = {static_cast<float>(u * wi), static_cast<float>(v * wi),
                        static_cast<float>(wi)};
    }
    // Counter-clockwise seen from O: the winding normal points back at O.
    if (dot(cross(c[1] - c[0], c[2] - c[0]), c[0]) > 0) std::swap(corners[1], corners[3]);
    set.tiles[k].corners = corners;
    // Texels and their pad (edge texels repeated), RGB sRGB-encoded then premultiplied.
    const int side = static_cast<int>(tex.side);
    for (int y = -1; y <= side; ++y) {
      for (int x = -1; x <= side; ++x) {
        const int sx = std::clamp(x, 0, side - 1), sy = std::clamp(y, 0, side - 1);
        const float* src = &tex.rgba[(size_t(sy) * side + sx) * 4];
        uint8_t* dst = &set.atlas_rgba[((size_t(at.y) + y) * width + (size_t(at.x) + x)) * 4];
        const float alpha = std::clamp(src[3], 0.0f, 1.0f);
        for (int ch = 0; ch < 3; ++ch) {
          dst[ch] = static_cast<uint8_t>(std::lround(srgb_from_linear(src[ch]) * alpha * 255.0f));
        }
        dst[3] = static_cast<uint8_t>(std::lround(alpha * 255.0f));
      }
    }
  }
  return set;
}

}  // namespace calf::encoder::tiles
