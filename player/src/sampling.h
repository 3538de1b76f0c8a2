// Private to the player: the texel fetches the CPU renderer shares (nearest depth, bilinear
// colour taps across face seams). Vector operations are calf/format/geometry.h's.
#pragma once

#include <cstdint>

#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/player/view_set.h"

namespace calf::player::internal {

// The four bilinear taps around texel-space position `c` on faces of `n` texels, with their
// weights (summing to 1). Taps that fall outside the face continue the face's plane and are
// re-projected onto whichever face that direction hits, like GL's seamless cube-map filtering
// (at a cube corner, where GL averages three texels, the off-diagonal tap lands on one of them).
struct BilinearTaps {
  Texel texel[4];
  double weight[4];
  // max(|du|, |dv|): how far the tap's centre is from the sampled position, in texels.
  double offset[4];
};
BilinearTaps bilinear_taps(const FaceTexelCoord& c, uint32_t n);

// The per-axis strengths of sharpened colour taps (LightfieldRenderOptions::colour_sharpen) read
// at bilinear fractions (ax, ay): k 4 a (1 - a) along each axis, 0 at a texel centre and k
// halfway between two.
void sharpen_strengths(const BilinearTaps& taps, double k, double strength[2]);

}  // namespace calf::player::internal
