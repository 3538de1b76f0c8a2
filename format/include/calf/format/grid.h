// Cell and tile grids on a cube face: the one place where calf splits a face into the regions that
// are coded, fetched and culled independently (paper 002: colour cells, Sec. 5.1; depth regions,
// Sec. 5.2; the per-face culling quadtree, Sec. 6.2).
//
// A FaceGrid splits an N x N face into square regions of side `cell_size`, laid from the top-left
// texel (0, 0) row by row. When N is not a multiple of cell_size, the last column and the last row
// hold the remainder: those edge cells are narrower and/or shorter (never empty), so every texel
// belongs to exactly one cell. Cells are indexed row-major: index = cy * cells_per_side + cx.
//
// Colour cells use an explicit cell size (default 64). Depth regions are asked for as a count per
// side (default 2 x 2); their side is ceil(N / count) rounded up to a multiple of 4 so that BCn
// blocks never straddle two tiles, which can leave fewer tiles than asked on tiny faces (a 6-texel
// face split 4 x 4 gets 2 x 2 tiles of 4 and 2 texels).
//
// The culling quadtree has the whole face as its root (level 0); a node at level L covers the cell
// columns [floor(i * C / 2^L), floor((i + 1) * C / 2^L)) and the same for rows, where C is the
// number of cells per side. The four children of a node partition it exactly; at the last level
// (2^L >= C) every non-empty node is one cell. When C is not a power of two some nodes are empty.
#pragma once

#include <cstdint>

#include "calf/format/status.h"

namespace calf {

// The largest face calf accepts, in texels per side (limits in format/SPEC.md refer to it).
inline constexpr uint32_t kMaxFaceSize = 16384;

// A rectangle of texels: columns [x, x + width), rows [y, y + height).
struct PixelRect {
  uint32_t x = 0, y = 0, width = 0, height = 0;
  friend bool operator==(const PixelRect&, const PixelRect&) = default;
};

// A rectangle of cells: columns [x0, x1), rows [y0, y1). Empty when x0 == x1 or y0 == y1.
struct CellRange {
  uint32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x0 >= x1 || y0 >= y1; }
  friend bool operator==(const CellRange&, const CellRange&) = default;
};

class FaceGrid {
 public:
  // Cells of `cell_size` texels on a face of `face_size` texels. Both must be in
  // [1, kMaxFaceSize]; a cell larger than the face is clipped to one cell covering the face.
  static Expected<FaceGrid> with_cell_size(uint32_t face_size, uint32_t cell_size);
  // About `tiles_per_side` x `tiles_per_side` tiles, 4-aligned as described above.
  static Expected<FaceGrid> with_regions_per_side(uint32_t face_size, uint32_t tiles_per_side);

  uint32_t face_size() const { return face_size_; }
  uint32_t cell_size() const { return cell_size_; }
  uint32_t cells_per_side() const { return per_side_; }
  uint32_t cell_count() const { return per_side_ * per_side_; }

  // The texels of cell `index`; index must be < cell_count() (checked: CALF-E024).
  Expected<PixelRect> cell_rect(uint32_t index) const;
  // The texels of cell (cx, cy); both must be < cells_per_side() (asserted; unchecked in release).
  PixelRect cell_rect(uint32_t cx, uint32_t cy) const;
  uint32_t cell_index(uint32_t cx, uint32_t cy) const { return cy * per_side_ + cx; }
  // The cell containing texel (x, y); both must be < face_size().
  uint32_t cell_index_at_texel(uint32_t x, uint32_t y) const {
    return cell_index(x / cell_size_, y / cell_size_);
  }
  // The texels covered by a range of cells (empty rect for an empty range).
  PixelRect rect_of_cells(const CellRange& r) const;

  // Levels of the culling quadtree: 1 + ceil(log2(cells_per_side)); a 1-cell face has 1 level.
  uint32_t quadtree_levels() const;
  // The cells under quadtree node (ix, iy) of `level`; level < quadtree_levels() and
  // ix, iy < 2^level (asserted).
  CellRange quadtree_node_cells(uint32_t level, uint32_t ix, uint32_t iy) const;

 private:
  FaceGrid(uint32_t face_size, uint32_t cell_size);
  uint32_t face_size_ = 1, cell_size_ = 1, per_side_ = 1;
};

}  // namespace calf
