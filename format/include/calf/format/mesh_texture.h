// The mip chain of a mesh track's base-colour texture (format/SPEC.md §11.4.6): one definition
// that the GL renderer uploads level by level and the CPU reference renderer samples, so both
// filter the same texels (GL's glGenerateMipmap is implementation-defined and never used).
//
// Level 0 is the texture (mesh::TextureTexels: sRGB RGBA8, row 0 at the top). Level k + 1 is
// max(1, floor(w / 2)) x max(1, floor(h / 2)) (GL's level sizes); its texel (x, y) is the box
// average of the level-k texels (2x + i, 2y + j), i, j in {0, 1}, clamped to level k's last
// column / row (so a side of 1 averages one texel twice): colour averaged in linear light
// (calf/format/colour.h linear_from_srgb8) and re-encoded with srgb8_from_linear, alpha averaged
// as bytes, rounded to nearest ((sum + 2) / 4). The chain ends at 1 x 1.
#pragma once

#include <vector>

#include "calf/format/mesh_layout.h"

namespace calf::mesh {

// The number of levels of a w x h chain: 1 + floor(log2(max(w, h))).
uint32_t mip_level_count(uint32_t width, uint32_t height);

// The whole chain of `level0` (which must hold width * height * 4 bytes, width and height >= 1):
// level0 itself first. Deterministic.
std::vector<TextureTexels> mip_chain(const TextureTexels& level0);

}  // namespace calf::mesh
