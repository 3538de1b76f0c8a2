// The mesh rasterisers (calf/player/mesh_renderer.h): the CPU reference against hand-computed
// depth and shading, its fill rule, subsets, near clipping and validation; the GL rasteriser
// against the CPU one (headless OSMesa, small images).
#include "calf/player/mesh_renderer.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "../gl_test_context.h"
#include "calf/format/colour.h"
#include "calf/format/mesh_texture.h"
#include "calf/player/gl_context.h"
#include "calf/player/image_compare.h"
#include "calf/player/mesh_representation.h"
#include "mesh_scenes.h"

namespace calf::player {
namespace {

using test::rectangle;

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

MeshDrawList one_object(MeshDrawPrototype p, MeshDrawMaterial m = {{0.5f, 0.5f, 0.5f}, {0, 0, 0}}) {
  MeshDrawList list;
  list.prototypes.push_back(std::move(p));
  list.materials.push_back(m);
  list.objects.push_back(MeshDrawObject{});
  return list;
}

RenderedImage cpu(const MeshDrawList& list, const Camera& cam, MeshRenderOptions o = {}) {
  RenderedImage out;
  const Status s = render_mesh_cpu(list, cam, o, &out);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

size_t covered(const RenderedImage& im) {
  size_t n = 0;
  for (float d : im.depth) n += std::isfinite(d) ? 1 : 0;
  return n;
}

// Depth convention: a plane facing the camera at distance 5 shows at each pixel the radial
// distance 5 / cos(angle to the axis) = 5 |d| / |d_z| for the pixel's ray d = (a, b, -1) (fov 90:
// tan 45 = 1), and the shading of mesh_draw_list.h with n = +z: 0.3 + 0.7 * L_z.
TEST(MeshCpuRenderer, PlaneAtKnownDistanceHasRadialDepthAndKnownShade) {
  const Camera cam = front_camera(16, 12);
  const RenderedImage im = cpu(one_object(rectangle(-50, 50, -50, 50, -5)), cam);
  ASSERT_EQ(im.width, 16u);
  const double shade = 0.5 * (0.3 + 0.7 * 0.50507627);
  for (uint32_t j = 0; j < 12; ++j) {
    for (uint32_t i = 0; i < 16; ++i) {
      const double a = (2 * (i + 0.5) / 16 - 1) * 16.0 / 12, b = 1 - 2 * (j + 0.5) / 12;
      const double expected = 5 * std::sqrt(a * a + b * b + 1);
      const size_t k = size_t{j} * 16 + i;
      EXPECT_NEAR(im.depth[k], expected, 2e-6 * expected) << i << "," << j;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(im.color[3 * k + c], shade, 1e-5);
    }
  }
}

// Two-sided: the same plane wound the other way shades the same (its normal faces the eye);
// emission adds.
TEST(MeshCpuRenderer, BackFacesAreDrawnAndEmissionAdds) {
  MeshDrawPrototype p = rectangle(-50, 50, -50, 50, -5);
  p.indices = {0, 2, 1, 0, 3, 2};
  const RenderedImage im =
      cpu(one_object(p, {{0.5f, 0.5f, 0.5f}, {0.25f, 0, 0}}), front_camera(8, 8));
  const double shade = 0.5 * (0.3 + 0.7 * 0.50507627);
  EXPECT_NEAR(im.color[0], shade + 0.25, 1e-5);
  EXPECT_NEAR(im.color[1], shade, 1e-5);
}

TEST(MeshCpuRenderer, EmptySceneIsInfinitelyFarAndBlack) {
  MeshDrawList list;
  const RenderedImage im = cpu(list, front_camera(8, 6));
  ASSERT_EQ(im.depth.size(), 48u);
  for (float d : im.depth) EXPECT_EQ(d, std::numeric_limits<float>::infinity());
  for (float c : im.color) EXPECT_EQ(c, 0.0f);
}

// A square at z = -1 spanning x, y in [-0.5, 0.5] covers image columns and rows 16..47 of 64
// (pixel centres 16.5 .. 47.5): 1024 pixels. Triangle 0 is the lower-right half (below the
// diagonal y = x), triangle 1 the upper-left half; a subset draws only its triangles.
TEST(MeshCpuRenderer, ObjectWithATriangleSubsetDrawsOnlyThose) {
  MeshDrawList list = one_object(rectangle(-0.5, 0.5, -0.5, 0.5, -1));
  const Camera cam = front_camera(64, 64);
  EXPECT_EQ(covered(cpu(list, cam)), 1024u);
  list.objects[0].all_triangles = false;
  list.objects[0].triangles = {1};
  const RenderedImage im = cpu(list, cam);
  // Upper-left half: image row j (down) and column i with (i + 0.5) < (64 - j - 0.5) + ... : a
  // pixel well above the diagonal is drawn, one well below is not.
  EXPECT_TRUE(std::isfinite(im.depth[20 * 64 + 20]));   // row 20 (upper), column 20 (left)
  EXPECT_FALSE(std::isfinite(im.depth[44 * 64 + 44]));  // row 44 (lower), column 44 (right)
  EXPECT_FALSE(std::isfinite(im.depth[20 * 64 + 8]));   // outside the square
  // The diagonal runs through pixel centres (i + 0.5 + j + 0.5 = 64): each triangle owns one side
  // of it, so the halves' pixels add up to the square's.
  list.objects[0].triangles = {0};
  EXPECT_EQ(covered(im) + covered(cpu(list, cam)), 1024u);
  list.objects[0].triangles = {};
  EXPECT_EQ(covered(cpu(list, cam)), 0u);
  EXPECT_EQ(mesh_draw_triangle_count(list), 0u);
}

// Watertight fill rule: a fan of 24 triangles around a centre covers every pixel of the union
// exactly once (drawn triangle by triangle, the counts add up to the union's) and no pixel inside
// the fan's inscribed circle is missed.
TEST(MeshCpuRenderer, TopLeftRuleCoversSharedEdgesExactlyOnce) {
  MeshDrawPrototype fan;
  const int n = 24;
  fan.positions = {0.013f, -0.021f, -2};
  for (int k = 0; k < n; ++k) {
    const double t = 2 * 3.141592653589793 * k / n;
    fan.positions.insert(fan.positions.end(), {static_cast<float>(1.3 * std::cos(t)),
                                               static_cast<float>(1.3 * std::sin(t)), -2});
  }
  for (uint32_t k = 0; k < n; ++k) {
    fan.indices.insert(fan.indices.end(), {0, 1 + k, 1 + (k + 1) % n});
  }
  MeshDrawList list = one_object(fan);
  const Camera cam = front_camera(61, 47);
  const RenderedImage all = cpu(list, cam);
  size_t sum = 0;
  list.objects[0].all_triangles = false;
  for (uint32_t k = 0; k < n; ++k) {
    list.objects[0].triangles = {k};
    sum += covered(cpu(list, cam));
  }
  EXPECT_EQ(sum, covered(all));
  // Inside radius 1.2 (inscribed radius 1.3 cos(pi / 24) = 1.289) at depth 2: every pixel.
  for (uint32_t j = 0; j < 47; ++j) {
    for (uint32_t i = 0; i < 61; ++i) {
      const double a = (2 * (i + 0.5) / 61 - 1) * 61.0 / 47, b = 1 - 2 * (j + 0.5) / 47;
      if (std::hypot(2 * a, 2 * b) < 1.2) {
        EXPECT_TRUE(std::isfinite(all.depth[j * 61 + i])) << i << "," << j;
      }
    }
  }
}

// The part of a triangle nearer than `near` is clipped: a floor running from behind the eye to
// far ahead shows no depth nearer than the near distance, and does show up beyond it.
TEST(MeshCpuRenderer, NearPlaneClips) {
  MeshDrawList list = one_object(rectangle(-3, 3, -3, 3, 0));
  list.objects[0].transform = {1, 0, 0, 0, 0, 0, 1, -0.2f, 0, -1, 0, 0};  // the floor y = -0.2
  MeshRenderOptions o;
  o.near = 0.5;
  const RenderedImage im = cpu(list, front_camera(32, 32), o);
  size_t n = 0;
  for (float d : im.depth) {
    if (std::isfinite(d)) {
      ++n;
      EXPECT_GE(d, 0.5f * (1 - 1e-6f));
    }
  }
  EXPECT_GT(n, 100u);
}

TEST(MeshDrawList, InvalidListsAndOptionsAreNamed) {
  MeshDrawList list = one_object(rectangle(0, 1, 0, 1, -1));
  EXPECT_TRUE(validate_mesh_draw_list(list).ok());
  MeshDrawList bad = list;
  bad.prototypes[0].indices[4] = 9;
  Status s = validate_mesh_draw_list(bad);
  EXPECT_EQ(s.id(), ErrorId::kMeshDrawList);
  EXPECT_NE(s.message().find("triangle 1"), std::string::npos) << s.message();
  bad = list;
  bad.objects[0].all_triangles = false;
  bad.objects[0].triangles = {1, 1};
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.objects[0].transform = {0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  EXPECT_NE(validate_mesh_draw_list(bad).message().find("singular"), std::string::npos);
  bad = list;
  bad.objects[0].material = 1;
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.prototypes[0].positions[2] = NAN;
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  RenderedImage out;
  MeshRenderOptions o;
  o.near = 0;
  EXPECT_EQ(render_mesh_cpu(list, front_camera(4, 4), o, &out).id(), ErrorId::kMeshRenderOptions);
}

// The GL rasteriser against the CPU reference on the feature scene from two poses: depth equal
// (relative 1e-4) except at <= 0.5 % of the pixels, each beside a depth edge of the CPU image
// (where the GPU's snapped vertices decide a centre on the other side of an edge; measured on
// llvmpipe: 0 and 1 pixels); colour PSNR >= 45 dB where both show the same surface (measured
// 150 dB: the shading is the same formula in float) and >= 35 dB over the whole image.
TEST(MeshGlRenderer, AgreesWithCpuReference) {
  CALF_REQUIRE_GL();
  const MeshDrawList list = test::feature_scene();
  auto gl = GlMeshRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().message();
  ASSERT_TRUE((*gl)->upload(list).ok());
  Camera poses[2] = {front_camera(96, 80), front_camera(96, 80)};
  poses[1].position = {1.5, 1.0, 0.5};
  poses[1].forward = {-0.35, -0.25, -1};
  for (const Camera& cam : poses) {
    RenderedImage g;
    const Status s = (*gl)->render(list, cam, {}, &g);
    ASSERT_TRUE(s.ok()) << s.message();
    const RenderedImage c = cpu(list, cam);
    const double p = *psnr(rgb_ref(g), rgb_ref(c));
    // GL where both show the same surface, CPU at the pixels whose depth differs.
    RenderedImage same_surface = g;
    size_t differing = 0, not_at_edge = 0;
    const auto close = [](float x, float y) {
      return (std::isinf(x) && std::isinf(y)) || std::abs(x - y) <= 1e-4f * std::min(x, y);
    };
    for (uint32_t j = 0; j < cam.height; ++j) {
      for (uint32_t i = 0; i < cam.width; ++i) {
        const size_t k = size_t{j} * cam.width + i;
        if (close(g.depth[k], c.depth[k])) continue;
        ++differing;
        for (int ch = 0; ch < 3; ++ch) same_surface.color[3 * k + ch] = c.color[3 * k + ch];
        std::printf(
            "  pixel (%u, %u): GL depth %.6g colour %.4f %.4f %.4f, CPU depth %.6g colour "
            "%.4f %.4f %.4f\n",
            i, j, g.depth[k], g.color[3 * k], g.color[3 * k + 1], g.color[3 * k + 2], c.depth[k],
            c.color[3 * k], c.color[3 * k + 1], c.color[3 * k + 2]);
        bool edge = false;
        for (int dj = -1; dj <= 1; ++dj) {
          for (int di = -1; di <= 1; ++di) {
            const int x = static_cast<int>(i) + di, y = static_cast<int>(j) + dj;
            if (x < 0 || y < 0 || x >= static_cast<int>(cam.width) ||
                y >= static_cast<int>(cam.height))
              continue;
            const float n = c.depth[size_t(y) * cam.width + x];
            if (!(std::isinf(n) && std::isinf(c.depth[k])) &&
                !(std::abs(n - c.depth[k]) <= 0.02f * std::min(n, c.depth[k])))
              edge = true;
          }
        }
        if (!edge) ++not_at_edge;
      }
    }
    const double p_same = *psnr(rgb_ref(same_surface), rgb_ref(c));
    std::printf(
        "GL vs CPU: PSNR %.2f dB (%.2f dB where both show the same surface), %zu of %zu depths "
        "differ (%zu not at an edge)\n",
        p, p_same, differing, g.depth.size(), not_at_edge);
    EXPECT_GE(p_same, 45.0);
    // One silhouette pixel flipped between a surface and the sky costs ~40 dB at this size.
    EXPECT_GE(p, 35.0);
    EXPECT_EQ(not_at_edge, 0u);
    EXPECT_LE(differing, g.depth.size() / 200);  // at most 0.5 %
  }
}

TEST(MeshGlRenderer, EmptyListAndSubsetsAndStructureChecks) {
  CALF_REQUIRE_GL();
  auto gl = GlMeshRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok());
  MeshDrawList empty;
  ASSERT_TRUE((*gl)->upload(empty).ok());
  RenderedImage im;
  ASSERT_TRUE((*gl)->render(empty, front_camera(8, 8), {}, &im).ok());
  for (float d : im.depth) EXPECT_EQ(d, std::numeric_limits<float>::infinity());

  MeshDrawList list = one_object(rectangle(-0.5, 0.5, -0.5, 0.5, -1));
  list.objects[0].all_triangles = false;
  list.objects[0].triangles = {1};
  ASSERT_TRUE((*gl)->upload(list).ok());
  ASSERT_TRUE((*gl)->render(list, front_camera(64, 64), {}, &im).ok());
  EXPECT_TRUE(std::isfinite(im.depth[20 * 64 + 20]));
  EXPECT_FALSE(std::isfinite(im.depth[44 * 64 + 44]));
  // Moved positions: re-uploaded, the square drawn farther away.
  for (size_t v = 2; v < list.prototypes[0].positions.size(); v += 3) {
    list.prototypes[0].positions[v] = -2;
  }
  ASSERT_TRUE((*gl)->update_positions(list, 0).ok());
  ASSERT_TRUE((*gl)->render(list, front_camera(64, 64), {}, &im).ok());
  const RenderedImage c = cpu(list, front_camera(64, 64));
  EXPECT_NEAR(im.depth[26 * 64 + 26], c.depth[26 * 64 + 26], 1e-4);
  // A list of another structure than the uploaded one.
  list.objects[0].triangles = {0, 1};
  EXPECT_EQ((*gl)->render(list, front_camera(8, 8), {}, &im).id(), ErrorId::kMeshGlStructure);
}

// Near clipping on both: a floor running from behind the eye, clipped at 0.5, shows the same
// pixels and depths (GL clips in homogeneous coordinates, the CPU in view space).
TEST(MeshGlRenderer, NearClippingAgreesWithCpu) {
  CALF_REQUIRE_GL();
  MeshDrawList list = one_object(rectangle(-3, 3, -3, 3, 0));
  list.objects[0].transform = {1, 0, 0, 0, 0, 0, 1, -0.2f, 0, -1, 0, 0};  // the floor y = -0.2
  MeshRenderOptions o;
  o.near = 0.5;
  auto gl = GlMeshRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok());
  ASSERT_TRUE((*gl)->upload(list).ok());
  const Camera cam = front_camera(48, 48);
  RenderedImage g;
  ASSERT_TRUE((*gl)->render(list, cam, o, &g).ok());
  const RenderedImage c = cpu(list, cam, o);
  size_t differing = 0;
  for (size_t k = 0; k < c.depth.size(); ++k) {
    const bool same = (std::isinf(g.depth[k]) && std::isinf(c.depth[k])) ||
                      std::abs(g.depth[k] - c.depth[k]) <= 1e-4f * c.depth[k];
    differing += same ? 0 : 1;
  }
  std::printf("near clipping: %zu of %zu pixels covered (CPU), %zu differ\n", covered(c),
              c.depth.size(), differing);
  EXPECT_GT(covered(c), 200u);
  EXPECT_LE(differing, 48u);  // at most one row: the clip line
}

// ---- Textures (mesh_draw_list.h "Texture") ----

// UVs for test::rectangle's vertices (lower-left, lower-right, upper-right, upper-left) mapping
// the texture upright (v = 0 at the top), repeated `n` times.
std::vector<float> rectangle_uvs(float n = 1) {
  return {0, n, n, n, n, 0, 0, 0};
}

// A w x h texture as its mip chain: texel (x, y) from `f`.
template <class F>
std::vector<mesh::TextureTexels> texture(uint32_t w, uint32_t h, F f) {
  mesh::TextureTexels t{w, h, {}};
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      const std::array<uint8_t, 4> c = f(x, y);
      t.rgba.insert(t.rgba.end(), c.begin(), c.end());
    }
  }
  return mesh::mip_chain(t);
}

std::array<uint8_t, 4> checker(uint32_t x, uint32_t y) {
  const uint8_t v = (x + y) % 2 ? 255 : 0;
  return {v, v, v, 255};
}

// A 64 x 64 one-texel checker filling an 8 x 8 image: 8 texels per pixel, lambda = 3, so level 3
// (each texel the linear average of black and white: sRGB 188) is sampled, and every pixel shows
// base * linear(188) * shade, where level 0 would alias to black or white.
TEST(MeshCpuRenderer, TextureIsSampledFromTheMipLevelOfTheFootprint) {
  MeshDrawPrototype p = rectangle(-1, 1, -1, 1, -1);
  p.uvs = rectangle_uvs();
  MeshDrawList list = one_object(p, {{0.5f, 0.5f, 0.5f}, {0, 0, 0}, 0});
  list.textures.push_back(texture(64, 64, checker));
  const RenderedImage im = cpu(list, front_camera(8, 8));
  const double shade = 0.5 * linear_from_srgb8(188) * (0.3 + 0.7 * 0.50507627);
  for (size_t k = 0; k < 64; ++k) {
    ASSERT_TRUE(std::isfinite(im.depth[k]));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(im.color[3 * k + c], shade, 2e-3) << k;
  }
  // Magnified: a 2 x 2 texture of red, green / blue, white over 8 x 8 pixels (lambda -2: bilinear
  // on level 0).
  list.textures[0] = texture(2, 2, [](uint32_t x, uint32_t y) -> std::array<uint8_t, 4> {
    const std::array<uint8_t, 4> c[4] = {
        {255, 0, 0, 255}, {0, 255, 0, 255}, {0, 0, 255, 255}, {255, 255, 255, 255}};
    return c[y * 2 + x];
  });
  const RenderedImage mag = cpu(list, front_camera(8, 8));
  // Pixel (1, 1): u = v = 1.5 / 8 = 0.1875, texel coordinate 0.375 - 0.5 = -0.125: taps -1 (=
  // texel 1 by repeat) weight 0.125 and 0 weight 0.875, the same along v. Red is 1 at texels
  // (0, 0) and (1, 1): 0.875^2 + 0.125^2; green 1 at (1, 0) and (1, 1): 0.125; blue at (0, 1)
  // and (1, 1): 0.125.
  const double lit = 0.5 * (0.3 + 0.7 * 0.50507627);
  const size_t k = 1 * 8 + 1;
  EXPECT_NEAR(mag.color[3 * k], lit * (0.875 * 0.875 + 0.125 * 0.125), 1e-5);
  EXPECT_NEAR(mag.color[3 * k + 1], lit * 0.125, 1e-5);
  EXPECT_NEAR(mag.color[3 * k + 2], lit * 0.125, 1e-5);
  // Without UVs the textured material draws untextured.
  list.prototypes[0].uvs.clear();
  EXPECT_NEAR(cpu(list, front_camera(8, 8)).color[0], lit, 1e-5);
}

TEST(MeshDrawList, TexturesAreValidated) {
  MeshDrawPrototype p = rectangle(-1, 1, -1, 1, -1);
  p.uvs = rectangle_uvs();
  MeshDrawList list = one_object(p, {{0.5f, 0.5f, 0.5f}, {0, 0, 0}, 0});
  list.textures.push_back(texture(4, 2, checker));
  EXPECT_TRUE(validate_mesh_draw_list(list).ok());
  MeshDrawList bad = list;
  bad.materials[0].base_colour_texture = 1;
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.textures[0].pop_back();  // no 1 x 1 level
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.textures[0][1].rgba.pop_back();
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.prototypes[0].uvs.pop_back();
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
  bad = list;
  bad.prototypes[0].uvs[0] = INFINITY;
  EXPECT_EQ(validate_mesh_draw_list(bad).id(), ErrorId::kMeshDrawList);
}

// A textured scene: a floor repeating a checker 24 times, seen at grazing angles (every mip level
// from magnification to the 1 x 1 level), a magnified 3 x 5 texture on a wall (not a power of
// two), and a strip whose triangle materials mix both textures and none (one GL pass each).
MeshDrawList textured_scene() {
  MeshDrawList list;
  list.textures.push_back(texture(64, 64, [](uint32_t x, uint32_t y) -> std::array<uint8_t, 4> {
    const bool on = ((x / 4) + (y / 4)) % 2 != 0;
    return {static_cast<uint8_t>(on ? 230 : 20), static_cast<uint8_t>(on ? 200 : 60),
            static_cast<uint8_t>(x * 4), 255};
  }));
  list.textures.push_back(texture(3, 5, [](uint32_t x, uint32_t y) -> std::array<uint8_t, 4> {
    return {static_cast<uint8_t>(60 * x + 40), static_cast<uint8_t>(50 * y), 128, 255};
  }));
  list.materials = {{{0.9f, 0.9f, 0.9f}, {0, 0, 0}, 0},
                    {{0.8f, 0.7f, 0.6f}, {0, 0, 0}, 1},
                    {{0.3f, 0.6f, 0.3f}, {0, 0, 0}, kMeshNoTexture}};
  MeshDrawPrototype floor = rectangle(-8, 8, -8, 8, 0);
  floor.uvs = rectangle_uvs(24);
  MeshDrawPrototype wall = rectangle(-1, 1, -0.5, 1.5, 0);
  wall.uvs = rectangle_uvs();
  MeshDrawPrototype strip;
  for (int i = 0; i < 5; ++i) {
    const float x = static_cast<float>(i) * 0.5f - 1;
    strip.positions.insert(strip.positions.end(), {x, -0.5f, 0, x, 0.5f, 0});
    strip.uvs.insert(strip.uvs.end(), {static_cast<float>(i) / 2, 1, static_cast<float>(i) / 2, 0});
  }
  for (uint32_t i = 0; i < 4; ++i) {
    const uint32_t a = 2 * i;
    strip.indices.insert(strip.indices.end(), {a, a + 2, a + 1, a + 1, a + 2, a + 3});
  }
  strip.triangle_materials = {0, 0, 1, kMeshObjectMaterial, 2, 2, 1, 0};
  list.prototypes = {floor, wall, strip};
  MeshDrawObject o;
  o.prototype = 0;
  o.transform = {1, 0, 0, 0, 0, 0, 1, -1, 0, -1, 0, -6};  // the floor y = -1
  list.objects.push_back(o);
  o.prototype = 1;
  o.material = 1;
  o.transform = {1, 0, 0, 1.5f, 0, 1, 0, -0.5f, 0, 0, 1, -4};
  list.objects.push_back(o);
  o.prototype = 2;
  o.material = 2;
  o.transform = {1, 0, 0, -1.2f, 0, 1, 0, 0.2f, 0, 0, 1, -3};
  list.objects.push_back(o);
  return list;
}

// GL (sRGB array texture, LINEAR_MIPMAP_LINEAR, REPEAT, coarse derivatives on llvmpipe) against
// the CPU reference's trilinear filter: colour PSNR where both show the same surface, printed.
// Measured on llvmpipe: 55.2 and 51.2 dB (max difference 0.012 and 0.015), no depth differs;
// 57.3 dB after the texture swap. GL without mips (GL_LINEAR minification) gives 16-17 dB.
TEST(MeshGlRenderer, TexturedAgreesWithCpuReference) {
  CALF_REQUIRE_GL();
  const MeshDrawList list = textured_scene();
  auto gl = GlMeshRenderer::make(gl_context()->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().message();
  const Status up = (*gl)->upload(list);
  ASSERT_TRUE(up.ok()) << up.message();
  Camera poses[2] = {front_camera(128, 96), front_camera(128, 96)};
  poses[1].position = {0.7, 0.3, 1.0};
  poses[1].forward = {-0.2, -0.35, -1};
  for (const Camera& cam : poses) {
    RenderedImage g;
    const Status st = (*gl)->render(list, cam, {}, &g);
    ASSERT_TRUE(st.ok()) << st.message();
    const RenderedImage c = cpu(list, cam);
    RenderedImage same_surface = g;
    size_t differing = 0, textured = 0;
    double max_diff = 0;
    for (size_t k = 0; k < c.depth.size(); ++k) {
      const bool same = (std::isinf(g.depth[k]) && std::isinf(c.depth[k])) ||
                        std::abs(g.depth[k] - c.depth[k]) <= 1e-4f * c.depth[k];
      if (!same) {
        ++differing;
        for (int ch = 0; ch < 3; ++ch) same_surface.color[3 * k + ch] = c.color[3 * k + ch];
        continue;
      }
      if (std::isfinite(c.depth[k])) ++textured;
      for (int ch = 0; ch < 3; ++ch)
        max_diff = std::max(max_diff, double{std::abs(g.color[3 * k + ch] - c.color[3 * k + ch])});
    }
    const double p_same = *psnr(rgb_ref(same_surface), rgb_ref(c));
    const double p = *psnr(rgb_ref(g), rgb_ref(c));
    std::printf(
        "textured GL vs CPU: PSNR %.2f dB where both show the same surface (%.2f dB whole "
        "image), max colour difference %.4f, %zu covered pixels, %zu of %zu depths differ\n",
        p_same, p, max_diff, textured, differing, c.depth.size());
    EXPECT_GT(textured, c.depth.size() / 3);
    EXPECT_GE(p_same, 45.0);
    EXPECT_LE(differing, c.depth.size() / 200);
  }
  // A material switching texture between frames: re-uploaded materials, new passes.
  MeshDrawList swapped = list;
  swapped.materials[0].base_colour_texture = 1;
  ASSERT_TRUE((*gl)->update_materials(swapped).ok());
  RenderedImage g;
  ASSERT_TRUE((*gl)->render(swapped, poses[0], {}, &g).ok());
  const double p = *psnr(rgb_ref(g), rgb_ref(cpu(swapped, poses[0])));
  std::printf("textured GL vs CPU after a texture swap: PSNR %.2f dB\n", p);
  EXPECT_GE(p, 45.0);
  swapped.materials[0].base_colour_texture = 2;
  EXPECT_EQ((*gl)->update_materials(swapped).id(), ErrorId::kMeshGlStructure);
}

// The representation over a draw list: render is the renderer's, and stats count triangles.
TEST(MeshRepresentation, FromDrawListRendersAndReports) {
  const MeshDrawList list = test::feature_scene();
  auto rep = MeshRepresentation::from_draw_list(list, Box3{{-1, -1, -1}, {1, 1, 1}}, {},
                                                RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(rep.ok()) << rep.status().message();
  const Camera cam = front_camera(32, 24);
  ASSERT_TRUE((*rep)->prepare(0, std::span<const Camera>(&cam, 1)).ok());
  EXPECT_EQ((*rep)->prepare(1, std::span<const Camera>(&cam, 1)).id(), ErrorId::kMeshPlayback);
  RenderedImage a;
  ASSERT_TRUE((*rep)->render(cam, &a).ok());
  const RenderedImage b = cpu(list, cam);
  EXPECT_EQ(a.color, b.color);
  EXPECT_EQ(a.depth, b.depth);
  // 2 + 12 + 7 + 12 + 10 * 16 * 2 + 12 triangles drawn, of 2 + 12 + 12 + 12 + 320 + 12.
  EXPECT_EQ((*rep)->triangles_drawn(), 365u);
  EXPECT_EQ((*rep)->triangles_total(), 370u);
  bool found = false;
  for (const Statistic& s : (*rep)->stats().entries) {
    if (s.name == "triangles drawn") found = s.value.find("365 of 370") != std::string::npos;
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace calf::player
