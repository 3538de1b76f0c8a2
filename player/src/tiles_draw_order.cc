// The tile set's validation, the render options' and the back-to-front drawing order
// (tiles_renderer.h), shared by both tile rasterisers.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "calf/player/tiles_renderer.h"

namespace calf::player {

namespace {

Status set_error(const std::string& what) {
  return Status(ErrorId::kTilesDraw, what);
}

}  // namespace

std::string_view tiles_blend_name(TilesBlend blend) {
  return blend == TilesBlend::kAlphaTest ? "alpha-test" : "sort";
}

Expected<TilesBlend> tiles_blend_from_name(std::string_view name) {
  if (name == "sort") return TilesBlend::kSorted;
  if (name == "alpha-test") return TilesBlend::kAlphaTest;
  return Status(ErrorId::kTilesRenderOptions,
                "tiles blend mode '" + std::string(name) + "' is neither sort nor alpha-test");
}

Status validate_tile_set(const TileSet& set) {
  const uint64_t texels = uint64_t{set.atlas_width} * set.atlas_height;
  if (set.atlas_rgba.size() != 4 * texels) {
    return set_error("the tile atlas has " + std::to_string(set.atlas_rgba.size()) +
                     " bytes, not 4 x " + std::to_string(set.atlas_width) + " x " +
                     std::to_string(set.atlas_height));
  }
  for (const Vec3& v : {set.view_volume.min, set.view_volume.max}) {
    if (!(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z))) {
      return set_error("the tile set's view region is not finite");
    }
  }
  if (!set.tiles.empty() && texels == 0) {
    return set_error(std::to_string(set.tiles.size()) + " tiles have an empty atlas");
  }
  for (size_t t = 0; t < set.tiles.size(); ++t) {
    for (size_t c = 0; c < 4; ++c) {
      const TileCorner& k = set.tiles[t].corners[c];
      const std::string where = "tile " + std::to_string(t) + ", corner " + std::to_string(c);
      for (float x : k.position) {
        if (!std::isfinite(x)) return set_error(where + ": a position is not finite");
      }
      const float w = k.uvw[2];
      if (!(std::isfinite(w) && w > 0)) {
        return set_error(where + ": w = " + std::to_string(w) + " is not > 0");
      }
      if (!(std::isfinite(k.uvw[0] / w) && std::isfinite(k.uvw[1] / w))) {
        return set_error(where + ": the texture coordinate is not finite");
      }
    }
  }
  return Status::Ok();
}

Status validate_tiles_render_options(const TilesRenderOptions& options) {
  if (!(std::isfinite(options.near) && options.near > 0)) {
    return Status(ErrorId::kTilesRenderOptions,
                  "tiles near distance " + std::to_string(options.near) + " is not > 0");
  }
  if (options.blend != TilesBlend::kSorted && options.blend != TilesBlend::kAlphaTest) {
    return Status(ErrorId::kTilesRenderOptions,
                  "tiles blend mode " + std::to_string(static_cast<int>(options.blend)) +
                      " is not one of sort, alpha-test");
  }
  if (!(options.occlusion_alpha == 0 ||
        (options.occlusion_alpha >= 0.5 && options.occlusion_alpha <= 1))) {
    return Status(ErrorId::kTilesRenderOptions, "tiles occlusion alpha " +
                                                    std::to_string(options.occlusion_alpha) +
                                                    " is neither 0 (off) nor in [0.5, 1]");
  }
  if (!(options.occlusion_epsilon > 0 && options.occlusion_epsilon <= 1)) {
    return Status(ErrorId::kTilesRenderOptions, "tiles occlusion epsilon " +
                                                    std::to_string(options.occlusion_epsilon) +
                                                    " is outside (0, 1]");
  }
  return Status::Ok();
}

void tiles_back_to_front(const TileSet& set, const Vec3& eye, std::vector<uint32_t>* order) {
  const size_t n = set.tiles.size();
  std::vector<double> distance(n);
  for (size_t t = 0; t < n; ++t) {
    Vec3 centre;
    for (const TileCorner& c : set.tiles[t].corners) {
      centre += Vec3{c.position[0], c.position[1], c.position[2]};
    }
    distance[t] = length(centre / 4 - eye);
  }
  order->resize(n);
  for (size_t t = 0; t < n; ++t) (*order)[t] = static_cast<uint32_t>(t);
  // Farthest first; the index breaks ties, so the order is a function of the set and the eye.
  std::sort(order->begin(), order->end(), [&](uint32_t a, uint32_t b) {
    return distance[a] != distance[b] ? distance[a] > distance[b] : a < b;
  });
}

}  // namespace calf::player
