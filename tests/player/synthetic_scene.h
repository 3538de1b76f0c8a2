// Analytic test scenes for the player tests: a box room (seen from inside) with spheres, an
// optional mirror floor, a smooth procedural albedo and a smooth sky. Views are filled by casting
// every cube texel's ray (calf/format/cube.h) into the scene, so view textures and ground truth
// come from the same exact geometry.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "calf/format/cube.h"
#include "calf/format/log_depth.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/view_set.h"

namespace calf::player::testing {

struct Sphere {
  Vec3 centre;
  double radius = 1;
};

struct Scene {
  bool room = true;  // the inside of the box [-room_half, room_half]^3
  double room_half = 4;
  std::vector<Sphere> spheres;
  bool mirror_floor = false;  // the floor y = -room_half is a perfect mirror (material (1, 0, 1))
  bool uniform_sky = false;   // sky is one colour instead of a gradient
  // Multiplies the albedo's spatial frequencies: 1 is the smooth default, 8 a texture of a few
  // texels per period at the tests' face sizes.
  double texture_scale = 1;
};

inline Vec3 add(const Vec3& a, const Vec3& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
inline Vec3 mul(const Vec3& a, double s) {
  return {a.x * s, a.y * s, a.z * s};
}
inline double dot3(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
inline Vec3 unit(const Vec3& a) {
  return mul(a, 1.0 / std::sqrt(dot3(a, a)));
}

struct SceneHit {
  double t = std::numeric_limits<double>::infinity();
  int object = -1;  // 0..5 room walls (+x, -x, +y, -y, +z, -z), 6 + i sphere i
  Vec3 p, n;
};

// The nearest hit along unit ray (o, d) with t > 1e-9.
inline bool cast(const Scene& s, const Vec3& o, const Vec3& d, SceneHit* h) {
  *h = SceneHit{};
  if (s.room) {
    const double oc[3] = {o.x, o.y, o.z}, dc[3] = {d.x, d.y, d.z};
    for (int axis = 0; axis < 3; ++axis) {
      for (int sign = 0; sign < 2; ++sign) {
        const double plane = sign == 0 ? s.room_half : -s.room_half;
        if (dc[axis] == 0) continue;
        const double t = (plane - oc[axis]) / dc[axis];
        if (t > 1e-9 && t < h->t) {
          h->t = t;
          h->object = 2 * axis + sign;
        }
      }
    }
  }
  for (size_t i = 0; i < s.spheres.size(); ++i) {
    const Vec3 oc = sub(o, s.spheres[i].centre);
    const double b = dot3(oc, d), c = dot3(oc, oc) - s.spheres[i].radius * s.spheres[i].radius;
    const double disc = b * b - c;
    if (disc < 0) continue;
    const double t = -b - std::sqrt(disc);
    if (t > 1e-9 && t < h->t) {
      h->t = t;
      h->object = 6 + static_cast<int>(i);
    }
  }
  if (h->object < 0) return false;
  h->p = add(o, mul(d, h->t));
  if (h->object >= 6) {
    h->n = unit(sub(h->p, s.spheres[h->object - 6].centre));
  } else {
    const double sign = h->object % 2 == 0 ? -1 : 1;  // walls face inward
    h->n = {h->object / 2 == 0 ? sign : 0, h->object / 2 == 1 ? sign : 0,
            h->object / 2 == 2 ? sign : 0};
  }
  return true;
}

// Albedo, continuous across the room's walls (a function of position only) so that only the
// spheres' silhouettes are colour edges; at `scale` 1 smooth, tens of texels per period at the
// tests' face sizes (Scene::texture_scale multiplies its frequencies).
inline void albedo(const SceneHit& h, double scale, double rgb[3]) {
  const double k = h.object >= 6 ? 0.4 * (h.object - 5) : 0.0;
  const Vec3 p = mul(h.p, scale);
  rgb[0] = 0.5 + 0.3 * std::sin(0.9 * p.x + k) * std::cos(0.8 * p.z);
  rgb[1] = 0.5 + 0.3 * std::cos(0.7 * p.y - 0.9 * p.x + 2 * k);
  rgb[2] = 0.45 + 0.25 * std::sin(0.6 * p.z + 0.5 * p.y + k);
}

inline void sky(const Scene& s, const Vec3& d, double rgb[3]) {
  if (s.uniform_sky) {
    rgb[0] = 0.25, rgb[1] = 0.5, rgb[2] = 0.9;
    return;
  }
  rgb[0] = 0.3 + 0.2 * d.y;
  rgb[1] = 0.5 + 0.2 * d.x * d.z;
  rgb[2] = 0.8 + 0.15 * d.y;
}

// What ray (o, d) shows: colour, radial depth of the first surface (+inf for sky), material.
inline void shade(const Scene& s, const Vec3& o, const Vec3& d, double rgb[3], double* depth,
                  Material* m = nullptr, int bounces = 2) {
  SceneHit h;
  if (m) *m = Material{};
  if (!cast(s, o, d, &h)) {
    sky(s, d, rgb);
    *depth = std::numeric_limits<double>::infinity();
    return;
  }
  *depth = h.t;
  if (s.mirror_floor && h.object == 3 && bounces > 0) {
    if (m) *m = Material{1, 0, 1};
    const Vec3 r = unit(sub(d, mul(h.n, 2 * dot3(d, h.n))));
    double dummy;
    shade(s, h.p, r, rgb, &dummy, nullptr, bounces - 1);
    return;
  }
  albedo(h, s.texture_scale, rgb);
}

// The mean colour of k x k rays from `o` through the centres of a k x k grid over a pixel or
// texel: ray_at(u, v) gives the unit direction at offsets u, v in (0, 1) of its square.
template <class RayAt>
void mean_colour(const Scene& s, const Vec3& o, uint32_t k, RayAt ray_at, double rgb[3]) {
  double sum[3] = {0, 0, 0};
  for (uint32_t sy = 0; sy < k; ++sy) {
    for (uint32_t sx = 0; sx < k; ++sx) {
      double c[3], z;
      shade(s, o, ray_at((sx + 0.5) / k, (sy + 0.5) / k), c, &z);
      for (int ch = 0; ch < 3; ++ch) sum[ch] += c[ch] / (k * k);
    }
  }
  std::copy(sum, sum + 3, rgb);
}

// A view at `position` with faces of `n` texels, its depth range measured from the data. With
// `colour_samples` k > 1 a texel's colour is the mean of k x k rays through the centres of a
// k x k grid over the texel (anti-aliased, as calf-capture's), its depth and material the
// centre ray's.
inline View make_view(const Scene& s, const Vec3& position, uint32_t n, bool material = false,
                      uint32_t colour_samples = 1) {
  std::vector<float> color[6], depth[6], mat[6];
  double lo = std::numeric_limits<double>::infinity(), hi = 0;
  for (int f = 0; f < 6; ++f) {
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const Vec3 dd = direction_from_texel(cube_face_from_index(f), x, y, n);
        double rgb[3], z;
        Material m;
        shade(s, position, {dd.x, dd.y, dd.z}, rgb, &z, &m);
        if (colour_samples > 1) {
          const auto ray_at = [&](double u, double v) {
            return unit(direction_from_texel_coord({cube_face_from_index(f), x + u, y + v}, n));
          };
          mean_colour(s, position, colour_samples, ray_at, rgb);
        }
        for (double c : rgb) color[f].push_back(static_cast<float>(c));
        depth[f].push_back(static_cast<float>(z));
        mat[f].insert(mat[f].end(), {m.reflect, m.refract, m.ior});
        if (std::isfinite(z)) lo = std::min(lo, z), hi = std::max(hi, z);
      }
    }
  }
  if (!(hi > 0)) lo = 1, hi = 2;  // all sky
  const LogDepthRange range =
      *LogDepthRange::covering(static_cast<float>(lo), static_cast<float>(hi));
  View v = *View::make(position, range, n, material);
  for (int f = 0; f < 6; ++f) {
    std::vector<uint16_t> codes;
    for (float z : depth[f]) codes.push_back(range.encode_unchecked(z));
    const PixelRect all{0, 0, n, n};
    const CubeFace face = cube_face_from_index(f);
    if (!v.write_colour_rect(face, all, color[f]).ok() ||
        !v.write_depth_rect(face, all, codes).ok() ||
        (material && !v.write_material_rect(face, all, mat[f]).ok())) {
      std::abort();
    }
  }
  return v;
}

// Coverage of every texel of `v` (format/CAPTURE.md "Coverage"), cast here from the scene: the
// centre rays of the texel's 4 x 4 cells against the texel's centre-ray depth, a cell showing the
// texel's own surface when both are sky or their depths agree within min(4 / n, 5 %) relative.
inline void add_coverage(const Scene& s, View* v) {
  const uint32_t n = v->face_size();
  const double tol = std::min(0.05, 4.0 / n);
  v->add_coverage();
  for (int f = 0; f < 6; ++f) {
    const CubeFace face = cube_face_from_index(f);
    std::vector<float> cov;
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        double rgb[3], centre;
        shade(s, v->position(), direction_from_texel(face, x, y, n), rgb, &centre);
        int near = 0, far = 0, mask = 0;
        for (int cell = 0; cell < 16; ++cell) {
          const Vec3 d = unit(direction_from_texel_coord(
              {face, x + (cell % 4 + 0.5) / 4, y + (cell / 4 + 0.5) / 4}, n));
          double z;
          shade(s, v->position(), d, rgb, &z);
          if (!std::isfinite(centre)) {
            if (std::isfinite(z))
              ++near;
            else
              mask |= 1 << cell;
          } else if (!std::isfinite(z)) {
            ++far;
          } else if (std::fabs(std::log(z / centre)) > tol) {
            ++(z < centre ? near : far);
          } else {
            mask |= 1 << cell;
          }
        }
        cov.insert(cov.end(), {near / 16.0f, far / 16.0f, static_cast<float>(mask)});
      }
    }
    if (!v->write_coverage_rect(face, {0, 0, n, n}, cov).ok()) std::abort();
  }
}

inline ViewSet make_views(const Scene& s, const std::vector<Vec3>& positions, uint32_t n,
                          bool material = false, uint32_t colour_samples = 1) {
  ViewSet set;
  for (const Vec3& p : positions) {
    set.views.push_back(make_view(s, p, n, material, colour_samples));
  }
  return set;
}

// Ground truth of `camera`: colour and radial depth per pixel. With `colour_samples` k > 1 the
// colour is the mean of k x k rays over the pixel (anti-aliased), the depth the centre ray's.
inline RenderedImage ground_truth(const Scene& s, const Camera& camera,
                                  uint32_t colour_samples = 1) {
  RenderedImage img;
  img.width = camera.width;
  img.height = camera.height;
  const CameraFrame frame = camera_frame(camera);
  for (uint32_t j = 0; j < camera.height; ++j) {
    for (uint32_t i = 0; i < camera.width; ++i) {
      double rgb[3], z;
      shade(s, camera.position, camera_ray(camera, i, j), rgb, &z);
      if (colour_samples > 1) {
        const auto ray_at = [&](double u, double v) {
          return camera_ray_at(camera, frame, i + u, j + v);
        };
        mean_colour(s, camera.position, colour_samples, ray_at, rgb);
      }
      for (double c : rgb) img.color.push_back(static_cast<float>(c));
      img.depth.push_back(static_cast<float>(z));
    }
  }
  return img;
}

// PSNR over RGB for signals with peak 1.
inline double psnr(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) se += (double{a[i]} - b[i]) * (double{a[i]} - b[i]);
  const double mse = se / static_cast<double>(a.size());
  return mse == 0 ? 200.0 : 10 * std::log10(1.0 / mse);
}

// Two spheres in the default room, the scene most renderer tests use.
inline Scene room_with_spheres() {
  Scene s;
  s.spheres = {{{0, -0.5, -2.2}, 0.8}, {{1.6, 0.6, -1.2}, 0.45}};
  return s;
}

// Eight viewpoints on the corners of a cube of side `side` around `c`, first the nearest
// corners to +x+y+z.
inline std::vector<Vec3> corner_views(const Vec3& c, double side) {
  std::vector<Vec3> v;
  const double h = side / 2;
  for (int i = 0; i < 8; ++i) {
    v.push_back({c.x + ((i & 1) ? -h : h), c.y + ((i & 2) ? -h : h), c.z + ((i & 4) ? -h : h)});
  }
  return v;
}

}  // namespace calf::player::testing
