// The tiles representation's render time (paper 000's budget: 72k triangles, average overdraw
// about 3) on the GL rasteriser under OSMesa, with the CPU reference as peer. The set is
// synthesized: every cube face of three nested cubes around the eye (half sizes 4, 6 and 9) cut
// into a grid of tiles (by default 40 x 50 per face: 6 x 3 x 2000 = 36000 tiles, 72000 triangles),
// over an atlas whose texels are opaque on the outer cube and 30 % opaque / 70 % partial on the
// inner two, so a 90 degree view from the centre draws about three layers at every pixel. Prints
// per image size the median render time (sort + draw + read-back; with and without the overdraw
// count, and without the occlusion pre-pass) over --repeats frames, and the measured overdraw.
//
//   bench-tiles_render_bench [--sizes 256 512 1024] [--grid 40 50] [--atlas 2048] [--repeats 5]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/player/gl_context.h"
#include "calf/player/tiles_renderer.h"

using namespace calf;
using namespace calf::player;

namespace {

TileSet synthesize(uint32_t gu, uint32_t gv, uint32_t atlas_size) {
  TileSet set;
  set.view_volume = {{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  set.atlas_width = set.atlas_height = atlas_size;
  set.atlas_rgba.resize(size_t{4} * atlas_size * atlas_size);
  uint32_t state = 12345;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0;
  };
  const double radii[3] = {4, 6, 9};
  // Tiles share the atlas round robin in cells of 16 x 16 texels, a third of the cell rows per
  // layer; the outer layer's rows are opaque.
  const uint32_t cells = atlas_size / 16;
  for (uint32_t y = 0; y < atlas_size; ++y) {
    const bool outer = y / 16 >= 2 * (cells / 3);
    for (uint32_t x = 0; x < atlas_size; ++x) {
      uint8_t* t = &set.atlas_rgba[4 * (size_t{y} * atlas_size + x)];
      const double a = outer || next() < 0.3 ? 1.0 : next();
      const auto A = static_cast<uint8_t>(std::lround(255 * a));
      for (int c = 0; c < 3; ++c) t[c] = static_cast<uint8_t>(std::lround(A * next()));
      t[3] = A;
    }
  }
  uint32_t cell = 0;
  for (int layer = 0; layer < 3; ++layer) {
    const double r = radii[layer];
    const uint32_t row0 = layer * cells / 3, rows = cells / 3;
    for (int face = 0; face < 6; ++face) {
      const int axis = face / 2;
      const double sign = face % 2 == 0 ? 1 : -1;
      for (uint32_t j = 0; j < gv; ++j) {
        for (uint32_t i = 0; i < gu; ++i) {
          const double a0 = -r + 2 * r * i / gu, a1 = -r + 2 * r * (i + 1) / gu;
          const double b0 = -r + 2 * r * j / gv, b1 = -r + 2 * r * (j + 1) / gv;
          const double corner[4][2] = {{a0, b0}, {a1, b0}, {a1, b1}, {a0, b1}};
          const uint32_t cx = cell % cells, cy = row0 + (cell / cells) % rows;
          ++cell;
          const double u0 = (16.0 * cx + 1) / set.atlas_width,
                       u1 = (16.0 * cx + 15) / set.atlas_width;
          const double v0 = (16.0 * cy + 1) / set.atlas_height,
                       v1 = (16.0 * cy + 15) / set.atlas_height;
          const double uv[4][2] = {{u0, v1}, {u1, v1}, {u1, v0}, {u0, v0}};
          Tile t;
          for (int c = 0; c < 4; ++c) {
            double p[3];
            p[axis] = sign * r;
            p[(axis + 1) % 3] = corner[c][0];
            p[(axis + 2) % 3] = corner[c][1];
            t.corners[c] = {
                {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])},
                {static_cast<float>(uv[c][0]), static_cast<float>(uv[c][1]), 1.0f}};
          }
          set.tiles.push_back(t);
        }
      }
    }
  }
  return set;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"tiles render time at the paper-000 budget under OSMesa, with the CPU reference"};
  std::vector<uint32_t> sizes = {256, 512, 1024}, grid = {40, 50};
  uint32_t atlas = 2048, repeats = 5, cpu_max_size = 512;
  app.add_option("--sizes", sizes, "square image sizes")->capture_default_str();
  app.add_option("--grid", grid, "tiles per cube face, across and down")
      ->expected(2)
      ->capture_default_str();
  app.add_option("--atlas", atlas, "atlas side in texels (>= 48)")->capture_default_str();
  app.add_option("--repeats", repeats, "timed frames after the first")->capture_default_str();
  app.add_option("--cpu-max-size", cpu_max_size, "largest size the CPU peer renders (0: none)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  Expected<std::unique_ptr<OsMesaContext>> ctx = OsMesaContext::make();
  if (!ctx.ok()) {
    fmt::print("no GL context: {}\n", ctx.status().to_string());
    return 1;
  }
  const GlFunctions& gl = (*ctx)->gl();
  const auto t0 = std::chrono::steady_clock::now();
  const TileSet set = synthesize(grid[0], grid[1], atlas);
  const TilesLinearAtlas linear = tiles_linear_atlas(set);
  const auto ms = [](auto a, auto b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const auto t1 = std::chrono::steady_clock::now();
  auto renderer = GlTilesRenderer::make(gl);
  if (!renderer.ok()) {
    fmt::print("{}\n", renderer.status().to_string());
    return 1;
  }
  if (Status s = (*renderer)->upload(set, linear); !s.ok()) {
    fmt::print("{}\n", s.to_string());
    return 1;
  }
  const auto t2 = std::chrono::steady_clock::now();
  fmt::print(
      "renderer: {} (GL {}.{}); {} tiles, {} triangles, atlas {}^2; set + linear atlas {:.0f} "
      "ms, upload {:.0f} ms; {} repeats\n",
      gl.renderer, gl.major_version, gl.minor_version, set.tiles.size(), 2 * set.tiles.size(),
      atlas, ms(t0, t1), ms(t1, t2), repeats + 1);
  {
    // The per-eye sort alone (part of every GL and CPU render).
    std::vector<double> sort_ms;
    std::vector<uint32_t> order;
    for (uint32_t k = 0; k <= repeats; ++k) {
      const auto a = std::chrono::steady_clock::now();
      tiles_back_to_front(set, {0.01 * k, 0, 0}, &order);
      sort_ms.push_back(ms(a, std::chrono::steady_clock::now()));
    }
    fmt::print("back-to-front sort of {} tiles: {:.2f} ms (median)\n", set.tiles.size(),
               median(sort_ms));
  }
  fmt::print("{:>6} {:>12} {:>14} {:>22} {:>10} {:>6} {:>10}\n", "size", "GL ms", "GL ms (no OD)",
             "GL ms (no OD, no occl.)", "overdraw", "peak", "CPU ms");
  Camera cam;
  cam.position = {0.1, 0.05, -0.1};
  cam.forward = {0.3, -0.2, -1};
  cam.up = {0, 1, 0};
  cam.fov_y = 1.5707963267948966;
  for (uint32_t size : sizes) {
    cam.width = cam.height = size;
    RenderedImage out;
    TilesFrameStats stats;
    // The defaults (overdraw counted, occlusion pre-pass); without the count; without either.
    std::vector<double> with, without, plain;
    for (int measure : {1, 0, -1}) {
      TilesRenderOptions o;
      o.measure_overdraw = measure == 1;
      if (measure < 0) o.occlusion_alpha = 0;
      for (uint32_t k = 0; k <= repeats; ++k) {
        const auto a = std::chrono::steady_clock::now();
        TilesFrameStats s;
        if (Status st = (*renderer)->render(set, cam, o, &out, &s); !st.ok()) {
          fmt::print("{}\n", st.to_string());
          return 1;
        }
        const double t = ms(a, std::chrono::steady_clock::now());
        if (k == 0) continue;  // the first frame compiles and allocates
        (measure == 1 ? with : measure == 0 ? without : plain).push_back(t);
        if (measure == 1) stats = s;
      }
    }
    double cpu_ms = NAN;
    if (size <= cpu_max_size) {
      const auto a = std::chrono::steady_clock::now();
      RenderedImage c;
      if (Status st = render_tiles_cpu(set, linear, cam, {}, &c, nullptr); !st.ok()) {
        fmt::print("{}\n", st.to_string());
        return 1;
      }
      cpu_ms = ms(a, std::chrono::steady_clock::now());
    }
    fmt::print("{:>6} {:>12.1f} {:>14.1f} {:>22.1f} {:>10.2f} {:>6} {:>10.0f}\n", size,
               median(with), median(without), median(plain), stats.mean_overdraw(), stats.peak,
               cpu_ms);
  }
  return 0;
}
