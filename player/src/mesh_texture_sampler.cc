// Trilinear sampling of a mesh texture on the CPU (rules in mesh_texture_sampler.h).
#include "mesh_texture_sampler.h"

#include <algorithm>
#include <cmath>

#include "calf/format/colour.h"

namespace calf::player::internal {
namespace {

// Wraps texel coordinate i into [0, n) (GL_REPEAT).
int64_t wrap(int64_t i, int64_t n) {
  const int64_t r = i % n;
  return r < 0 ? r + n : r;
}

// GL_LINEAR on one level: the four texels around (u * w - 0.5, v * h - 0.5), decoded to linear.
Vec3 bilinear(const mesh::TextureTexels& t, double u, double v) {
  const double x = u * t.width - 0.5, y = v * t.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double ax = x - fx, ay = y - fy;
  const int64_t w = t.width, h = t.height;
  // A UV far outside [0, 1] keeps its fraction: reduce before converting to an integer.
  const int64_t x0 = wrap(static_cast<int64_t>(std::fmod(fx, static_cast<double>(w))), w);
  const int64_t y0 = wrap(static_cast<int64_t>(std::fmod(fy, static_cast<double>(h))), h);
  const int64_t xs[2] = {x0, wrap(x0 + 1, w)}, ys[2] = {y0, wrap(y0 + 1, h)};
  const double wx[2] = {1 - ax, ax}, wy[2] = {1 - ay, ay};
  Vec3 sum{0, 0, 0};
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const uint8_t* p = &t.rgba[4 * static_cast<size_t>(ys[j] * w + xs[i])];
      const double k = wx[i] * wy[j];
      sum =
          sum + Vec3{linear_from_srgb8(p[0]), linear_from_srgb8(p[1]), linear_from_srgb8(p[2])} * k;
    }
  }
  return sum;
}

}  // namespace

double mesh_texture_lod(const mesh::TextureTexels& level0, double du_dx, double dv_dx, double du_dy,
                        double dv_dy) {
  const double w = level0.width, h = level0.height;
  const double rx = std::hypot(du_dx * w, dv_dx * h), ry = std::hypot(du_dy * w, dv_dy * h);
  return std::log2(std::max(rx, ry));
}

Vec3 sample_mesh_texture(const std::vector<mesh::TextureTexels>& chain, double u, double v,
                         double lod) {
  if (!(lod > 0)) return bilinear(chain[0], u, v);
  const double last = static_cast<double>(chain.size() - 1);
  const double l = std::min(lod, last);
  const size_t d1 = static_cast<size_t>(std::floor(l));
  const double f = l - static_cast<double>(d1);
  const Vec3 a = bilinear(chain[d1], u, v);
  if (d1 + 1 >= chain.size() || f == 0) return a;
  return a * (1 - f) + bilinear(chain[d1 + 1], u, v) * f;
}

}  // namespace calf::player::internal
