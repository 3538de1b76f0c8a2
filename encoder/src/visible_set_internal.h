// Internals of the visible-set builder (calf/encoder/visible_set.h), shared by its files:
//   visible_set_scene.cc      the scene flattened to world-space primitives per frame, numbering
//   visible_set_raster.cc     cube-face bases, conservative pixel bounds, the per-pixel coverage
//                             intervals of Eq. 2 (triangles) and Sec. 3.3 (spheres)
//   visible_set_intervals.cc  depth compositing of coverage intervals into a pixel's list
//   visible_set.cc            the driver: checks, frames, segments, tiles, threads, the union
//   visible_set_from_points.cc  the from-point z-buffer baseline
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/encoder/visible_set.h"
#include "calf/format/cube.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::encoder::visibility {

// ---- the scene as primitives ----

// Primitive p of the scene: object o's mesh triangles are [base[o], base[o] + T_o), its spheres
// [base[o] + T_o, base[o + 1]).
struct PrimitiveTable {
  std::vector<uint64_t> base;            // objects + 1 entries
  std::vector<uint32_t> mesh_triangles;  // T_o per object
  uint64_t count() const { return base.back(); }
};
PrimitiveTable number_primitives(const capture::SceneFile& scene);

struct WorldSphere {
  Vec3 centre;
  double radius = 0;
  uint32_t primitive = 0;
  friend bool operator==(const WorldSphere&, const WorldSphere&) = default;
};

// The scene at one frame in world space.
struct FrameGeometry {
  std::vector<Vec3> vertices;        // 3 per triangle (corners in the mesh's winding)
  std::vector<uint32_t> triangles;   // the primitive of each triangle
  std::vector<WorldSphere> spheres;  // spheres, in primitive order
  Box3 bounds;                       // of everything (valid when !empty())
  bool empty() const { return triangles.empty() && spheres.empty(); }
  friend bool operator==(const FrameGeometry&, const FrameGeometry&) = default;
};
// The world geometry of frame `frame` (transform_at, positions_at(frame / fps)).
void build_frame(const capture::SceneFile& scene, const PrimitiveTable& table, uint32_t frame,
                 FrameGeometry* out);

// ---- cube faces and pixel bounds ----

// The (non-unit) direction through pixel centre (x, y) of a face of N pixels is
// m + sc s + tc t with sc = (2x + 1) / N - 1, tc = (2y + 1) / N - 1 (calf/format/cube.h).
struct FaceBasis {
  Vec3 m, s, t;
};
FaceBasis face_basis(int face);
inline double pixel_sc(uint32_t x, uint32_t n) {
  return (2.0 * x + 1.0) / n - 1.0;
}

// The pixels of one face that directions from the segment's points to a convex set may hit: the
// convex hull of `points` minus {v0, v1}, clipped at depth `delta` along the face axis and
// projected (rows y0..y1, each row's columns from row_span).
class PixelBound {
 public:
  // false when nothing of the set can be seen through the face.
  bool compute(std::span<const Vec3> points, const Vec3& v0, const Vec3& v1, const FaceBasis& f,
               uint32_t n, double delta);
  int y0() const { return y0_; }
  int y1() const { return y1_; }
  int x0() const { return x0_; }
  int x1() const { return x1_; }
  // The columns [*xa, *xb] of row y (false when none).
  bool row_span(int y, int* xa, int* xb) const;

 private:
  std::array<double, 2 * 160> hull_{};
  int hull_n_ = 0;
  bool rect_ = false;
  int n_ = 0;
  int x0_ = 0, x1_ = -1, y0_ = 0, y1_ = -1;
};

// ---- coverage intervals (Eq. 2) ----

// A triangle seen from a segment v(s) = v0 + s w through one face: the edge functions' and the
// normal's coefficients in (1, sc, tc), so that a pixel costs a few multiply-adds.
struct TriangleSetup {
  double alpha[3][3];     // edge k: d . ((P - v0) x (Q - P)), P Q in canonical order, signed
  double beta[3][3];      // edge k: d . (w x (Q - P)), same sign
  double normal[3];       // d . N
  double g0 = 0, g1 = 0;  // N . (A - v(s)) = g0 - s g1
};
void setup_triangle(const Vec3* corners, const Vec3& v0, const Vec3& w, const FaceBasis& f,
                    TriangleSetup* out);

// A depth function of s along one pixel's ray: p + q s for a triangle; for a sphere (sphere >= 0,
// an index into the caller's SphereDepth table) k0 + k1 s - sqrt(max(0, c0 + c1 s + c2 s^2)).
struct SphereDepth {
  double k0, k1, c0, c1, c2;
};
struct Interval {
  double s0, s1;
  double p, q;
  uint32_t primitive;
  int32_t sphere;  // -1: linear depth
};
// The interval over which the triangle covers pixel (sc, tc) ahead of the eye, and its depth line.
// false when it covers it for no s of positive length.
bool triangle_coverage(const TriangleSetup& t, double sc, double tc, Interval* out);

// Up to two coverage intervals of a sphere at a pixel (direction d) from v(s) = v0 + s w; the
// depth parameters go to *depth (the intervals' `sphere` is left to the caller). Returns the count.
int sphere_coverage(const WorldSphere& sphere, const Vec3& v0, const Vec3& w, const Vec3& d,
                    Interval out[2], SphereDepth* depth);

// ---- depth compositing ----

double depth_at(const Interval& i, std::span<const SphereDepth> spheres, double s);
// Depth-composites `in` into the sorted, disjoint list `list` (scratch: a reused buffer): where
// `in` is nearer it replaces what was there, where nothing was it is added, ties keep the list.
// Returns false when the list did not change (`in` hidden wherever it covers).
bool composite(std::vector<Interval>* list, const Interval& in,
               std::span<const SphereDepth> spheres, std::vector<Interval>* scratch);

// ---- the driver's shared checks ----

// The checks every entry point runs; fills `frames` with the frames to solve (distinct geometry).
struct Prepared {
  PrimitiveTable table;
  std::vector<uint32_t> frames;  // frame numbers, each with geometry unlike the previous one's
  Box3 bounds;                   // over those frames
  double delta = 0;              // the near clip depth
};
Expected<Prepared> prepare(const capture::SceneFile& scene, const VisibleSetOptions& options);
Status check_point(const Prepared& prepared, const Vec3& p, const std::string& what);

// Turns per-primitive flags into the per-object triangle lists and counts.
void collect(const capture::SceneFile& scene, const PrimitiveTable& table,
             const std::vector<uint8_t>& visible, bool object_granularity, VisibleSet* out);

// Keeps the better of two witnesses for one primitive (longer interval, then smaller key).
bool better_witness(const VisibilityWitness& a, const VisibilityWitness& b);

}  // namespace calf::encoder::visibility
