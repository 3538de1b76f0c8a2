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
// Two frusta are tested with the separating-axis theorem over both frusta's face normals and the
// cross products of their edge directions: exact for convex polyhedra, up to a tiny tolerance that
// counts touching as intersecting (so culling never drops a cell the viewer can see). A quadtree
// node's frustum contains its children's, so a node separated from every viewer has no visible
// cell below it, and the hierarchical search returns exactly the brute-force set.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "calf/format/cube.h"
#include "calf/format/grid.h"

namespace calf {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

// A convex truncated pyramid given by its 4 near and 4 far corners, each in the same winding
// (corner i of near and far lie on one side edge).
class Frustum {
 public:
  Frustum() = default;
  Frustum(const std::array<Vec3, 4>& near_corners, const std::array<Vec3, 4>& far_corners);

  const std::array<Vec3, 8>& corners() const { return corners_; }
  // Face normals, pointing inward (the separating-axis test ignores the sign).
  const std::array<Vec3, 6>& face_normals() const { return normals_; }
  // The distinct edge directions: 4 side edges and the 2 directions of the cap edges.
  const std::array<Vec3, 6>& edge_directions() const { return edges_; }
  // Whether `p` lies inside or on the frustum (no tolerance: used only to prove intersection).
  bool contains(const Vec3& p) const;

 private:
  std::array<Vec3, 8> corners_{};
  std::array<Vec3, 6> normals_{};  // oriented inward
  std::array<double, 6> offsets_{};  // inside: dot(normal, p) >= offset
  std::array<Vec3, 6> edges_{};
};

// Whether two frusta share any point (touching counts). Exact separating-axis test.
bool frusta_intersect(const Frustum& a, const Frustum& b);

// A perspective eye: position, orthonormal basis, vertical field of view (radians), aspect
// (width / height), near and far distances along `forward` (0 < near < far).
struct EyeView {
  Vec3 position, forward{0, 0, -1}, up{0, 1, 0};
  double fov_y = 1.5707963267948966, aspect = 1, near = 0.01, far = 1000;
};
Frustum eye_frustum(const EyeView& eye);

// The frustum of texel rectangle `rect` of `face` on a cube map of `face_size` texels centred at
// `viewpoint`, for radial depths [z_near, z_far] (0 < z_near < z_far, finite).
Frustum cell_frustum(const Vec3& viewpoint, CubeFace face, uint32_t face_size,
                     const PixelRect& rect, double z_near, double z_far);

// Counts of frustum-frustum tests, for Table 4 of the paper.
struct CullStats {
  uint64_t tests = 0;
  uint64_t visible_cells = 0;
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

}  // namespace calf
