// What every renderer of every representation produces for one eye: linear colour plus the radial
// distance of the surface each pixel shows. The radial depth is what lets Playback put the
// outputs of several representations (a light field, tiles, surfels, a mesh) into one image.
#pragma once

#include <cstdint>
#include <vector>

#include "calf/format/status.h"

namespace calf::player {

// A rendered frame: linear RGB float (3 per pixel, HDR kept) and the radial distance from the eye
// to the surface each pixel shows (+inf for sky), row-major from the top row like ground truth.
struct RenderedImage {
  uint32_t width = 0, height = 0;
  std::vector<float> color;
  std::vector<float> depth;
};

// Depth compositing: each pixel of `into` takes `layer`'s colour and depth where `layer`'s depth
// is strictly nearer (a tie keeps `into`, so earlier layers win ties; a NaN depth never wins and
// is never beaten — it compares false — so it should not occur). Both images must have the same
// size and complete buffers: CALF-E403 otherwise, and `into` is unchanged.
Status composite_nearest(const RenderedImage& layer, RenderedImage* into);

}  // namespace calf::player
