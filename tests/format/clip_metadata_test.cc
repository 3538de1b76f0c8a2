// The typed clip metadata values (calf/format/clip_metadata.h) against format/SPEC.md §5.
#include "calf/format/clip_metadata.h"

#include <gtest/gtest.h>

#include <string>

namespace calf::container {
namespace {

TEST(ClipMetadata, ViewVolumeIsSpecsSixNumbers) {
  EXPECT_EQ(kViewVolumeKey, "view_volume");
  // SPEC.md §5's example: %.17g of each coordinate, min then max.
  const Box3 box{{-0.6, 1.4, -0.6}, {0.6, 2.1, 0.6}};
  EXPECT_EQ(format_view_volume(box),
            "-0.59999999999999998 1.3999999999999999 -0.59999999999999998 "
            "0.59999999999999998 2.1000000000000001 0.59999999999999998");
  const std::string text = format_view_volume(box);
  const std::optional<Box3> back = parse_view_volume(&text);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(*back, box);
}

TEST(ClipMetadata, AViewVolumeThatIsNotSixOrderedFiniteNumbersIsNone) {
  EXPECT_FALSE(parse_view_volume(nullptr).has_value());
  for (const std::string text : {"", "1 2 3 4 5", "0 0 0 1 1 x", "0 0 0 nan 1 1", "0 0 0 inf 1 1",
                                 "2 0 0 1 1 1", "0 0 2 1 1 1"}) {
    EXPECT_FALSE(parse_view_volume(&text).has_value()) << text;
  }
  const std::string flat = "1 2 3 1 2 3";
  EXPECT_TRUE(parse_view_volume(&flat).has_value());
}

}  // namespace
}  // namespace calf::container
