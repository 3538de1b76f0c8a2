#include "calf/format/grid.h"

#include <algorithm>
#include <cassert>
#include <string>

namespace calf {

FaceGrid::FaceGrid(uint32_t face_size, uint32_t cell_size)
    : face_size_(face_size),
      cell_size_(std::min(cell_size, face_size)),
      per_side_((face_size + cell_size_ - 1) / cell_size_) {}

namespace {

// Every grid size (face, cell, tile count) is validated against the same range.
Status check_grid_size(const char* what, uint32_t value) {
  if (value == 0 || value > kMaxFaceSize) {
    return Status(ErrorId::kGridSize, std::string(what) + " " + std::to_string(value) +
                                          " must be in [1, " + std::to_string(kMaxFaceSize) + "]");
  }
  return Status::Ok();
}

}  // namespace

Expected<FaceGrid> FaceGrid::with_cell_size(uint32_t face_size, uint32_t cell_size) {
  CALF_RETURN_IF_ERROR(check_grid_size("face size", face_size));
  CALF_RETURN_IF_ERROR(check_grid_size("cell size", cell_size));
  return FaceGrid(face_size, cell_size);
}

Expected<FaceGrid> FaceGrid::with_regions_per_side(uint32_t face_size, uint32_t tiles_per_side) {
  CALF_RETURN_IF_ERROR(check_grid_size("tiles per side", tiles_per_side));
  // Checked here too so that a zero face is reported as such, not as a zero cell size.
  CALF_RETURN_IF_ERROR(check_grid_size("face size", face_size));
  const uint32_t side = (face_size + tiles_per_side - 1) / tiles_per_side;
  return with_cell_size(face_size, (side + 3u) & ~3u);
}

Expected<PixelRect> FaceGrid::cell_rect(uint32_t index) const {
  if (index >= cell_count()) {
    return Status(ErrorId::kGridIndex, "cell index " + std::to_string(index) +
                                           " is outside a grid of " + std::to_string(cell_count()) +
                                           " cells");
  }
  return cell_rect(index % per_side_, index / per_side_);
}

PixelRect FaceGrid::cell_rect(uint32_t cx, uint32_t cy) const {
  assert(cx < per_side_ && cy < per_side_);
  const uint32_t x = cx * cell_size_, y = cy * cell_size_;
  return {x, y, std::min(cell_size_, face_size_ - x), std::min(cell_size_, face_size_ - y)};
}

PixelRect FaceGrid::rect_of_cells(const CellRange& r) const {
  if (r.empty()) return {};
  const PixelRect first = cell_rect(r.x0, r.y0);
  const PixelRect last = cell_rect(r.x1 - 1, r.y1 - 1);
  return {first.x, first.y, last.x + last.width - first.x, last.y + last.height - first.y};
}

uint32_t FaceGrid::quadtree_levels() const {
  uint32_t levels = 1;
  while ((1u << (levels - 1)) < per_side_) ++levels;
  return levels;
}

CellRange FaceGrid::quadtree_node_cells(uint32_t level, uint32_t ix, uint32_t iy) const {
  assert(level < quadtree_levels() && ix < (1u << level) && iy < (1u << level));
  const uint64_t c = per_side_;
  const auto edge = [c, level](uint64_t i) { return static_cast<uint32_t>((i * c) >> level); };
  return {edge(ix), edge(iy), edge(ix + 1u), edge(iy + 1u)};
}

}  // namespace calf
