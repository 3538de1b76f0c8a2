// composite_nearest: per pixel the nearer radial depth wins; ties and mismatched sizes.
#include "calf/player/rendered_image.h"

#include <gtest/gtest.h>

#include <cmath>

namespace calf::player {
namespace {

RenderedImage image(std::vector<float> depth, float shade) {
  RenderedImage im;
  im.width = static_cast<uint32_t>(depth.size());
  im.height = 1;
  im.depth = std::move(depth);
  for (size_t i = 0; i < im.depth.size(); ++i) {
    im.color.insert(im.color.end(), {shade, shade + 0.25f, static_cast<float>(i)});
  }
  return im;
}

TEST(CompositeNearest, NearerDepthWinsPerPixel) {
  RenderedImage into = image({1, 5, INFINITY, 2}, 0.5f);
  const RenderedImage layer = image({3, 4, 7, 2}, 0.0f);
  ASSERT_TRUE(composite_nearest(layer, &into).ok());
  EXPECT_EQ(into.depth, (std::vector<float>{1, 4, 7, 2}));
  // Pixel 0 and the tie at pixel 3 keep `into`; pixels 1 and 2 take the layer.
  EXPECT_EQ(into.color,
            (std::vector<float>{0.5f, 0.75f, 0, 0, 0.25f, 1, 0, 0.25f, 2, 0.5f, 0.75f, 3}));
}

TEST(CompositeNearest, SkyOverSkyStaysSky) {
  RenderedImage into = image({INFINITY}, 0.5f);
  ASSERT_TRUE(composite_nearest(image({INFINITY}, 0.0f), &into).ok());
  EXPECT_EQ(into.color[0], 0.5f);
}

TEST(CompositeNearest, RefusesDifferentSizesAndLeavesTheImage) {
  RenderedImage into = image({1, 2}, 0.5f);
  const RenderedImage before = into;
  EXPECT_EQ(composite_nearest(image({0}, 0.0f), &into).id(), ErrorId::kPlayerOptions);
  RenderedImage short_colour = image({0, 0}, 0.0f);
  short_colour.color.pop_back();
  EXPECT_EQ(composite_nearest(short_colour, &into).id(), ErrorId::kPlayerOptions);
  EXPECT_EQ(into.color, before.color);
  EXPECT_EQ(into.depth, before.depth);
}

}  // namespace
}  // namespace calf::player
