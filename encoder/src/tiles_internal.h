// The tiles builder's stages (calf/encoder/tiles_build.h), shared between its files; private to
// the encoder.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/encoder/tiles_build.h"
#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::encoder::tiles {

// Runs body(i) for i in [0, count) on `threads` threads. Each i must write only its own outputs,
// so the result does not depend on the thread count or the schedule.
template <typename Body>
void parallel_for(uint32_t threads, size_t count, const Body& body) {
  if (threads <= 1 || count <= 1) {
    for (size_t i = 0; i < count; ++i) body(i);
    return;
  }
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i = next++; i < count; i = next++) body(i);
  };
  std::vector<std::thread> pool;
  const size_t n = std::min<size_t>(threads, count);
  for (size_t t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

// A quadtree cell of a cube face: level L has 2^L x 2^L cells; (i, j) index s and t.
struct CellId {
  uint8_t face = 0, level = 0;
  uint32_t i = 0, j = 0;
};
// The face coordinates of a cell's corner k (0: (s0, t0), 1: (s1, t0), 2: (s1, t1), 3: (s0, t1)),
// dilated by `dilation` of the cell width on every side.
void cell_corner_st(const CellId& c, double dilation, int k, double* s, double* t);
// The index (face, j, i) among the 6 x 4^level cells of `level` of the cell holding face
// coordinate `c`.
inline size_t cell_index_at_level(const FaceCoord& c, uint32_t level) {
  const uint32_t side = 1u << level;
  const uint32_t i = std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, c.s * side)), side - 1);
  const uint32_t j = std::min<uint32_t>(static_cast<uint32_t>(std::max(0.0, c.t * side)), side - 1);
  return (size_t{static_cast<uint8_t>(c.face)} * side + j) * side + i;
}
// The unit direction from O through a cell's (dilated) corner k.
Vec3 cell_corner_direction(const CellId& c, double dilation, int k);
// The solid angle of a cell (dilated), exact for the spherical quadrilateral.
double cell_solid_angle(const CellId& c, double dilation);

// The frame of one capture set view, shared by the stages.
struct Frame {
  Vec3 origin;               // O, the view volume's centre
  double region_radius = 0;  // half the view volume's diagonal
  uint32_t face_size = 0;
  std::vector<Vec3> viewpoints;
};

// --- point merging (tiles_points.cc) ---
struct MergedPoints {
  // Relative to O, sorted by (face, Morton code of the leaf cell at level 30 / enough bits), so
  // that every quadtree cell's points are one contiguous range.
  std::vector<Vec3> position;
  std::vector<float> weight;  // samples merged into each point
  std::vector<uint8_t> face;
  std::vector<uint64_t> morton;  // of the cell at kMortonLevel
  uint64_t samples = 0;
  double max_radius = 0;
  // The sky layer: per root cell (face, j, i at min_level) whether some view saw sky (no depth)
  // in its directions, and how many sky texels were read.
  std::vector<uint8_t> sky_roots;
  uint64_t sky_samples = 0;
};
inline constexpr uint32_t kMortonLevel = 16;
uint64_t morton_code(uint32_t i, uint32_t j);
Expected<MergedPoints> merge_points(const capture::CaptureSetReader& reader, uint32_t frame,
                                    const Frame& f, const TilesBuildOptions& options);

// --- candidates (tiles_candidates.cc) ---
struct Plane {
  Vec3 normal;        // unit
  double offset = 0;  // dot(normal, x) = offset for points x (relative to O) on the plane, > 0
};
struct Tiling {
  uint32_t first_plane = 0, plane_count = 0;  // into Candidates::planes
  double distortion = 0;
};
struct CandidateCell {
  CellId id;
  uint32_t first_tiling = 0, tiling_count = 0;  // into Candidates::tilings
  int32_t children[4] = {-1, -1, -1, -1};       // indices into Candidates::cells, -1 = empty
  int32_t parent = -1;
  uint32_t point_begin = 0, point_end = 0;  // range into MergedPoints
};
struct Candidates {
  std::vector<CandidateCell> cells;  // breadth first: by level, roots in (face, j, i) order
  std::vector<uint32_t> roots;
  std::vector<Tiling> tilings;
  std::vector<Plane> planes;
};
// Where plane `p` meets the ray from O along unit `d`: the distance, or a negative value when it
// does not (parallel or behind).
double plane_distance_along(const Plane& p, const Vec3& d);
Candidates generate_candidates(const MergedPoints& points, const Frame& f,
                               const TilesBuildOptions& options);

// --- selection (tiles_select.cc) ---
struct Selected {
  CellId cell;
  Plane plane;
  bool sky = false;  // a tile of the sky layer: far, opaque, coloured by the views' sky texels
};
struct Selection {
  std::vector<Selected> tiles;
  double distortion = 0, dual_bound = 0;
  double average_overdraw = 0, peak_overdraw = 0;  // as modelled
  uint32_t evaluations = 0;
};
// The unit directions of the F overdraw views, with right and up axes (90-degree square views).
struct ViewAxes {
  Vec3 forward, right, up;
};
std::vector<ViewAxes> overdraw_view_axes(uint32_t count);
Expected<Selection> select_tiles(const Candidates& candidates, const Frame& f,
                                 const TilesBuildOptions& options);

// --- texturing (tiles_texture.cc) ---
struct TileTexture {
  uint32_t side = 0;        // texels per side (corners on texel centres)
  std::vector<float> rgba;  // side * side * 4: linear RGB (not premultiplied), alpha
};
// --- least-squares colour (tiles_texture_solve.cc) ---
// One tile's colour samples, accumulated sample by sample with their bilinear weights b: per
// texel the weighted sums (sum b r, sum b g, sum b b, sum b), which are both Seurat's splat
// (divided by the last) and the right-hand side of the least-squares fit, and, when the fit
// runs, its normal matrix: the diagonal and four of the eight couplings (the others are the
// neighbours' entries).
struct TileNormals {
  enum : int { kDiag = 0, kRight = 1, kDown = 2, kDownRight = 3, kDownLeft = 4 };
  uint32_t side = 0;
  std::vector<float> sums;      // side * side * 4
  std::vector<float> coupling;  // side * side * 5, empty without the fit
  void reset(uint32_t side, bool with_coupling);
  // A sample of linear RGB `colour` at texture position (u, w) in texels (corners on centres).
  void add(double u, double w, const float* colour, double weight = 1.0);
};
// Refines `rgba` (side * side * 4, the splat's colour as the start) towards the texel values whose
// bilinear interpolation best fits the samples, with a membrane term of weight `smoothness` times
// the tile's mean diagonal; `iterations` conjugate-gradient steps (0: leaves rgba as it is).
void solve_tile_colour(const TileNormals& normals, double smoothness, uint32_t iterations,
                       float* rgba);

// The scene-space (relative to O) corners of a selected tile.
std::array<Vec3, 4> tile_corners(const Selected& t, double dilation);
Expected<std::vector<TileTexture>> texture_tiles(const capture::CaptureSetReader& reader,
                                                 uint32_t frame, const Frame& f,
                                                 const Selection& selection,
                                                 const std::vector<uint32_t>& sides,
                                                 const TilesBuildOptions& options);

// --- atlas (tiles_atlas.cc) ---
struct AtlasPlacement {
  uint32_t x = 0, y = 0;  // top-left texel of the tile's texture (inside its pad)
};
// Packs squares of `sides` (each with a 1-texel pad) into shelves of a power-of-two wide atlas no
// wider than max_size; false when they do not fit in max_size x max_size.
bool pack_atlas(const std::vector<uint32_t>& sides, uint32_t max_size,
                std::vector<AtlasPlacement>* placements, uint32_t* width, uint32_t* height);
// Writes the tile set: corners, projective coordinates and the RGBA8 atlas.
TileSet write_tile_set(const Frame& f, const Box3& view_volume, const Selection& selection,
                       const std::vector<TileTexture>& textures,
                       const std::vector<AtlasPlacement>& placements, uint32_t width,
                       uint32_t height, double dilation);

// --- measurement (tiles_overdraw.cc) ---
struct OverdrawMeasure {
  double mean = 0, peak = 0;
  uint32_t max_layers = 0, views = 0;
};
OverdrawMeasure measure_overdraw(const TileSet& set, const std::vector<Vec3>& eyes,
                                 uint32_t directions, uint32_t resolution, uint32_t threads);

}  // namespace calf::encoder::tiles
