// Private to the player: the triangle coverage of the CPU reference rasterisers (the mesh's,
// mesh_cpu_renderer.cc, and the tiles', tiles_cpu_renderer.cc), one copy of the rules their public
// headers state: near-plane clipping in the camera's frame (Sutherland-Hodgman, edge points
// computed from the endpoints in canonical order so that two triangles sharing an edge clip it to
// the same point), projection to image coordinates (the inverse of calf::camera_ray), and pixel
// centres covered by the top-left rule with edge functions evaluated in double.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "calf/format/camera.h"

namespace calf::player::internal {

// A vertex in the camera's frame: x along right, y along up, z along forward (eye at 0).
struct ViewVertex {
  double x, y, z;
};

// A point in image coordinates: x to the right, y down, pixel centres at half-integers.
struct ImagePoint {
  double x, y;
};

// Lexicographic order, so that an edge's computations run in one order whichever triangle asks.
inline bool before(const ViewVertex& a, const ViewVertex& b) {
  if (a.x != b.x) return a.x < b.x;
  if (a.y != b.y) return a.y < b.y;
  return a.z < b.z;
}
inline bool before(const ImagePoint& a, const ImagePoint& b) {
  return a.x != b.x ? a.x < b.x : a.y < b.y;
}

// The point of edge a-b at z = near (a and b on either side), computed from the edge's endpoints
// in canonical order so that two triangles sharing the edge clip it to the same point.
inline ViewVertex clip_point(ViewVertex a, ViewVertex b, double near) {
  if (before(b, a)) std::swap(a, b);
  const double s = (near - a.z) / (b.z - a.z);
  return {a.x + s * (b.x - a.x), a.y + s * (b.y - a.y), near};
}

// Sutherland-Hodgman against z >= near: 0, 3 or 4 vertices.
inline int clip_near(const std::array<ViewVertex, 3>& in, double near,
                     std::array<ViewVertex, 4>* out) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const ViewVertex& a = in[i];
    const ViewVertex& b = in[(i + 1) % 3];
    const bool a_in = a.z >= near, b_in = b.z >= near;
    if (a_in) (*out)[n++] = a;
    if (a_in != b_in) (*out)[n++] = clip_point(a, b, near);
  }
  return n;
}

// The edge function of a -> b at p: > 0 on the side the triangle's interior is on once the
// triangle is oriented (see rasterise()). Evaluated from the endpoints in canonical order and
// negated when they were swapped, so the two triangles sharing an edge get exactly opposite values.
inline double edge(ImagePoint a, ImagePoint b, double px, double py) {
  double sign = 1;
  if (before(b, a)) {
    std::swap(a, b);
    sign = -1;
  }
  return sign * ((b.x - a.x) * (py - a.y) - (b.y - a.y) * (px - a.x));
}

// The top-left rule for edge a -> b of a triangle whose interior is on the edge function's
// positive side: a left edge (interior to its right: the function grows with x) or a top edge
// (horizontal, interior below it in the y-down image: the function grows with y).
inline bool top_left(const ImagePoint& a, const ImagePoint& b) {
  const double ddx = -(b.y - a.y), ddy = b.x - a.x;
  return ddx > 0 || (ddx == 0 && ddy > 0);
}

inline bool inside(double e, bool tl) {
  return e > 0 || (e == 0 && tl);
}

// View coordinates -> image coordinates for `camera` (the inverse of camera_ray's pixel ->
// direction); the point must be in front (z > 0).
class ViewProjector {
 public:
  explicit ViewProjector(const Camera& camera)
      : width_(camera.width),
        height_(camera.height),
        h_(std::tan(camera.fov_y / 2)),
        aspect_(static_cast<double>(camera.width) / camera.height) {}
  ImagePoint operator()(const ViewVertex& v) const {
    const double a = v.x / (v.z * h_ * aspect_), b = v.y / (v.z * h_);
    return ImagePoint{(a + 1) * 0.5 * width_, (1 - b) * 0.5 * height_};
  }

 private:
  double width_, height_, h_, aspect_;
};

// Calls shade(i, j) for every pixel centre of a `width` x `height` image that the image-space
// triangle a, b, c covers by the top-left rule (either winding), rows top to bottom, each left to
// right. Degenerate and non-finite triangles cover nothing.
template <class Shade>
void rasterise(ImagePoint a, ImagePoint b, ImagePoint c, uint32_t width, uint32_t height,
               Shade&& shade) {
  const double area = edge(a, b, c.x, c.y);
  if (area == 0 || !std::isfinite(area)) return;
  if (area < 0) std::swap(b, c);
  const bool tl0 = top_left(a, b), tl1 = top_left(b, c), tl2 = top_left(c, a);
  const double w = width, h = height;
  // Pixel centres i + 0.5 within the bounds: i from ceil(min - 0.5) to floor(max - 0.5).
  const double x0 = std::max(0.0, std::ceil(std::min({a.x, b.x, c.x}) - 0.5));
  const double x1 = std::min(w - 1, std::floor(std::max({a.x, b.x, c.x}) - 0.5));
  const double y0 = std::max(0.0, std::ceil(std::min({a.y, b.y, c.y}) - 0.5));
  const double y1 = std::min(h - 1, std::floor(std::max({a.y, b.y, c.y}) - 0.5));
  if (!(x0 <= x1 && y0 <= y1)) return;
  for (double y = y0; y <= y1; ++y) {
    const double py = y + 0.5;
    for (double x = x0; x <= x1; ++x) {
      const double px = x + 0.5;
      if (inside(edge(a, b, px, py), tl0) && inside(edge(b, c, px, py), tl1) &&
          inside(edge(c, a, px, py), tl2)) {
        shade(static_cast<uint32_t>(x), static_cast<uint32_t>(y));
      }
    }
  }
}

// Clips the camera-frame triangle `view` at `near`, projects it and rasterises its pieces (a fan
// of the clipped polygon), calling shade(i, j) for each covered pixel.
template <class Shade>
void rasterise_clipped(const std::array<ViewVertex, 3>& view, double near,
                       const ViewProjector& project, uint32_t width, uint32_t height,
                       Shade&& shade) {
  std::array<ViewVertex, 4> poly;
  const int n = clip_near(view, near, &poly);
  if (n < 3) return;
  const ImagePoint p0 = project(poly[0]);
  for (int k = 1; k + 1 < n; ++k) {
    rasterise(p0, project(poly[k]), project(poly[k + 1]), width, height, shade);
  }
}

}  // namespace calf::player::internal
