// The mip chain of a mesh texture (rules in mesh_texture.h).
#include "calf/format/mesh_texture.h"

#include <algorithm>

#include "calf/format/colour.h"

namespace calf::mesh {

uint32_t mip_level_count(uint32_t width, uint32_t height) {
  uint32_t n = 1;
  for (uint32_t s = std::max(width, height); s > 1; s /= 2) ++n;
  return n;
}

std::vector<TextureTexels> mip_chain(const TextureTexels& level0) {
  std::vector<TextureTexels> chain = {level0};
  const uint32_t levels = mip_level_count(level0.width, level0.height);
  for (uint32_t k = 1; k < levels; ++k) {
    const TextureTexels& src = chain.back();
    TextureTexels dst;
    dst.width = std::max(1u, src.width / 2);
    dst.height = std::max(1u, src.height / 2);
    dst.rgba.resize(size_t{4} * dst.width * dst.height);
    for (size_t y = 0; y < dst.height; ++y) {
      const size_t ys[2] = {std::min<size_t>(2 * y, src.height - 1),
                            std::min<size_t>(2 * y + 1, src.height - 1)};
      for (size_t x = 0; x < dst.width; ++x) {
        const size_t xs[2] = {std::min<size_t>(2 * x, src.width - 1),
                              std::min<size_t>(2 * x + 1, src.width - 1)};
        float colour[3] = {0, 0, 0};
        unsigned alpha = 0;
        for (size_t yy : ys) {
          for (size_t xx : xs) {
            const uint8_t* t = &src.rgba[4 * (yy * src.width + xx)];
            for (int c = 0; c < 3; ++c) colour[c] += linear_from_srgb8(t[c]);
            alpha += t[3];
          }
        }
        uint8_t* d = &dst.rgba[4 * (y * dst.width + x)];
        for (int c = 0; c < 3; ++c) d[c] = srgb8_from_linear(colour[c] * 0.25f);
        d[3] = static_cast<uint8_t>((alpha + 2) / 4);
      }
    }
    chain.push_back(std::move(dst));
  }
  return chain;
}

}  // namespace calf::mesh
