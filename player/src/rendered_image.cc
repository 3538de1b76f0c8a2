#include "calf/player/rendered_image.h"

#include <string>

namespace calf::player {
namespace {

bool complete(const RenderedImage& im) {
  const size_t n = size_t{im.width} * im.height;
  return im.color.size() == 3 * n && im.depth.size() == n;
}

}  // namespace

Status composite_nearest(const RenderedImage& layer, RenderedImage* into) {
  if (layer.width != into->width || layer.height != into->height || !complete(layer) ||
      !complete(*into)) {
    return Status(ErrorId::kPlayerOptions, "cannot composite a " + std::to_string(layer.width) +
                                               "x" + std::to_string(layer.height) +
                                               " image into a " + std::to_string(into->width) +
                                               "x" + std::to_string(into->height) +
                                               " one (sizes differ or buffers are incomplete)");
  }
  for (size_t i = 0; i < layer.depth.size(); ++i) {
    if (layer.depth[i] < into->depth[i]) {
      into->depth[i] = layer.depth[i];
      for (size_t k = 0; k < 3; ++k) into->color[3 * i + k] = layer.color[3 * i + k];
    }
  }
  return Status::Ok();
}

}  // namespace calf::player
