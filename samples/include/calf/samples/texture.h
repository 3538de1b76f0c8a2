// Base-colour textures of the sample scenes, and the filtered lookup the ray tracer shades with.
//
// A scene keeps a texture as it came from the model: 8-bit RGBA, sRGB-encoded, row 0 at the top
// (capture::SceneTexture, exactly what a scene file stores, so the export writes it unchanged).
// make_texture() adds what rendering needs once, at load time: the image decoded to linear RGB
// floats and its mip chain (each level a box-filtered reduction of level 0, half the size
// rounded down, to 1 x 1), so that a FrameTracer built per frame does not decode again.
//
// Texture coordinates are those of a scene file (format/SCENE.md): u across the image from its
// left edge, v down from its top row, the texel (x, y) covering [x, x + 1) / width by
// [y, y + 1) / height; both wrap (repeat, glTF's default). Alpha is not used: surfaces are opaque.
//
// Filtering (docs/RENDERING.md "Textures"): trilinear. A lookup takes a level of detail lambda
// (0: full resolution, each +1 halves it, continuous), interpolates bilinearly in the two levels
// around it and linearly between them. lambda comes from the ray's footprint (texture_lod): the
// width a ray cone has reached at the hit, against the texel density of the triangle it hit
// (Akenine-Moeller et al., "Texture Level of Detail Strategies for Real-Time Ray Tracing", Ray
// Tracing Gems ch. 20, 2019: the ray-cone method). Everything is float arithmetic in a fixed
// order, so the same lookup gives the same bits on every thread.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "calf/capture/scene_file.h"

namespace calf::samples {

// One mip level: width * height texels of linear RGB, row 0 at the top.
struct TextureLevel {
  uint32_t width = 0, height = 0;
  std::vector<glm::vec3> texels;
};

struct Texture {
  capture::SceneTexture image;       // the source: sRGB8 RGBA as loaded (exported as it is)
  std::vector<TextureLevel> levels;  // levels[0]: image in linear RGB; then halved to 1 x 1
};

// Decodes `image` to linear RGB (calf/format/colour.h's curve) and builds its mip chain. The
// image must hold width * height * 4 bytes with both sides >= 1 (validate_scene checks scenes).
std::shared_ptr<const Texture> make_texture(capture::SceneTexture image);

// The filtered linear RGB of `texture` at (u, v) (any finite values: they wrap) and level of
// detail `lod` (clamped to [0, last level]; NaN reads level 0).
glm::vec3 sample_texture(const Texture& texture, const glm::vec2& uv, float lod);

// The level of detail of a hit by the ray-cone method: log2 of the number of level-0 texels
// across the cone's footprint on the triangle. `cone_width` is the cone's width at the hit
// (scene units), `cos_incidence` |cos| of the angle between the ray and the triangle's normal,
// `uv_area` and `world_area` twice the triangle's area in texture space (unit square = 1) and in
// scene units. Texels per scene unit are sqrt(width * height * uv_area / world_area); a grazing
// hit stretches the footprint by 1 / cos_incidence (capped at 1e4). Clamped to [-64, 64]; NaN
// (a degenerate triangle: zero areas) gives 0, the full-resolution level.
float texture_lod(const Texture& texture, float cone_width, float cos_incidence, float uv_area,
                  float world_area);

// The angular width (radians, the side of a square of the same solid angle) of a pinhole pixel:
// a pixel `plane_pixel` wide on an image plane at distance 1 (2 / n for a cube face of n texels,
// 2 tan(fov_y / 2) / height for a camera), seen along a ray at angle theta to the optical axis
// (`cos_axis` = cos theta): plane_pixel * cos^1.5 theta, since its solid angle is
// plane_pixel^2 cos^3 theta. The tracer starts each primary ray cone with this spread.
float pixel_spread(float plane_pixel, float cos_axis);

}  // namespace calf::samples
