// Private to the player: the CPU reference's trilinear sampling of a mesh texture's mip chain,
// the filter mesh_draw_list.h states (GL's LINEAR_MIPMAP_LINEAR, REPEAT, sRGB decoded per texel
// before filtering).
#pragma once

#include <vector>

#include "calf/format/geometry.h"
#include "calf/format/mesh_texture.h"

namespace calf::player::internal {

// The level of detail lambda = log2(rho) of a footprint: the UV derivatives along x and y of the
// image, in UV units, scaled by level 0's size (rho as mesh_draw_list.h). -inf for a zero
// footprint.
double mesh_texture_lod(const mesh::TextureTexels& level0, double du_dx, double dv_dx, double du_dy,
                        double dv_dy);

// Linear RGB of `chain` at (u, v) and level of detail `lod`: bilinear on level 0 for lod <= 0,
// else trilinear between levels floor(lod) and floor(lod) + 1 (lod clamped to the last level).
Vec3 sample_mesh_texture(const std::vector<mesh::TextureTexels>& chain, double u, double v,
                         double lod);

}  // namespace calf::player::internal
