// Tests of the cell / tile grids and the culling quadtree (format/include/calf/format/grid.h).
#include "calf/format/grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace calf {
namespace {

FaceGrid must(Expected<FaceGrid> g) {
  EXPECT_TRUE(g.ok()) << g.status().to_string();
  return *g;
}

// Every texel of the face is in exactly one cell, and cell_index_at_texel agrees with the rects.
void expect_partition(const FaceGrid& g) {
  const uint32_t n = g.face_size();
  std::vector<int> owner(static_cast<size_t>(n) * n, -1);
  for (uint32_t i = 0; i < g.cell_count(); ++i) {
    const PixelRect r = *g.cell_rect(i);
    ASSERT_GT(r.width, 0u);
    ASSERT_GT(r.height, 0u);
    ASSERT_LE(r.x + r.width, n);
    ASSERT_LE(r.y + r.height, n);
    for (uint32_t y = r.y; y < r.y + r.height; ++y) {
      for (uint32_t x = r.x; x < r.x + r.width; ++x) {
        ASSERT_EQ(owner[y * n + x], -1) << "texel in two cells";
        owner[y * n + x] = static_cast<int>(i);
        ASSERT_EQ(g.cell_index_at_texel(x, y), i);
      }
    }
  }
  for (int o : owner) ASSERT_NE(o, -1) << "texel in no cell";
}

TEST(GridTest, ExactMultipleHasEqualCells) {
  const FaceGrid g = must(FaceGrid::with_cell_size(256, 64));
  EXPECT_EQ(g.cells_per_side(), 4u);
  EXPECT_EQ(g.cell_count(), 16u);
  EXPECT_EQ(*g.cell_rect(0), (PixelRect{0, 0, 64, 64}));
  EXPECT_EQ(*g.cell_rect(6), (PixelRect{128, 64, 64, 64}));  // row-major: (2, 1)
  EXPECT_EQ(g.cell_index(2, 1), 6u);
  expect_partition(g);
}

TEST(GridTest, NonMultipleHasSmallerEdgeCells) {
  const FaceGrid g = must(FaceGrid::with_cell_size(100, 64));
  EXPECT_EQ(g.cells_per_side(), 2u);
  EXPECT_EQ(*g.cell_rect(1), (PixelRect{64, 0, 36, 64}));
  EXPECT_EQ(*g.cell_rect(3), (PixelRect{64, 64, 36, 36}));
  expect_partition(g);
  for (uint32_t face : {1u, 3u, 4u, 5u, 17u, 63u, 65u, 129u}) {
    for (uint32_t cell : {1u, 4u, 7u, 16u, 64u, 200u})
      expect_partition(must(FaceGrid::with_cell_size(face, cell)));
  }
}

TEST(GridTest, CellIndexRectRoundTrip) {
  const FaceGrid g = must(FaceGrid::with_cell_size(1000, 48));
  for (uint32_t i = 0; i < g.cell_count(); ++i) {
    const PixelRect r = *g.cell_rect(i);
    EXPECT_EQ(g.cell_index_at_texel(r.x, r.y), i);
    EXPECT_EQ(g.cell_index_at_texel(r.x + r.width - 1, r.y + r.height - 1), i);
  }
}

TEST(GridTest, CellLargerThanFaceIsOneCell) {
  const FaceGrid g = must(FaceGrid::with_cell_size(4, 64));
  EXPECT_EQ(g.cell_count(), 1u);
  EXPECT_EQ(*g.cell_rect(0), (PixelRect{0, 0, 4, 4}));
  EXPECT_EQ(g.quadtree_levels(), 1u);
}

TEST(GridTest, BadSizesAndIndicesAreErrors) {
  EXPECT_EQ(FaceGrid::with_cell_size(0, 64).status().id(), ErrorId::kGridSize);
  EXPECT_EQ(FaceGrid::with_cell_size(64, 0).status().id(), ErrorId::kGridSize);
  EXPECT_EQ(FaceGrid::with_cell_size(kMaxFaceSize + 1, 64).status().id(), ErrorId::kGridSize);
  EXPECT_EQ(FaceGrid::with_regions_per_side(64, 0).status().id(), ErrorId::kGridSize);
  const FaceGrid g = must(FaceGrid::with_cell_size(128, 64));
  auto bad = g.cell_rect(4u);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().id(), ErrorId::kGridIndex);
  EXPECT_EQ(bad.status().to_string(), "CALF-E024 cell index 4 is outside a grid of 4 cells");
}

TEST(GridTest, TilesAreFourAligned) {
  const FaceGrid two = must(FaceGrid::with_regions_per_side(1024, 2));
  EXPECT_EQ(two.cells_per_side(), 2u);
  EXPECT_EQ(*two.cell_rect(3), (PixelRect{512, 512, 512, 512}));
  const FaceGrid odd = must(FaceGrid::with_regions_per_side(30, 2));  // 15 -> 16
  EXPECT_EQ(odd.cell_size(), 16u);
  EXPECT_EQ(*odd.cell_rect(1), (PixelRect{16, 0, 14, 16}));
  const FaceGrid tiny = must(FaceGrid::with_regions_per_side(6, 4));  // documented example
  EXPECT_EQ(tiny.cells_per_side(), 2u);
  EXPECT_EQ(*tiny.cell_rect(3), (PixelRect{4, 4, 2, 2}));
  for (uint32_t face : {1u, 2u, 7u, 33u, 1000u}) {
    for (uint32_t tiles : {1u, 2u, 3u, 8u}) {
      const FaceGrid g = must(FaceGrid::with_regions_per_side(face, tiles));
      EXPECT_LE(g.cells_per_side(), tiles);
      for (uint32_t i = 0; i + 1 < g.cells_per_side(); ++i)
        EXPECT_EQ(g.cell_rect(i, 0).width % 4, 0u);
      expect_partition(g);
    }
  }
}

TEST(GridTest, QuadtreeChildrenPartitionParentsDownToSingleCells) {
  for (uint32_t cells : {1u, 2u, 3u, 5u, 8u, 16u, 17u}) {
    const FaceGrid g = must(FaceGrid::with_cell_size(cells * 8, 8));
    ASSERT_EQ(g.cells_per_side(), cells);
    const uint32_t levels = g.quadtree_levels();
    EXPECT_EQ(g.quadtree_node_cells(0, 0, 0), (CellRange{0, 0, cells, cells}));
    for (uint32_t level = 0; level + 1 < levels; ++level) {
      for (uint32_t iy = 0; iy < (1u << level); ++iy) {
        for (uint32_t ix = 0; ix < (1u << level); ++ix) {
          const CellRange p = g.quadtree_node_cells(level, ix, iy);
          const CellRange a = g.quadtree_node_cells(level + 1, 2 * ix, 2 * iy);
          const CellRange d = g.quadtree_node_cells(level + 1, 2 * ix + 1, 2 * iy + 1);
          EXPECT_EQ(a.x0, p.x0);
          EXPECT_EQ(a.y0, p.y0);
          EXPECT_EQ(d.x1, p.x1);
          EXPECT_EQ(d.y1, p.y1);
          EXPECT_EQ(a.x1, d.x0);  // the split column / row is shared
          EXPECT_EQ(a.y1, d.y0);
        }
      }
    }
    // Leaves: each non-empty node of the last level is exactly one cell, and all cells appear.
    const uint32_t last = levels - 1;
    uint32_t seen = 0;
    for (uint32_t iy = 0; iy < (1u << last); ++iy) {
      for (uint32_t ix = 0; ix < (1u << last); ++ix) {
        const CellRange r = g.quadtree_node_cells(last, ix, iy);
        if (r.empty()) continue;
        EXPECT_EQ(r.x1 - r.x0, 1u);
        EXPECT_EQ(r.y1 - r.y0, 1u);
        ++seen;
      }
    }
    EXPECT_EQ(seen, cells * cells);
    EXPECT_EQ(levels, cells == 1 ? 1u : 1u + static_cast<uint32_t>(std::ceil(std::log2(cells))));
  }
}

TEST(GridTest, RectOfCellsCoversTheRange) {
  const FaceGrid g = must(FaceGrid::with_cell_size(100, 32));  // 4 per side, last is 4 wide
  EXPECT_EQ(g.rect_of_cells({1, 2, 4, 4}), (PixelRect{32, 64, 68, 36}));
  EXPECT_EQ(g.rect_of_cells({2, 2, 2, 3}), PixelRect{});
}

}  // namespace
}  // namespace calf
