// View-dependent culling (paper 002, Sec. 6.2): which cells of a viewpoint's cube map can be seen
// by any viewer, tested hierarchically on a per-face quadtree.
//
// A cell's frustum is the truncated pyramid with its apex at the viewpoint, its sides through the
// cell's corner directions, cut by planes parallel to the face at the nearest and farthest axial
// distances any texel of the cell can have given the view's radial depth range [z_near, z_far]:
// near = z_near * (smallest cosine between a cell direction and the face axis, at a corner),
// far = z_far * (largest cosine, at the cell point closest to the face centre). It therefore
// contains every point the cell's texels can stand for (the paper places the caps at z_near and
// z_far, which clips the corners of wide cells). Cells holding sky need a finite far: pass the
// distance beyond which nothing matters to the viewer (e.g. its far plane plus the distance
// between eye and viewpoint).
//
// Frusta and their intersection test are calf/format/geometry.h (shared with the encoder's
// builders). A quadtree node's frustum contains its children's, so a node separated from every
// viewer has no visible cell below it, and the hierarchical search returns exactly the
// brute-force set.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/grid.h"

namespace calf {

// How far, in texels, the light-field renderers read around a point they sample: a bilinear tap
// lies within one texel of it, and a sharpened tap reads its neighbours one texel further
// (LightfieldRenderOptions::colour_sharpen). The visibility searches below test each cell's
// rectangle grown by this much, so that every texel a visible point's colour reads is decoded.
inline constexpr double kRenderReachTexels = 2;

// The frustum of texel rectangle `rect` of `face` on a cube map of `face_size` texels centred at
// `viewpoint`, for radial depths [z_near, z_far] (0 < z_near < z_far, finite), the rectangle
// grown by `grow_texels` >= 0 on every side (continuing the face's plane past its edges).
Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far, double grow_texels = 0);

// Counts of frustum-frustum tests, for Table 4 of the paper. `exact_tests` counts the full
// separating-axis tests GridCuller falls back to (the reference searches below count none).
// GridCuller::visible_reusing() counts in `reused` the node decisions it took from its memory
// instead of testing (those are not in `tests`).
struct CullStats {
  uint64_t tests = 0;
  uint64_t visible_cells = 0;
  uint64_t exact_tests = 0;
  uint64_t reused = 0;
};

// The cells of `face` (indices in `grid`, increasing) whose frustum meets at least one eye
// frustum, by descending the face quadtree from the root down to `levels` levels (1 = test every
// cell directly; 0 or more than grid.quadtree_levels() = all levels). Adds to `stats`.
std::vector<uint32_t> visible_cells_hierarchical(const Vec3& viewpoint, CubeFace face,
                                                 const FaceGrid& grid, double z_near, double z_far,
                                                 std::span<const Frustum> eyes, uint32_t levels,
                                                 CullStats* stats);

// The same set by testing every cell against every eye: the reference the hierarchical search is
// tested against.
std::vector<uint32_t> visible_cells_brute_force(const Vec3& viewpoint, CubeFace face,
                                                const FaceGrid& grid, double z_near, double z_far,
                                                std::span<const Frustum> eyes, CullStats* stats);

// The parts of a cell frustum that depend on the cell alone (face, face size, texel rectangle):
// its 4 corner directions (near/far corner i lies on direction i), their cosines with the face
// axis, and the smallest and largest cosine over the cell. cell_frustum() is
// cell_frustum_from(cell_directions(...), ...), so a frustum built from cached directions has the
// very bits of one built from scratch.
struct CellDirections {
  std::array<Vec3, 4> dirs;
  std::array<double, 4> cos{};
  double min_cos = 1, max_cos = 1;
};
CellDirections cell_directions(CubeFace face, uint32_t face_size, const PixelRect& rect,
                               double grow_texels = 0);
// The 8 corners (near 0..3, far 0..3) of the frustum of `cell` seen from `viewpoint` for radial
// depths [z_near, z_far].
std::array<Vec3, 8> cell_frustum_corners(const CellDirections& cell, const Vec3& viewpoint,
                                         double z_near, double z_far);

// An eye frustum prepared for GridCuller: its face planes (inward normals) with the interval its
// corners span on each, as the separating-axis test computes them.
// For GridCuller's memory (visible_reusing) the same planes as 12 half-spaces, each
// dot(u, x - origin) >= offset with a unit normal u: half-space k < 6 is the eye's side of its
// interval on normals[k] (u = normals[k] / |normals[k]|, from lo[k]), half-space 6 + k the other
// end (u = -normals[k] / |normals[k]|, from hi[k]); `origin` is the near cap's centre. How far
// these move between two eyes bounds how far every decision made against one can change for the
// other.
struct PreparedEye {
  const Frustum* frustum = nullptr;
  std::array<Vec3, 6> normals;
  std::array<double, 6> lo{}, hi{}, margin{};
  double reach = 0;                 // the largest coordinate magnitude of a corner
  std::array<Vec3, 6> unit;         // normals[k] / |normals[k]|
  std::array<double, 6> inv_len{};  // 1 / |normals[k]|
  Vec3 origin;
  std::array<double, 12> offset{};
};
PreparedEye prepare_eye(const Frustum& eye);

// Culling for one grid, fast enough to run every frame: the directions of every
// quadtree node of every face are computed once, at construction (they depend on the face, the
// face size and the node's rectangle only; the viewpoint and depth range enter per call through 8
// multiply-adds per node). Each node is then tested against each eye's 6 face planes only: the
// same projections and tolerance as frusta_intersect()'s first 6 axes, so a node it rejects the
// exact test rejects too. A node whose 8 corners all lie inside an eye frustum by a margin
// (1e-9 relative, far above rounding) has every cell below it visible, without further tests; so
// has a node whose cross-section at some axial depth every cell below it spans (from z_near to
// z_far times the node's smallest cosine) lies inside by the margin (the far caps reach past the
// eye's far plane, so the first rule rarely applies to them);
// a cell whose corner lies inside by that margin is visible. Next the eye's corners are tested
// against the node's own planes (side planes through the apex from the cached directions, caps
// along the face axis): all outside one plane by the margin rejects the node (the exact test's
// axis for that face differs from this one by rounding only, far below the margin), a corner
// inside all by the margin makes a cell visible, and so does a segment (side edge or centre line)
// of either frustum with a stretch inside the other by the margin. Only the cells left undecided go
// through frusta_intersect(), on the frustum cell_frustum() builds (the same bits), which stays
// the arbiter. The result is exactly visible_cells_hierarchical()'s and
// visible_cells_brute_force()'s (tested on random frusta).
class CullMemory;

class GridCuller {
 public:
  explicit GridCuller(const FaceGrid& grid);

  const FaceGrid& grid() const { return grid_; }
  // The cells of `face` (increasing) whose frustum meets at least one of `eyes`; `levels` as for
  // visible_cells_hierarchical (it only changes where the descent starts). Adds to `stats`
  // (`tests` counts node-eye plane tests, `exact_tests` the full tests among them).
  void visible(const Vec3& viewpoint, CubeFace face, double z_near, double z_far,
               std::span<const PreparedEye> eyes, uint32_t levels, CullStats* stats,
               std::vector<uint32_t>* out) const;

  // The same set for one eye, reusing the decisions `memory` kept from earlier calls where they
  // provably still hold (a moving eye): a node decision is kept with its slack — the
  // smallest distance by which the node points it rests on lay inside or outside the eye's
  // planes, and that distance over their distance from the eye — and taken again while the eye's
  // planes (their unit normals and offsets) and the node frusta (viewpoint, depth range) have
  // moved less since than the slack allows, with a margin of 1e-7 of the coordinates' scale (far
  // above the tests' own 1e-9 and rounding). Kept: a rejection by an eye plane, an acceptance by
  // points inside the eye (corners, a cross-section, a point on a segment), and for an inner
  // node "not rejected by any eye plane", which descends to the children (an inner node the
  // planes accept has only visible cells below it, so descending finds the same cells). All
  // else — leaves settled by their own planes or by the exact test — is tested afresh, with the
  // very tests of visible(); a leaf the exact test rejected is first tried on the one axis of
  // that test which separated it by the widest gap (with 100 times its tolerance, so that the
  // exact test would reject it too). The result is therefore exactly visible()'s for `eye`, for any
  // sequence of calls (tested on random moving, jumping and zooming eyes). `memory` belongs to
  // one (viewpoint, face, eye) as the caller sees it; one given another culler or face starts
  // afresh, and any other change only makes it test more.
  void visible_reusing(const Vec3& viewpoint, CubeFace face, double z_near, double z_far,
                       const PreparedEye& eye, uint32_t levels, CullMemory* memory,
                       CullStats* stats, std::vector<uint32_t>* out) const;

 private:
  struct Node {
    CellDirections cell;
    CellRange range;
    std::array<Vec3, 4> side;  // side plane normals through the apex, inward
    std::array<double, 4> side_len{};
    std::array<Vec3, 4> axial;  // dirs[i] / cos[i]: corner i's offset per unit of axial depth
  };
  struct Search;
  FaceGrid grid_;
  std::vector<uint32_t> level_start_;  // first node of each level in nodes_[face]
  std::array<std::vector<Node>, 6> nodes_;
  std::array<Vec3, 6> axis_;  // each face's axis (the caps are perpendicular to it)
  // Per node (the same on every face): bit 0 no cells, bit 1 one cell (a leaf). A walk through
  // the memory reads this, not the node.
  std::vector<uint8_t> shape_;
  double max_axial_ = 0;  // the longest axial[i] of any node, for how far corners move
};

// What GridCuller::visible_reusing() keeps between calls for one (viewpoint, face, eye): each
// node's last decision with its slack, and the eye and node frusta of the last call with the
// motion summed since (an upper bound of how far they have moved from any earlier call).
class CullMemory {
 public:
  // Forgets every decision (never needed for correctness: a memory only ever saves tests).
  void clear();

 private:
  friend class GridCuller;
  enum class Kind : uint8_t { kNone, kReject, kAccept, kDescend };
  // 24 bytes: a walk reads one per node it visits.
  struct Decision {
    // Kept while turn * inv_angle + (travel + margin) * inv_distance < budget, that is while
    // (turn - turn then) / angle + (travel - travel then + margin) / distance < 1 with room for
    // rounding (the inverses rounded up to floats).
    double budget = 0;
    float inv_angle = 0, inv_distance = 0;
    float depth = 0;  // an inner node accepted by its cross-section: that section's depth
    Kind kind = Kind::kNone;
    // A leaf the exact test rejected: the axis that separated it by the widest gap, tried
    // first next time (a fresh test, cheaper than the exact one); -1: none.
    int8_t axis = -1;
  };
  std::vector<Decision> nodes_;
  const GridCuller* culler_ = nullptr;
  int face_ = -1;
  bool has_last_ = false;
  std::array<Vec3, 6> unit_;
  std::array<double, 12> offset_{};
  Vec3 origin_, apex_;
  double z_near_ = 0, z_far_ = 0;
  double turn_ = 0, travel_ = 0;  // summed motion: unit normals' turn, offsets' and points' travel
};

}  // namespace calf
