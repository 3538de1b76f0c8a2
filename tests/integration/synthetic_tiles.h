// A synthetic tile set shaped like a Seurat build (paper 000): tiles are cells of each cube
// face's k x k grid seen from the origin (the view region's centre), each cut by a plane tilted
// from the cell's direction at its own distance, textured projectively (W = 1 / distance, so the
// texture is uniform as seen from the origin) from its own s x s rectangle of the atlas, whose
// texels are a premultiplied smooth colour under a soft-edged disc of coverage. Made by code from
// a seed (splitmix64), so every machine builds the same set: the tiles track's tests, conformance
// generator and export tests use it instead of a builder.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <utility>

#include "calf/format/tile_set.h"

namespace calf::test {

struct TilesRng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
};

// `cells` x `cells` tiles per cube face (6 cells^2 tiles), each from an `s` x `s` texel rectangle
// packed row by row into an atlas `atlas_width` wide (its height is what the rectangles need).
inline TileSet make_synthetic_tile_set(uint32_t cells, uint32_t s, uint32_t atlas_width,
                                       uint64_t seed) {
  TilesRng rng{seed};
  TileSet set;
  set.view_volume = Box3{{-0.25, -0.1, -0.25}, {0.25, 0.1, 0.25}};
  const uint32_t per_row = atlas_width / s, count = 6 * cells * cells;
  set.atlas_width = atlas_width;
  set.atlas_height = (count + per_row - 1) / per_row * s;
  set.atlas_rgba.assign(size_t{4} * set.atlas_width * set.atlas_height, 0);
  // Cube face axes (OpenGL order): the face's direction and two in-face axes.
  const double axes[6][3][3] = {
      {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
      {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},   {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
      {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}}};
  uint32_t tile = 0;
  for (int face = 0; face < 6; ++face) {
    const auto& a = axes[face];
    for (uint32_t cy = 0; cy < cells; ++cy) {
      for (uint32_t cx = 0; cx < cells; ++cx, ++tile) {
        // Corner directions (not unit) of the cell: face + s * right + t * down.
        const double s0 = -1 + 2.0 * cx / cells, s1 = -1 + 2.0 * (cx + 1) / cells;
        const double t0 = -1 + 2.0 * cy / cells, t1 = -1 + 2.0 * (cy + 1) / cells;
        const double st[4][2] = {{s0, t1}, {s1, t1}, {s1, t0}, {s0, t0}};
        const double dist = 2 + 8 * rng.uniform();
        // Plane n . x = c: the face direction tilted by up to ~35 degrees.
        double n[3];
        const double tx = 0.7 * (rng.uniform() - 0.5), ty = 0.7 * (rng.uniform() - 0.5);
        for (int k = 0; k < 3; ++k) n[k] = a[0][k] + tx * a[1][k] + ty * a[2][k];
        const uint32_t rx = (tile % per_row) * s, ry = (tile / per_row) * s;
        Tile t;
        for (int i = 0; i < 4; ++i) {
          double dir[3];
          for (int k = 0; k < 3; ++k) dir[k] = a[0][k] + st[i][0] * a[1][k] + st[i][1] * a[2][k];
          const double nd = n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2];
          const double ncenter = n[0] * a[0][0] + n[1] * a[0][1] + n[2] * a[0][2];
          const double d = dist * ncenter / nd;  // the plane meets the face centre at `dist`
          for (int k = 0; k < 3; ++k) t.corners[i].position[k] = static_cast<float>(d * dir[k]);
          // Corner i at the texel centre of its rectangle's corner: (u, v) linear in (s, t) on
          // the face, so (U, V, W) = (u, v, 1) / d interpolated linearly in the plane.
          const double u = (rx + 0.5 + (s - 1) * (i == 1 || i == 2)) / set.atlas_width;
          const double v = (ry + 0.5 + (s - 1) * (i == 0 || i == 1)) / set.atlas_height;
          const double w = 1.0 / d;
          t.corners[i].uvw = {static_cast<float>(u * w), static_cast<float>(v * w),
                              static_cast<float>(w)};
          // Keep U <= W, V <= W exactly after rounding to binary32 (u, v < 1 by half a texel).
          t.corners[i].uvw[0] = std::min(t.corners[i].uvw[0], t.corners[i].uvw[2]);
          t.corners[i].uvw[1] = std::min(t.corners[i].uvw[1], t.corners[i].uvw[2]);
        }
        // Counter-clockwise seen from the origin (tile_set.h): the normal of (0, 1, 2) by the
        // right-hand rule points back at the origin.
        const auto& p0 = t.corners[0].position;
        const auto& p1 = t.corners[1].position;
        const auto& p2 = t.corners[2].position;
        const double e1[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        const double e2[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        const double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                              e1[0] * e2[1] - e1[1] * e2[0]};
        if (cr[0] * p0[0] + cr[1] * p0[1] + cr[2] * p0[2] > 0)
          std::swap(t.corners[1], t.corners[3]);
        set.tiles.push_back(t);
        // Texels: a smooth colour ramp premultiplied by a disc of coverage with a soft edge.
        const double base[3] = {rng.uniform(), rng.uniform(), rng.uniform()};
        for (uint32_t y = 0; y < s; ++y) {
          for (uint32_t x = 0; x < s; ++x) {
            const double fx = (x + 0.5) / s - 0.5, fy = (y + 0.5) / s - 0.5;
            const double r = std::sqrt(fx * fx + fy * fy);
            const double alpha = std::clamp((0.45 - r) / 0.1, 0.0, 1.0);
            uint8_t* p = &set.atlas_rgba[4 * ((size_t{ry} + y) * set.atlas_width + rx + x)];
            const uint8_t a8 = static_cast<uint8_t>(std::lround(alpha * 255));
            for (int c = 0; c < 3; ++c) {
              const double colour = std::clamp(base[c] + 0.4 * (c == 0 ? fx : fy), 0.0, 1.0);
              p[c] = static_cast<uint8_t>(std::lround(colour * a8));
            }
            p[3] = a8;
          }
        }
      }
    }
  }
  return set;
}

}  // namespace calf::test
