// Texture mip chains and the trilinear, ray-cone filtered lookup of the ray tracer.
#include "calf/samples/texture.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "calf/format/colour.h"

namespace calf::samples {

namespace {

// The source texels each of `n_out` output texels averages when a row of `n_in` texels shrinks
// to n_out: output i covers [i, i + 1) * n_in / n_out, each source texel weighted by its overlap.
// Exact areas (not 2 x 2 blocks) keep odd sizes unbiased: every level has level 0's mean.
struct Tap {
  uint32_t index;
  float weight;
};
std::vector<std::vector<Tap>> box_taps(uint32_t n_in, uint32_t n_out) {
  std::vector<std::vector<Tap>> taps(n_out);
  const double ratio = static_cast<double>(n_in) / n_out;
  for (uint32_t i = 0; i < n_out; ++i) {
    const double lo = i * ratio, hi = (i + 1) * ratio;
    for (uint32_t s = static_cast<uint32_t>(lo); s < n_in && s < hi; ++s) {
      const double overlap = std::min<double>(hi, s + 1) - std::max<double>(lo, s);
      if (overlap > 0) taps[i].push_back({s, static_cast<float>(overlap / ratio)});
    }
  }
  return taps;
}

TextureLevel reduce(const TextureLevel& in) {
  TextureLevel out;
  out.width = std::max(1u, in.width / 2);
  out.height = std::max(1u, in.height / 2);
  const auto tx = box_taps(in.width, out.width), ty = box_taps(in.height, out.height);
  // Separable: rows first into `mid` (out.width x in.height), then columns.
  std::vector<glm::vec3> mid(static_cast<size_t>(out.width) * in.height, glm::vec3(0));
  for (uint32_t y = 0; y < in.height; ++y) {
    for (uint32_t x = 0; x < out.width; ++x) {
      glm::vec3 sum(0);
      for (const Tap& t : tx[x]) sum += t.weight * in.texels[size_t{y} * in.width + t.index];
      mid[size_t{y} * out.width + x] = sum;
    }
  }
  out.texels.assign(static_cast<size_t>(out.width) * out.height, glm::vec3(0));
  for (uint32_t y = 0; y < out.height; ++y) {
    for (uint32_t x = 0; x < out.width; ++x) {
      glm::vec3 sum(0);
      for (const Tap& t : ty[y]) sum += t.weight * mid[size_t{t.index} * out.width + x];
      out.texels[size_t{y} * out.width + x] = sum;
    }
  }
  return out;
}

// A texel index wrapped into [0, n) (repeat), for any integer-valued float.
uint32_t wrap(double i, uint32_t n) {
  const double r = i - std::floor(i / n) * n;
  return std::min(n - 1, static_cast<uint32_t>(r));
}

glm::vec3 bilinear(const TextureLevel& level, float u, float v) {
  // Texel centres sit at half-integers: texel x covers [x, x + 1) / width.
  const double x = static_cast<double>(u) * level.width - 0.5;
  const double y = static_cast<double>(v) * level.height - 0.5;
  const double x0 = std::floor(x), y0 = std::floor(y);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const uint32_t xa = wrap(x0, level.width), xb = wrap(x0 + 1, level.width);
  const uint32_t ya = wrap(y0, level.height), yb = wrap(y0 + 1, level.height);
  auto at = [&](uint32_t tx, uint32_t ty) { return level.texels[size_t{ty} * level.width + tx]; };
  const glm::vec3 top = at(xa, ya) * (1 - fx) + at(xb, ya) * fx;
  const glm::vec3 bottom = at(xa, yb) * (1 - fx) + at(xb, yb) * fx;
  return top * (1 - fy) + bottom * fy;
}

}  // namespace

std::shared_ptr<const Texture> make_texture(capture::SceneTexture image) {
  auto t = std::make_shared<Texture>();
  TextureLevel base;
  base.width = image.width;
  base.height = image.height;
  base.texels.resize(static_cast<size_t>(image.width) * image.height);
  for (size_t i = 0; i < base.texels.size(); ++i) {
    const uint8_t* p = &image.rgba[4 * i];
    base.texels[i] =
        glm::vec3(linear_from_srgb8(p[0]), linear_from_srgb8(p[1]), linear_from_srgb8(p[2]));
  }
  t->image = std::move(image);
  t->levels.push_back(std::move(base));
  while (t->levels.back().width > 1 || t->levels.back().height > 1) {
    TextureLevel next = reduce(t->levels.back());
    t->levels.push_back(std::move(next));
  }
  return t;
}

glm::vec3 sample_texture(const Texture& texture, const glm::vec2& uv, float lod) {
  if (texture.levels.empty()) return glm::vec3(1);
  // Only the fraction matters (repeat); taking it here keeps huge coordinates in range.
  auto fract = [](float c) { return std::isfinite(c) ? c - std::floor(c) : 0.0f; };
  const float u = fract(uv.x), v = fract(uv.y);
  const float last = static_cast<float>(texture.levels.size() - 1);
  const float l = std::isnan(lod) ? 0.0f : std::clamp(lod, 0.0f, last);
  const uint32_t l0 = static_cast<uint32_t>(l);
  const float f = l - static_cast<float>(l0);
  const glm::vec3 a = bilinear(texture.levels[l0], u, v);
  if (f <= 0 || l0 + 1 >= texture.levels.size()) return a;
  return a * (1 - f) + bilinear(texture.levels[l0 + 1], u, v) * f;
}

float texture_lod(const Texture& texture, float cone_width, float cos_incidence, float uv_area,
                  float world_area) {
  if (texture.levels.empty()) return 0;
  const double texels = static_cast<double>(texture.levels[0].width) * texture.levels[0].height;
  const double density2 = texels * uv_area / world_area;  // texels per scene unit, squared
  // A grazing hit stretches the footprint without bound; 1e-4 caps it at 13 levels of blur.
  const double across = cone_width * std::sqrt(density2) / std::max(cos_incidence, 1e-4f);
  const double lod = std::log2(across);
  return std::isnan(lod) ? 0.0f : static_cast<float>(std::clamp(lod, -64.0, 64.0));
}

float pixel_spread(float plane_pixel, float cos_axis) {
  const float c = std::clamp(cos_axis, 0.0f, 1.0f);
  return plane_pixel * c * std::sqrt(c);
}

}  // namespace calf::samples
