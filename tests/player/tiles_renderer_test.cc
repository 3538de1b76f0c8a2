// The tile rasterisers (calf/player/tiles_renderer.h) and the tiles representation: the CPU
// reference and the GL rasteriser against hand-computed images (an opaque quad's pixel rectangle
// and colour, two 50 % layers composited over, projective texture coordinates, the depth of the
// nearest half-covered tile), the back-to-front order, the alpha-test mode, validation, and the GL
// rasteriser against the CPU one on synthesized sets (headless OSMesa, small images).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <span>
#include <vector>

#include "../gl_test_context.h"
#include "calf/format/colour.h"
#include "calf/player/gl_context.h"
#include "calf/player/image_compare.h"
#include "calf/player/tiles_renderer.h"
#include "calf/player/tiles_representation.h"

namespace calf::player {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

using ::calf::test::gl_context;

// A camera at the origin looking down -z, 90 degrees vertical field of view.
Camera front_camera(uint32_t w, uint32_t h) {
  Camera c;
  c.position = {0, 0, 0};
  c.forward = {0, 0, -1};
  c.up = {0, 1, 0};
  c.fov_y = 1.5707963267948966;
  c.width = w;
  c.height = h;
  return c;
}

// The sRGB decode written out here (IEC 61966-2-1), independently of calf/format/colour.h.
double decode(double e) {
  return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4);
}

// A tile facing the camera (+z) in the plane z, x in [x0, x1], y in [y0, y1], mapping the atlas
// rectangle u in [u0, u1], v in [v0, v1] (v down: the tile's top edge y1 takes v0), w = 1.
Tile quad(double x0, double x1, double y0, double y1, double z, double u0 = 0, double u1 = 1,
          double v0 = 0, double v1 = 1) {
  const auto f = [](double x) { return static_cast<float>(x); };
  Tile t;
  t.corners[0] = {{f(x0), f(y0), f(z)}, {f(u0), f(v1), 1}};
  t.corners[1] = {{f(x1), f(y0), f(z)}, {f(u1), f(v1), 1}};
  t.corners[2] = {{f(x1), f(y1), f(z)}, {f(u1), f(v0), 1}};
  t.corners[3] = {{f(x0), f(y1), f(z)}, {f(u0), f(v0), 1}};
  return t;
}

// An atlas of `w` x `h` texels, each given as RGBA bytes (premultiplied sRGB, tile_set.h).
void set_atlas(TileSet* set, uint32_t w, uint32_t h, const std::vector<std::array<uint8_t, 4>>& t) {
  set->atlas_width = w;
  set->atlas_height = h;
  set->atlas_rgba.clear();
  for (const auto& texel : t)
    set->atlas_rgba.insert(set->atlas_rgba.end(), texel.begin(), texel.end());
}

TileSet base_set() {
  TileSet s;
  s.view_volume = {{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  return s;
}

RenderedImage cpu(const TileSet& set, const Camera& cam, TilesRenderOptions o = {},
                  TilesFrameStats* stats = nullptr) {
  RenderedImage out;
  const Status s = render_tiles_cpu(set, tiles_linear_atlas(set), cam, o, &out, stats);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

RenderedImage gl(const TileSet& set, const Camera& cam, TilesRenderOptions o = {},
                 TilesFrameStats* stats = nullptr) {
  RenderedImage out;
  auto r = GlTilesRenderer::make(gl_context()->gl());
  EXPECT_TRUE(r.ok()) << r.status().message();
  if (!r.ok()) return out;
  Status s = (*r)->upload(set, tiles_linear_atlas(set));
  EXPECT_TRUE(s.ok()) << s.message();
  s = (*r)->render(set, cam, o, &out, stats);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

// Both backends, named for failure messages.
template <class F>
void for_both(const TileSet& set, const Camera& cam, TilesRenderOptions o, F check) {
  check(cpu(set, cam, o), "cpu");
  if (gl_context() != nullptr) check(gl(set, cam, o), "gl");
}

// The radial distance of pixel (i, j)'s ray to the plane z = -depth (fov 90: tan 45 = 1).
double radial(const Camera& cam, uint32_t i, uint32_t j, double depth) {
  const double a = (2 * (i + 0.5) / cam.width - 1) * cam.width / cam.height;
  const double b = 1 - 2 * (j + 0.5) / cam.height;
  return depth * std::sqrt(a * a + b * b + 1);
}

// One opaque quad of one colour at distance 5 spanning x, y in [-2.5, 2.5]: it covers the middle
// half of a 16 x 16 image (pixel centres at (i + 0.5) / 8 - 1 = x / 5, so i = 4 .. 11), with the
// colour's linear value and the plane's radial distance there, and nothing elsewhere.
TEST(TilesRenderer, OpaqueQuadFillsKnownRectangleWithItsColour) {
  TileSet set = base_set();
  set.tiles.push_back(quad(-2.5, 2.5, -2.5, 2.5, -5));
  set_atlas(&set, 2, 2, std::vector<std::array<uint8_t, 4>>(4, {200, 100, 50, 255}));
  const Camera cam = front_camera(16, 16);
  const double expected[3] = {decode(200 / 255.0), decode(100 / 255.0), decode(50 / 255.0)};
  for_both(set, cam, {}, [&](const RenderedImage& im, const char* backend) {
    ASSERT_EQ(im.width, 16u) << backend;
    for (uint32_t j = 0; j < 16; ++j) {
      for (uint32_t i = 0; i < 16; ++i) {
        const size_t k = j * 16 + i;
        const bool in = i >= 4 && i <= 11 && j >= 4 && j <= 11;
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(im.color[3 * k + c], in ? expected[c] : 0.0, 1e-3)
              << backend << " pixel " << i << "," << j;
        }
        if (in) {
          EXPECT_NEAR(im.depth[k], radial(cam, i, j, 5), 1e-4) << backend << " " << i << "," << j;
        } else {
          EXPECT_EQ(im.depth[k], kInf) << backend << " " << i << "," << j;
        }
      }
    }
  });
}

// Two 50 % layers over each other: the front (alpha byte 128, stored byte 64 so the encoded
// colour is 64 / 128 = 0.5 exactly) over the back (alpha 128, stored 128: encoded 1.0). Over:
// out = F + (1 - a) B with F = a decode(0.5), B = a decode(1) = a, a = 128 / 255. Depth: the front
// (a >= 0.5). The front tile is first in the set, so drawing in set order (or the reversed sort)
// gives B + (1 - a) F instead: the test fails if the order is not back to front.
TEST(TilesRenderer, TwoHalfLayersCompositeBackToFront) {
  TileSet set = base_set();
  // Texels 0, 1: the front's colour; 2, 3: the back's. Each tile's u range runs between its two
  // texels' centres, so bilinear filtering stays within one colour.
  set_atlas(&set, 4, 1,
            {{64, 64, 64, 128}, {64, 64, 64, 128}, {128, 0, 128, 128}, {128, 0, 128, 128}});
  set.tiles.push_back(quad(-10, 10, -10, 10, -4, 0.125, 0.375, 0, 1));  // front, first
  set.tiles.push_back(quad(-10, 10, -10, 10, -6, 0.625, 0.875, 0, 1));  // back
  const double a = 128 / 255.0;
  const double front = a * decode(0.5), back_r = a * decode(1.0), back_g = 0;
  const double expected[3] = {front + (1 - a) * back_r, front + (1 - a) * back_g,
                              front + (1 - a) * back_r};
  const double reversed_r = back_r + (1 - a) * front;
  ASSERT_GT(std::abs(expected[0] - reversed_r), 0.05);  // the order is visible
  const Camera cam = front_camera(8, 8);
  for_both(set, cam, {}, [&](const RenderedImage& im, const char* backend) {
    for (uint32_t j = 0; j < 8; ++j) {
      for (uint32_t i = 0; i < 8; ++i) {
        const size_t k = j * 8 + i;
        for (int c = 0; c < 3; ++c) {
          EXPECT_NEAR(im.color[3 * k + c], expected[c], 2e-3) << backend << " " << i << "," << j;
        }
        EXPECT_NEAR(im.depth[k], radial(cam, i, j, 4), 1e-4) << backend;
      }
    }
  });
}

// Depth is the nearest tile at least half covering the pixel: a front layer of alpha 127 / 255
// (< 0.5) over an opaque back layer shows the back's distance; the colour still blends both.
TEST(TilesRenderer, DepthSkipsTilesBelowHalfCoverage) {
  TileSet set = base_set();
  set_atlas(&set, 4, 1, {{0, 0, 127, 127}, {0, 0, 127, 127}, {255, 0, 0, 255}, {255, 0, 0, 255}});
  set.tiles.push_back(quad(-10, 10, -10, 10, -4, 0.125, 0.375, 0, 1));
  set.tiles.push_back(quad(-10, 10, -10, 10, -6, 0.625, 0.875, 0, 1));
  const double a = 127 / 255.0;
  const Camera cam = front_camera(6, 4);
  for_both(set, cam, {}, [&](const RenderedImage& im, const char* backend) {
    for (uint32_t j = 0; j < 4; ++j) {
      for (uint32_t i = 0; i < 6; ++i) {
        const size_t k = j * 6 + i;
        EXPECT_NEAR(im.color[3 * k + 0], 1 - a, 2e-3) << backend;
        EXPECT_NEAR(im.color[3 * k + 2], a * decode(1.0), 2e-3) << backend;
        EXPECT_NEAR(im.depth[k], radial(cam, i, j, 6), 1e-4) << backend;
      }
    }
  });
}

// The sort itself: farthest centre first, ties by index.
TEST(TilesRenderer, BackToFrontOrderIsByDistanceThenIndex) {
  TileSet set = base_set();
  set.tiles.push_back(quad(-1, 1, -1, 1, -2));
  set.tiles.push_back(quad(-1, 1, -1, 1, -7));
  set.tiles.push_back(quad(-1, 1, -1, 1, -3));
  set.tiles.push_back(quad(-1, 1, -1, 1, -7));
  std::vector<uint32_t> order;
  tiles_back_to_front(set, {0, 0, 0}, &order);
  EXPECT_EQ(order, (std::vector<uint32_t>{1, 3, 2, 0}));
  // From behind the far tiles (z = -10) the order turns around.
  tiles_back_to_front(set, {0, 0, -10}, &order);
  EXPECT_EQ(order, (std::vector<uint32_t>{0, 2, 1, 3}));
}

// The occlusion pre-pass: an opaque front tile (z = -5, x in [-2, 20]) whose centre lies 10.3 from
// the eye, and a small tile behind it (z = -6, x and y in [-1, 1]) whose centre lies 6 away. The
// sort draws the hidden tile last, over the front; the pre-pass drops its fragments (pixels 7 and 8
// of both axes, inside the front's i >= 5), and without it they show.
TEST(TilesRenderer, OcclusionPassHidesWhatTheSortDrawsLastFromBehind) {
  TileSet set = base_set();
  set_atlas(&set, 4, 1,
            {{200, 100, 50, 255}, {200, 100, 50, 255}, {0, 0, 255, 255}, {0, 0, 255, 255}});
  set.tiles.push_back(quad(-2, 20, -10, 10, -5, 0.125, 0.375, 0, 1));  // front, opaque
  set.tiles.push_back(quad(-1, 1, -1, 1, -6, 0.625, 0.875, 0, 1));     // behind it
  std::vector<uint32_t> order;
  tiles_back_to_front(set, {0, 0, 0}, &order);
  ASSERT_EQ(order, (std::vector<uint32_t>{0, 1}));  // the sort gets it wrong
  const Camera cam = front_camera(16, 16);
  const double front_r = decode(200 / 255.0);
  for (const double occlusion : {0.9, 0.0}) {
    TilesRenderOptions o;
    o.occlusion_alpha = occlusion;
    for_both(set, cam, o, [&](const RenderedImage& im, const char* backend) {
      for (uint32_t j = 0; j < 16; ++j) {
        for (uint32_t i = 5; i < 16; ++i) {
          const size_t k = j * 16 + i;
          const bool hidden = (i == 7 || i == 8) && (j == 7 || j == 8);
          const bool shows_back = hidden && occlusion == 0;
          EXPECT_NEAR(im.color[3 * k + 0], shows_back ? 0.0 : front_r, 1e-3)
              << backend << " occlusion " << occlusion << " pixel " << i << "," << j;
          EXPECT_NEAR(im.color[3 * k + 2], shows_back ? 1.0 : decode(50 / 255.0), 1e-3)
              << backend << " occlusion " << occlusion << " pixel " << i << "," << j;
        }
      }
    });
  }
}

// Projective texture coordinates: a full-screen tile whose right corners carry w = 3 (uvw = (3 u,
// 3 v, 3)) over an atlas of two texels, black and white. Along the tile at fraction s from the
// left, U = 3 s and W = 1 + 2 s, so u = 3 s / (1 + 2 s) (affine interpolation would give s); the
// bilinear filter between the texel centres 0.25 and 0.75 gives the linear value
// clamp(2 u - 0.5, 0, 1).
TEST(TilesRenderer, ProjectiveCoordinatesDividePerPixel) {
  TileSet set = base_set();
  Tile t = quad(-20, 20, -5, 5, -5);  // the whole 16 x 4 image (aspect 4) at distance 5
  for (int c : {1, 2}) {
    for (float& x : t.corners[c].uvw) x *= 3;
  }
  set.tiles.push_back(t);
  set_atlas(&set, 2, 1, {{0, 0, 0, 255}, {255, 255, 255, 255}});
  const Camera cam = front_camera(16, 4);
  for_both(set, cam, {}, [&](const RenderedImage& im, const char* backend) {
    for (uint32_t i = 0; i < 16; ++i) {
      const double s = (i + 0.5) / 16;
      const double u = 3 * s / (1 + 2 * s);
      const double expected = std::clamp(2 * u - 0.5, 0.0, 1.0);
      EXPECT_NEAR(im.color[3 * (16 + i)], expected, 2e-3) << backend << " column " << i;
    }
  });
}

// Scaling every corner's (U, V, W) by one factor changes nothing (the divide undoes it).
TEST(TilesRenderer, UniformWScaleLeavesTheImage) {
  TileSet set = base_set();
  set.tiles.push_back(quad(-3, 3, -2, 2, -5));
  set_atlas(&set, 2, 2, {{255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {90, 90, 90, 255}});
  TileSet scaled = set;
  for (TileCorner& c : scaled.tiles[0].corners) {
    for (float& x : c.uvw) x *= 2.5f;
  }
  const Camera cam = front_camera(20, 16);
  const RenderedImage a = cpu(set, cam), b = cpu(scaled, cam);
  for (size_t k = 0; k < a.color.size(); ++k) EXPECT_NEAR(a.color[k], b.color[k], 1e-5);
}

// Alpha test: the nearest tile with alpha >= 0.5 wins, unpremultiplied and opaque; the order of
// the set does not matter.
TEST(TilesRenderer, AlphaTestShowsNearestHalfCoveredTileOpaque) {
  TileSet set = base_set();
  // Front: alpha 153 (0.6), stored 76 (encoded 76 / 153); back: opaque red.
  set_atlas(&set, 4, 1, {{76, 0, 0, 153}, {76, 0, 0, 153}, {255, 0, 0, 255}, {255, 0, 0, 255}});
  set.tiles.push_back(quad(-10, 10, -10, 10, -6, 0.625, 0.875, 0, 1));
  set.tiles.push_back(quad(-10, 10, -10, 10, -4, 0.125, 0.375, 0, 1));
  TilesRenderOptions o;
  o.blend = TilesBlend::kAlphaTest;
  const Camera cam = front_camera(6, 4);
  for_both(set, cam, o, [&](const RenderedImage& im, const char* backend) {
    for (uint32_t j = 0; j < 4; ++j) {
      for (uint32_t i = 0; i < 6; ++i) {
        const size_t k = j * 6 + i;
        EXPECT_NEAR(im.color[3 * k], decode(76.0 / 153.0), 2e-3) << backend;
        EXPECT_NEAR(im.depth[k], radial(cam, i, j, 4), 1e-4) << backend;
      }
    }
  });
}

// An empty set draws nothing, without error, on both backends; overdraw 0.
TEST(TilesRenderer, EmptySetRendersNothing) {
  const TileSet set = base_set();
  const Camera cam = front_camera(8, 6);
  TilesFrameStats stats;
  const RenderedImage c = cpu(set, cam, {}, &stats);
  EXPECT_EQ(stats.fragments, 0u);
  for (float d : c.depth) EXPECT_EQ(d, kInf);
  for (float v : c.color) EXPECT_EQ(v, 0.0f);
  if (gl_context() == nullptr) return;
  const RenderedImage g = gl(set, cam, {}, &stats);
  ASSERT_EQ(g.depth.size(), 48u);
  EXPECT_EQ(stats.fragments, 0u);
  for (float d : g.depth) EXPECT_EQ(d, kInf);
  for (float v : g.color) EXPECT_EQ(v, 0.0f);
}

// Overdraw: three full-screen layers and one covering a quarter: mean (3 * 64 + 16) / 64, peak 4.
TEST(TilesRenderer, OverdrawCountsFragmentsPerCoveredPixel) {
  TileSet set = base_set();
  set_atlas(&set, 1, 1, {{10, 10, 10, 20}});
  for (double z : {-3.0, -4.0, -5.0}) set.tiles.push_back(quad(-9, 9, -9, 9, z));
  set.tiles.push_back(quad(-2, 0, 0, 2, -2));  // the top-left quarter of the 8 x 8 image
  const Camera cam = front_camera(8, 8);
  TilesFrameStats stats;
  cpu(set, cam, {}, &stats);
  EXPECT_EQ(stats.covered_pixels, 64u);
  EXPECT_EQ(stats.fragments, 3u * 64 + 16);
  EXPECT_EQ(stats.peak, 4u);
  EXPECT_DOUBLE_EQ(stats.mean_overdraw(), (3.0 * 64 + 16) / 64);
  if (gl_context() == nullptr) return;
  TilesFrameStats g;
  gl(set, cam, {}, &g);
  EXPECT_TRUE(g.measured);
  EXPECT_EQ(g.covered_pixels, 64u);
  EXPECT_EQ(g.fragments, 3u * 64 + 16);
  EXPECT_EQ(g.peak, 4u);
}

TEST(TilesRenderer, InvalidSetsAndOptionsAreRejected) {
  TileSet set = base_set();
  set.tiles.push_back(quad(-1, 1, -1, 1, -3));
  set_atlas(&set, 1, 1, {{1, 2, 3, 255}});
  EXPECT_TRUE(validate_tile_set(set).ok());
  TileSet bad = set;
  bad.atlas_rgba.pop_back();
  EXPECT_EQ(validate_tile_set(bad).id(), ErrorId::kTilesDraw);
  bad = set;
  bad.tiles[0].corners[2].uvw[2] = 0;
  EXPECT_EQ(validate_tile_set(bad).id(), ErrorId::kTilesDraw);
  bad = set;
  bad.tiles[0].corners[1].position[0] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(validate_tile_set(bad).id(), ErrorId::kTilesDraw);
  bad = set;
  bad.atlas_width = bad.atlas_height = 0;
  bad.atlas_rgba.clear();
  EXPECT_EQ(validate_tile_set(bad).id(), ErrorId::kTilesDraw);
  TilesRenderOptions o;
  o.near = 0;
  EXPECT_EQ(validate_tiles_render_options(o).id(), ErrorId::kTilesRenderOptions);
  o = {};
  for (double a : {0.3, 0.49, 1.01, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
    o.occlusion_alpha = a;
    EXPECT_EQ(validate_tiles_render_options(o).id(), ErrorId::kTilesRenderOptions) << a;
  }
  for (double a : {0.0, 0.5, 0.9, 1.0}) {
    o.occlusion_alpha = a;
    EXPECT_TRUE(validate_tiles_render_options(o).ok()) << a;
  }
  o = {};
  for (double e : {0.0, -1e-3, 1.5, std::numeric_limits<double>::infinity()}) {
    o.occlusion_epsilon = e;
    EXPECT_EQ(validate_tiles_render_options(o).id(), ErrorId::kTilesRenderOptions) << e;
  }
  EXPECT_EQ(tiles_blend_from_name("additive").status().id(), ErrorId::kTilesRenderOptions);
  EXPECT_EQ(*tiles_blend_from_name("alpha-test"), TilesBlend::kAlphaTest);
  RenderedImage out;
  EXPECT_EQ(
      render_tiles_cpu(bad, tiles_linear_atlas(set), front_camera(4, 4), {}, &out, nullptr).id(),
      ErrorId::kTilesDraw);
}

// A synthesized set: `n` tiles of random size, position (in front of the camera, some straddling
// the near plane), tilt and projective w, over a random atlas whose texels are partly transparent
// (a simple deterministic generator, portable across standard libraries).
TileSet random_set(int n, uint32_t seed, bool opaque) {
  uint32_t state = seed;
  const auto next = [&] {
    state = state * 1664525u + 1013904223u;
    return (state >> 8) / 16777216.0;
  };
  TileSet set = base_set();
  const uint32_t w = 64, h = 32;
  std::vector<std::array<uint8_t, 4>> texels(w * h);
  for (auto& t : texels) {
    const double a = opaque ? 1.0 : (next() < 0.3 ? 1.0 : next());
    const auto A = static_cast<uint8_t>(std::lround(255 * a));
    for (int c = 0; c < 3; ++c) t[c] = static_cast<uint8_t>(std::lround(A * next()));
    t[3] = A;
  }
  set_atlas(&set, w, h, texels);
  for (int k = 0; k < n; ++k) {
    const double cx = 8 * next() - 4, cy = 6 * next() - 3, cz = -1 - 8 * next();
    const double sx = 0.5 + 2 * next(), sy = 0.5 + 2 * next(), tilt = next() - 0.5;
    const double u0 = next() * 0.7, v0 = next() * 0.7, du = 0.05 + 0.25 * next(),
                 dv = 0.05 + 0.25 * next();
    Tile t;
    const double px[4] = {-1, 1, 1, -1}, py[4] = {-1, -1, 1, 1};
    const double us[4] = {u0, u0 + du, u0 + du, u0}, vs[4] = {v0 + dv, v0 + dv, v0, v0};
    for (int c = 0; c < 4; ++c) {
      const double x = cx + sx * px[c], y = cy + sy * py[c], z = cz + tilt * sx * px[c];
      const double wc = 0.5 + 2 * next();
      t.corners[c] = {
          {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)},
          {static_cast<float>(us[c] * wc), static_cast<float>(vs[c] * wc), static_cast<float>(wc)}};
    }
    set.tiles.push_back(t);
  }
  return set;
}

// GL against the CPU reference on synthesized sets, opaque and semi-transparent, from two poses,
// in both blend modes: depth equal (1e-4 relative) but at a few tile edges (<= 0.5 % of the
// pixels: where the GPU's snapped vertices put a pixel centre on the other side of an edge),
// colour PSNR >= 45 dB where the depths agree and >= 40 dB over the whole image (one 96 x 72
// pixel showing another tile costs about 43 dB); fragment counts within 1 %.
TEST(TilesGlRenderer, AgreesWithCpuReference) {
  CALF_REQUIRE_GL();
  Camera poses[2] = {front_camera(96, 72), front_camera(96, 72)};
  poses[1].position = {0.4, 0.3, 0.2};
  poses[1].forward = {-0.2, -0.1, -1};
  for (bool opaque : {true, false}) {
    const TileSet set = random_set(60, opaque ? 7 : 11, opaque);
    // The sort with and without the occlusion pre-pass, and the alpha test.
    for (int mode = 0; mode < 3; ++mode) {
      const TilesBlend blend = mode == 2 ? TilesBlend::kAlphaTest : TilesBlend::kSorted;
      TilesRenderOptions o;
      o.blend = blend;
      if (mode == 1) o.occlusion_alpha = 0;
      for (const Camera& cam : poses) {
        TilesFrameStats sg, sc;
        const RenderedImage g = gl(set, cam, o, &sg);
        const RenderedImage c = cpu(set, cam, o, &sc);
        ASSERT_EQ(g.color.size(), c.color.size());
        const double p = *psnr(rgb_ref(g), rgb_ref(c));
        // GL where both show the same nearest tile, CPU at the pixels whose depth differs.
        RenderedImage same_surface = g;
        size_t differing = 0;
        for (size_t k = 0; k < g.depth.size(); ++k) {
          const float x = g.depth[k], y = c.depth[k];
          const bool same =
              (std::isinf(x) && std::isinf(y)) || std::abs(x - y) <= 1e-4f * std::min(x, y);
          if (same) continue;
          ++differing;
          for (int ch = 0; ch < 3; ++ch) same_surface.color[3 * k + ch] = c.color[3 * k + ch];
        }
        const double p_same = *psnr(rgb_ref(same_surface), rgb_ref(c));
        std::printf(
            "tiles GL vs CPU (%s, %s%s): PSNR %.1f dB (%.1f dB where the depth agrees), depth "
            "differs at %zu of %zu, overdraw %.3f / %.3f, peak %u / %u\n",
            opaque ? "opaque" : "transparent", tiles_blend_name(blend).data(),
            mode == 1 ? ", no occlusion pass" : "", p, p_same, differing, g.depth.size(),
            sg.mean_overdraw(), sc.mean_overdraw(), sg.peak, sc.peak);
        EXPECT_GE(p_same, 45.0);
        EXPECT_GE(p, 40.0);  // one pixel showing another tile costs ~43 dB at this size
        EXPECT_LE(differing, g.depth.size() / 200);
        EXPECT_NEAR(static_cast<double>(sg.fragments), static_cast<double>(sc.fragments),
                    0.01 * sc.fragments);
        EXPECT_GT(sc.fragments, 0u);
      }
    }
  }
}

// The representation: stats as the HUD shows them, one frame, both backends agree.
TEST(TilesRepresentation, PlaysASetWithStatistics) {
  const TileSet set = random_set(10, 3, false);
  auto rep = TilesRepresentation::make(set, 2, 30, {}, RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(rep.ok()) << rep.status().message();
  TilesRepresentation& r = **rep;
  EXPECT_EQ(r.kind(), "tiles");
  EXPECT_EQ(r.track(), 2u);
  EXPECT_EQ(r.frame_count(), 1u);
  const Camera cam = front_camera(32, 24);
  EXPECT_TRUE(r.prepare(0, std::span<const Camera>(&cam, 1)).ok());
  EXPECT_EQ(r.prepare(1, std::span<const Camera>(&cam, 1)).id(), ErrorId::kTilesDraw);
  RenderedImage out;
  ASSERT_TRUE(r.render(cam, &out).ok());
  const RepresentationStats s = r.stats();
  EXPECT_EQ(s.title, "tiles track 2 (cpu)");
  ASSERT_GE(s.entries.size(), 4u);
  EXPECT_EQ(s.entries[0].value, "10");
  EXPECT_EQ(s.entries[1].value, "20");
  EXPECT_TRUE(r.last_frame_stats().measured);
  EXPECT_GT(r.last_frame_stats().peak, 0u);
  EXPECT_EQ(s.entries[3].value, "64 x 32 (0.0 Mtexels)");
  // The numbers reports compute with: the set's 10 quads and this render's overdraw, nothing else.
  const FrameFigures fig = r.figures();
  ASSERT_TRUE(fig.quads.has_value());
  EXPECT_EQ(fig.quads->count, 10u);
  EXPECT_EQ(fig.quads->peak_overdraw, r.last_frame_stats().peak);
  EXPECT_EQ(fig.quads->mean_overdraw, r.last_frame_stats().mean_overdraw());
  EXPECT_EQ(fig.triangles_drawn, 0u);
  EXPECT_FALSE(fig.points.has_value());
  EXPECT_EQ(TilesRepresentation::make(set, 0, 0, {}, RenderBackend::kCpu, nullptr).status().id(),
            ErrorId::kTilesDraw);
  if (gl_context() == nullptr) return;
  auto g = TilesRepresentation::make(set, 2, 30, {}, RenderBackend::kGl, &gl_context()->gl());
  ASSERT_TRUE(g.ok()) << g.status().message();
  RenderedImage go;
  ASSERT_TRUE((*g)->render(cam, &go).ok());
  EXPECT_GE(*psnr(rgb_ref(go), rgb_ref(out)), 45.0);
  EXPECT_EQ((*g)->stats().title, "tiles track 2 (gl)");
}

}  // namespace
}  // namespace calf::player
