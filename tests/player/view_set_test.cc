// View textures: creation, rect writes shaped like the decoder's texture updates, and their
// validation.
#include "calf/player/view_set.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace calf::player {
namespace {

View make(uint32_t n, bool material) {
  const Expected<View> v = View::make({1, 2, 3}, *LogDepthRange::make(0.5f, 20.0f), n, material);
  EXPECT_TRUE(v.ok()) << v.status().to_string();
  return *v;
}

TEST(ViewSet, StartsAsSky) {
  const View v = make(8, true);
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint16_t c : v.depth_face(face)) ASSERT_EQ(c, kLog16Sky);
    for (float c : v.color_face(face)) ASSERT_EQ(c, 0.0f);
    const Material m = v.material_at(face, 7, 7);
    EXPECT_EQ(m.reflect, 0.0f);
    EXPECT_EQ(m.refract, 0.0f);
    EXPECT_EQ(m.ior, 1.0f);
  }
  EXPECT_FALSE(make(4, false).has_material());
  EXPECT_EQ(make(4, false).material_at(CubeFace::kPosY, 0, 0).ior, 1.0f);
}

TEST(ViewSet, RectWritesLandWhereTheySay) {
  View v = make(8, true);
  // A 3 x 2 rect at (4, 5) from a source with a padded stride of 5 codes.
  const std::vector<uint16_t> src = {1, 2, 3, 99, 99, 4, 5, 6};
  ASSERT_TRUE(v.write_depth_rect(CubeFace::kNegY, {4, 5, 3, 2}, src, 5).ok());
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 4, 5), 1);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 6, 5), 3);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 4, 6), 4);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 6, 6), 6);
  EXPECT_EQ(v.depth_code_at(CubeFace::kNegY, 7, 6), kLog16Sky);
  EXPECT_EQ(v.depth_code_at(CubeFace::kPosY, 4, 5), kLog16Sky);
  const std::vector<float> rgb = {0.1f, 0.2f, 3.5f};  // HDR kept
  ASSERT_TRUE(v.write_color_rect(CubeFace::kPosZ, {7, 0, 1, 1}, rgb).ok());
  EXPECT_EQ(v.color_at(CubeFace::kPosZ, 7, 0)[2], 3.5f);
  const std::vector<float> mat = {0.25f, 0.5f, 1.5f};
  ASSERT_TRUE(v.write_material_rect(CubeFace::kNegX, {0, 7, 1, 1}, mat).ok());
  EXPECT_EQ(v.material_at(CubeFace::kNegX, 0, 7).ior, 1.5f);
}

TEST(ViewSet, RejectsBadViewsAndRects) {
  const LogDepthRange range = *LogDepthRange::make(1, 2);
  EXPECT_EQ(View::make({}, range, 0, false).status().id(), ErrorId::kPlayerViewSet);
  EXPECT_EQ(View::make({}, range, kMaxFaceSize + 1, false).status().id(), ErrorId::kPlayerViewSet);
  EXPECT_EQ(View::make({std::nan(""), 0, 0}, range, 4, false).status().id(),
            ErrorId::kPlayerViewSet);
  View v = make(8, false);
  const std::vector<uint16_t> codes(64, 7);
  const std::vector<float> rgb(3 * 64, 1);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {7, 0, 2, 1}, codes).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 0, 1}, codes).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0xFFFFFFFFu, 1, 2}, codes).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 4, 2}, codes, 3).id(), ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_depth_rect(CubeFace::kPosX, {0, 0, 8, 8}, std::span(codes).first(63)).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_color_rect(static_cast<CubeFace>(6), {0, 0, 1, 1}, rgb).id(),
            ErrorId::kPlayerRect);
  EXPECT_EQ(v.write_material_rect(CubeFace::kPosX, {0, 0, 1, 1}, rgb).id(),
            ErrorId::kPlayerNoMaterial);
  // Nothing was written by the failed calls.
  for (uint16_t c : v.depth_face(CubeFace::kPosX)) ASSERT_EQ(c, kLog16Sky);
}

}  // namespace
}  // namespace calf::player
