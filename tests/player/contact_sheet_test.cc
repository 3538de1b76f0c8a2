// Contact sheets: tile placement, the heat-map column at its two ends (no error: black; full
// error: red), the pose rows chosen for long paths (hand-computed), errors, and the PNG read back.
#include "calf/player/contact_sheet.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace calf::player {
namespace {

namespace fs = std::filesystem;

std::array<uint8_t, 3> at(const Rgb8Image& s, uint32_t x, uint32_t y) {
  const size_t i = 3 * (size_t{y} * s.width + x);
  return {s.rgb[i], s.rgb[i + 1], s.rgb[i + 2]};
}

using Px = std::array<uint8_t, 3>;

TEST(ContactSheet, PlacesGroundTruthRenderedAndHeatMapTiles) {
  // Row 0: 2 x 1, ground truth black, rendered white: sRGB error 1 everywhere -> red.
  const std::vector<float> black(6, 0.0f), white(6, 1.0f);
  // Row 1: 3 x 2, identical mid grey: linear 0.5 is sRGB 0.7354 -> byte 188; no error -> black.
  const std::vector<float> grey(18, 0.5f);
  const std::vector<ContactSheetRow> rows = {{{2, 1, black}, {2, 1, white}},
                                             {{3, 2, grey}, {3, 2, grey}}};
  ContactSheetOptions o;
  o.gap = 2;
  o.background = 7;
  auto sheet = compose_contact_sheet(rows, o);
  ASSERT_TRUE(sheet.ok()) << sheet.status().to_string();
  // Width: the widest row, 3 tiles of 3 + 4 gaps of 2 = 17; height: 2 + 1 + 2 + 2 + 2 = 9.
  EXPECT_EQ(sheet->width, 17u);
  EXPECT_EQ(sheet->height, 9u);
  EXPECT_EQ(at(*sheet, 0, 0), (Px{7, 7, 7}));
  // Row 0 at y = 2: ground truth x 2..3, rendered x 6..7, heat map x 10..11.
  EXPECT_EQ(at(*sheet, 2, 2), (Px{0, 0, 0}));
  EXPECT_EQ(at(*sheet, 3, 2), (Px{0, 0, 0}));
  EXPECT_EQ(at(*sheet, 4, 2), (Px{7, 7, 7}));
  EXPECT_EQ(at(*sheet, 6, 2), (Px{255, 255, 255}));
  EXPECT_EQ(at(*sheet, 7, 2), (Px{255, 255, 255}));
  EXPECT_EQ(at(*sheet, 10, 2), (Px{255, 0, 0}));
  EXPECT_EQ(at(*sheet, 11, 2), (Px{255, 0, 0}));
  EXPECT_EQ(at(*sheet, 12, 2), (Px{7, 7, 7}));  // row 0 is narrower than the sheet
  EXPECT_EQ(at(*sheet, 2, 4), (Px{7, 7, 7}));   // gap between the rows
  // Row 1 at y = 5..6: ground truth x 2..4, rendered x 7..9, heat map x 12..14.
  EXPECT_EQ(at(*sheet, 2, 5), (Px{188, 188, 188}));
  EXPECT_EQ(at(*sheet, 9, 6), (Px{188, 188, 188}));
  EXPECT_EQ(at(*sheet, 12, 5), (Px{0, 0, 0}));
  EXPECT_EQ(at(*sheet, 14, 6), (Px{0, 0, 0}));
  EXPECT_EQ(at(*sheet, 16, 8), (Px{7, 7, 7}));
}

TEST(ContactSheet, PosesAreSpreadAndKeepTheEnds) {
  using V = std::vector<size_t>;
  EXPECT_EQ(contact_sheet_poses(10, 4), (V{0, 3, 6, 9}));  // k * 9 / 3
  EXPECT_EQ(contact_sheet_poses(8, 3), (V{0, 4, 7}));      // 0, 3.5 rounded up, 7
  EXPECT_EQ(contact_sheet_poses(3, 8), (V{0, 1, 2}));
  EXPECT_EQ(contact_sheet_poses(5, 1), (V{0}));
  EXPECT_EQ(contact_sheet_poses(5, 0), V{});
  EXPECT_EQ(contact_sheet_poses(0, 4), V{});
}

TEST(ContactSheet, RejectsWhatCannotBeShown) {
  const std::vector<float> px(12, 0.25f);
  EXPECT_EQ(compose_contact_sheet({}).status().id(), ErrorId::kImageCompare);
  const std::vector<ContactSheetRow> mismatched = {{{2, 2, px}, {2, 2, px}},
                                                   {{2, 2, px}, {2, 1, px}}};
  auto bad = compose_contact_sheet(mismatched);
  EXPECT_EQ(bad.status().id(), ErrorId::kImageCompare);
  EXPECT_NE(bad.status().to_string().find("row 1"), std::string::npos);
  const std::vector<ContactSheetRow> ok = {{{2, 2, px}, {2, 2, px}}};
  ContactSheetOptions o;
  o.gap = 65;
  EXPECT_EQ(compose_contact_sheet(ok, o).status().id(), ErrorId::kImageCompareOption);
  o = {};
  o.heat_full_scale = 0;
  EXPECT_EQ(compose_contact_sheet(ok, o).status().id(), ErrorId::kImageCompareOption);
  // 6000 pixels wide per tile: three tiles exceed the 16384-pixel side.
  const std::vector<float> wide(3 * 6000, 0.0f);
  const std::vector<ContactSheetRow> huge = {{{6000, 1, wide}, {6000, 1, wide}}};
  EXPECT_EQ(compose_contact_sheet(huge).status().id(), ErrorId::kImageCompareOption);
}

TEST(ContactSheet, PngReadsBackByteExact) {
  const fs::path dir = fs::temp_directory_path() / ("calf_sheet_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  Rgb8Image image{3, 2, {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18}};
  const fs::path p = dir / "sheet.png";
  ASSERT_TRUE(write_png_rgb8(p, image).ok());
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(p.string());
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().width, 3);
  EXPECT_EQ(in->spec().height, 2);
  std::vector<uint8_t> px(18);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  EXPECT_EQ(px, image.rgb);
  in.reset();
  EXPECT_EQ(write_png_rgb8(dir / "empty.png", Rgb8Image{}).id(), ErrorId::kImageCompare);
  EXPECT_FALSE(fs::exists(dir / "empty.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::player
