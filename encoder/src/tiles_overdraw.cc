// Overdraw measurement: the built quads rasterised as the GPU fills them (every quad whole, alpha
// ignored, no culling) into 90-degree square views from each eye, counting fragments per pixel.
// A view's overdraw is its fragments over its pixels; the report gives the mean over all views,
// the peak view and the largest per-pixel count.
#include <algorithm>
#include <cmath>

#include "tiles_internal.h"

namespace calf::encoder::tiles {

namespace {

struct P3 {
  double x, y, z;
};

// Clips a polygon to z >= near (Sutherland-Hodgman against one plane).
std::vector<P3> clip_near(const std::vector<P3>& in, double near) {
  std::vector<P3> out;
  for (size_t i = 0; i < in.size(); ++i) {
    const P3& a = in[i];
    const P3& b = in[(i + 1) % in.size()];
    const bool ia = a.z >= near, ib = b.z >= near;
    if (ia) out.push_back(a);
    if (ia != ib) {
      const double t = (near - a.z) / (b.z - a.z);
      out.push_back({a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), near});
    }
  }
  return out;
}

}  // namespace

OverdrawMeasure measure_overdraw(const TileSet& set, const std::vector<Vec3>& eyes,
                                 uint32_t directions, uint32_t resolution, uint32_t threads) {
  const std::vector<ViewAxes> axes = overdraw_view_axes(directions);
  const size_t views = eyes.size() * axes.size();
  std::vector<uint64_t> fragments(views, 0);
  std::vector<uint32_t> max_layers(views, 0);
  const double res = resolution;
  parallel_for(threads, views, [&](size_t vi) {
    const Vec3 eye = eyes[vi / axes.size()];
    const ViewAxes& ax = axes[vi % axes.size()];
    std::vector<uint16_t> count(size_t{resolution} * resolution, 0);
    for (const Tile& tile : set.tiles) {
      std::vector<P3> poly(4);
      bool left = true, right = true, below = true, above = true;
      double zmax = 0;
      for (int k = 0; k < 4; ++k) {
        const auto& p = tile.corners[k].position;
        const Vec3 d = Vec3{p[0], p[1], p[2]} - eye;
        poly[k] = {dot(d, ax.right), dot(d, ax.up), dot(d, ax.forward)};
        left &= poly[k].x < -poly[k].z;
        right &= poly[k].x > poly[k].z;
        below &= poly[k].y < -poly[k].z;
        above &= poly[k].y > poly[k].z;
        zmax = std::max(zmax, poly[k].z);
      }
      if (left || right || below || above || zmax <= 0) continue;
      poly = clip_near(poly, 1e-6 * zmax);
      if (poly.size() < 3) continue;
      std::vector<std::pair<double, double>> px(poly.size());
      double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
      for (size_t k = 0; k < poly.size(); ++k) {
        px[k] = {(poly[k].x / poly[k].z + 1) * 0.5 * res, (poly[k].y / poly[k].z + 1) * 0.5 * res};
        x0 = std::min(x0, px[k].first);
        x1 = std::max(x1, px[k].first);
        y0 = std::min(y0, px[k].second);
        y1 = std::max(y1, px[k].second);
      }
      double area = 0;
      for (size_t k = 0; k < px.size(); ++k) {
        const auto& a = px[k];
        const auto& b = px[(k + 1) % px.size()];
        area += a.first * b.second - b.first * a.second;
      }
      if (area == 0) continue;
      const double sign = area > 0 ? 1 : -1;
      const int ix0 = std::max(0, static_cast<int>(std::floor(x0 - 0.5)));
      const int ix1 = std::min(int(resolution) - 1, static_cast<int>(std::ceil(x1 - 0.5)));
      const int iy0 = std::max(0, static_cast<int>(std::floor(y0 - 0.5)));
      const int iy1 = std::min(int(resolution) - 1, static_cast<int>(std::ceil(y1 - 0.5)));
      for (int y = iy0; y <= iy1; ++y) {
        for (int x = ix0; x <= ix1; ++x) {
          const double cx = x + 0.5, cy = y + 0.5;
          bool inside = true;
          for (size_t k = 0; k < px.size() && inside; ++k) {
            const auto& a = px[k];
            const auto& b = px[(k + 1) % px.size()];
            const double e =
                (b.first - a.first) * (cy - a.second) - (b.second - a.second) * (cx - a.first);
            inside = e * sign >= 0;
          }
          if (inside) {
            uint16_t& c = count[size_t(y) * resolution + x];
            if (c < UINT16_MAX) ++c;
          }
        }
      }
    }
    uint64_t sum = 0;
    uint32_t mx = 0;
    for (uint16_t c : count) {
      sum += c;
      mx = std::max<uint32_t>(mx, c);
    }
    fragments[vi] = sum;
    max_layers[vi] = mx;
  });
  OverdrawMeasure m;
  m.views = static_cast<uint32_t>(views);
  const double pixels = res * res;
  uint64_t total = 0;
  for (size_t v = 0; v < views; ++v) {
    total += fragments[v];
    m.peak = std::max(m.peak, fragments[v] / pixels);
    m.max_layers = std::max(m.max_layers, max_layers[v]);
  }
  m.mean = views ? total / (pixels * views) : 0;
  return m;
}

}  // namespace calf::encoder::tiles
