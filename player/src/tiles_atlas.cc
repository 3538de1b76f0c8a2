// The tile atlas converted to premultiplied linear half floats (tiles_renderer.h, "Colour space").
#include <algorithm>
#include <array>
#include <vector>

#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/player/tiles_renderer.h"

namespace calf::player {

TilesLinearAtlas tiles_linear_atlas(const TileSet& set) {
  // Every (stored byte C, alpha byte A) pair once: 64 K sRGB decodes instead of one per texel
  // channel (a 4096² atlas has 50 M).
  static const std::vector<uint16_t> table = [] {
    std::vector<uint16_t> t(256 * 256);
    for (int a = 0; a < 256; ++a) {
      for (int c = 0; c < 256; ++c) {
        float v = 0;
        if (a > 0) {
          const float encoded = std::min(1.0f, static_cast<float>(c) / static_cast<float>(a));
          v = (static_cast<float>(a) / 255.0f) * linear_from_srgb(encoded);
        }
        t[256 * a + c] = bc::float_to_half(v);
      }
    }
    return t;
  }();
  TilesLinearAtlas out;
  out.width = set.atlas_width;
  out.height = set.atlas_height;
  const size_t texels = size_t{set.atlas_width} * set.atlas_height;
  out.rgba_half.resize(4 * texels);
  for (size_t k = 0; k < texels; ++k) {
    const uint8_t* p = &set.atlas_rgba[4 * k];
    const size_t row = 256 * size_t{p[3]};
    out.rgba_half[4 * k + 0] = table[row + p[0]];
    out.rgba_half[4 * k + 1] = table[row + p[1]];
    out.rgba_half[4 * k + 2] = table[row + p[2]];
    out.rgba_half[4 * k + 3] = bc::float_to_half(static_cast<float>(p[3]) / 255.0f);
  }
  return out;
}

}  // namespace calf::player
