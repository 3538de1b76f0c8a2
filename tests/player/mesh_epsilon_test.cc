// Epsilon (paper 004: the share of pixels where a triangle is missing), image_compare.h's
// missing_geometry(): hand-made depth images and rendered missing-triangle cases with a share
// computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "calf/player/image_compare.h"
#include "calf/player/mesh_renderer.h"
#include "mesh_scenes.h"

namespace calf::player {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

RenderedImage depth_image(uint32_t w, uint32_t h, std::vector<float> depth) {
  RenderedImage im;
  im.width = w;
  im.height = h;
  im.depth = std::move(depth);
  im.color.assign(size_t{3} * w * h, 0.0f);
  return im;
}

// 4 x 4 pixels: a reference at depth 2 with sky in its last row; the test image misses a surface
// at 2 pixels (sky there), shows 1 pixel 1 % farther (a surface behind the missing one), 1 pixel
// 0.05 % farther (within the 0.1 % tolerance), 1 pixel nearer (not counted), 1 NaN (counted) and
// a surface where the reference has sky (not counted): 4 of 16.
TEST(MissingGeometry, CountsFartherOrEmptyPixelsBeyondTheTolerance) {
  std::vector<float> ref(16, 2.0f), test(16, 2.0f);
  for (int i = 12; i < 16; ++i) ref[i] = kInf;
  test[0] = kInf;
  test[1] = kInf;
  test[2] = 2.02f;
  test[3] = 2.001f;
  test[4] = 1.5f;
  test[5] = NAN;
  test[12] = 3.0f;
  auto m = missing_geometry(depth_image(4, 4, test), depth_image(4, 4, ref));
  ASSERT_TRUE(m.ok()) << m.status().message();
  EXPECT_EQ(m->missing, 4u);
  EXPECT_EQ(m->pixels, 16u);
  EXPECT_DOUBLE_EQ(m->epsilon, 0.25);
  // A tighter tolerance also counts the 0.05 % pixel; a looser one drops the 1 % one.
  EXPECT_EQ(missing_geometry(depth_image(4, 4, test), depth_image(4, 4, ref), {1e-4, 0})->missing,
            5u);
  EXPECT_EQ(missing_geometry(depth_image(4, 4, test), depth_image(4, 4, ref), {0.02, 0})->missing,
            3u);
  // The same image against itself: nothing missing.
  EXPECT_EQ(missing_geometry(depth_image(4, 4, ref), depth_image(4, 4, ref))->epsilon, 0.0);
}

TEST(MissingGeometry, RejectsMismatchedImagesAndBadTolerances) {
  const RenderedImage a = depth_image(4, 4, std::vector<float>(16, 1.0f));
  const RenderedImage b = depth_image(4, 3, std::vector<float>(12, 1.0f));
  EXPECT_EQ(missing_geometry(a, b).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(missing_geometry(a, depth_image(0, 0, {})).status().id(), ErrorId::kImageCompare);
  RenderedImage short_depth = a;
  short_depth.depth.resize(10);
  EXPECT_EQ(missing_geometry(short_depth, a).status().id(), ErrorId::kImageCompare);
  EXPECT_EQ(missing_geometry(a, a, {-1, 0}).status().id(), ErrorId::kImageCompareOption);
  EXPECT_EQ(missing_geometry(a, a, {0, NAN}).status().id(), ErrorId::kImageCompareOption);
}

// Rendered: a square at distance 1 spanning x, y in [-0.5, 0.5] covers 32 x 32 of 64 x 64 pixels
// (fov 90), in front of a wall at distance 3 filling the view. Without the square (a visible set
// that lost it) the wall shows there instead, farther: epsilon = 1024 / 4096 = 0.25. Without the
// wall, the pixels the square covers are still right (nothing is missing there) and the rest
// misses the wall: 3072 / 4096.
TEST(MissingGeometry, MissingTriangleCasesOnRenderedDepth) {
  MeshDrawList full;
  full.materials = {{{0.5f, 0.5f, 0.5f}, {0, 0, 0}}};
  full.prototypes = {test::rectangle(-0.5, 0.5, -0.5, 0.5, -1), test::rectangle(-9, 9, -9, 9, -3)};
  full.objects.resize(2);
  full.objects[1].prototype = 1;
  Camera cam;
  cam.width = cam.height = 64;
  RenderedImage reference, image;
  ASSERT_TRUE(render_mesh_cpu(full, cam, {}, &reference).ok());

  MeshDrawList without_square = full;
  without_square.objects[0].all_triangles = false;  // an empty subset
  ASSERT_TRUE(render_mesh_cpu(without_square, cam, {}, &image).ok());
  auto m = missing_geometry(image, reference);
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m->missing, 1024u);
  EXPECT_DOUBLE_EQ(m->epsilon, 0.25);

  MeshDrawList without_wall = full;
  without_wall.objects.pop_back();
  ASSERT_TRUE(render_mesh_cpu(without_wall, cam, {}, &image).ok());
  EXPECT_EQ(missing_geometry(image, reference)->missing, 3072u);

  // One triangle of the square missing: half the square's pixels, the diagonal's centres going
  // to exactly one of the two triangles (top-left rule): 1024 = 496 + 528 (the lower-right
  // triangle takes the 32 centres on the diagonal i + j = 63, whose edge is its left one).
  MeshDrawList half = full;
  half.objects[0].all_triangles = false;
  half.objects[0].triangles = {1};
  ASSERT_TRUE(render_mesh_cpu(half, cam, {}, &image).ok());
  const uint64_t missing_lower = missing_geometry(image, reference)->missing;
  half.objects[0].triangles = {0};
  ASSERT_TRUE(render_mesh_cpu(half, cam, {}, &image).ok());
  const uint64_t missing_upper = missing_geometry(image, reference)->missing;
  EXPECT_EQ(missing_lower + missing_upper, 1024u);
  EXPECT_EQ(std::min(missing_lower, missing_upper), 496u);
  EXPECT_EQ(std::max(missing_lower, missing_upper), 528u);
}

}  // namespace
}  // namespace calf::player
