// Internals of the visible-set builder (calf/encoder/visible_set.h), shared by its files:
//   visible_set_scene.cc      the scene flattened to world-space primitives per frame, numbering
//   visible_set_raster.cc     cube-face bases, conservative pixel bounds, the per-pixel coverage
//                             intervals of Eq. 2 (triangles) and Sec. 3.3 (spheres)
//   visible_set_list.cc       a pixel's interval list, stored in blocks
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

// ---- a pixel's interval list ----

// Intervals per block of an IntervalList.
inline constexpr uint32_t kListBlock = 32;

// The blocks of the interval lists of one tile, handed out one at a time and taken back all at
// once (reset) when the tile is done. Block ids stay valid across allocations; pointers from
// block() do not.
class IntervalPool {
 public:
  uint32_t allocate();
  void release(uint32_t block);
  // Every block free again (the lists using them must be cleared).
  void reset();
  Interval* block(uint32_t b) { return &storage_[size_t{b} * kListBlock]; }
  const Interval* block(uint32_t b) const { return &storage_[size_t{b} * kListBlock]; }

 private:
  std::vector<Interval> storage_;
  std::vector<uint32_t> free_;
  uint32_t used_ = 0;
};

// A pixel's sorted, disjoint intervals, in blocks of at most kListBlock held in an IntervalPool
// (visible_set_list.cc says why). A position is (block, index); end() is (blocks, 0). Each block
// also keeps the largest depth at its intervals' ends and whether they leave a gap between them,
// so that far_bound() costs one step per block, not per interval.
class IntervalList {
 public:
  struct Pos {
    uint32_t block = 0, index = 0;
    friend bool operator==(const Pos&, const Pos&) = default;
  };
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  // Forgets the intervals (the pool's blocks are taken back by IntervalPool::reset).
  void clear();
  Pos begin() const { return {}; }
  Pos end() const { return {static_cast<uint32_t>(blocks_.size()), 0}; }
  void next(Pos* p) const {
    if (++p->index == blocks_[p->block].count) ++p->block, p->index = 0;
  }
  const Interval& at(const IntervalPool& pool, Pos p) const {
    return pool.block(blocks_[p.block].id)[p.index];
  }
  // The first interval whose s1 is above s (end() when none).
  Pos first_ending_after(const IntervalPool& pool, double s) const;
  // Replaces the intervals [first, last) by `with` (sorted, disjoint, fitting between the
  // neighbours; `spheres` their sphere depths); `tmp` is a reused buffer. Positions are invalid
  // afterwards.
  void replace(IntervalPool* pool, Pos first, Pos last, std::span<const Interval> with,
               std::span<const SphereDepth> spheres, std::vector<Interval>* tmp);
  // The largest depth of the list (largest of its intervals' depths at their ends: depths are
  // lines or convex) when its intervals cover all of [0, 1] without a gap; else +inf, with a time
  // inside a gap in *gap.
  double far_bound(const IntervalPool& pool, double* gap) const;
  // Calls f(interval) in order while it returns true; false when one returned false.
  template <typename F>
  bool for_each(const IntervalPool& pool, F&& f) const {
    for (const Block& b : blocks_) {
      const Interval* e = pool.block(b.id);
      for (uint32_t i = 0; i < b.count; ++i)
        if (!f(e[i])) return false;
    }
    return true;
  }

 private:
  struct Block {
    double end = 0;   // s1 of its last interval
    double far = 0;   // largest depth at its intervals' ends
    uint32_t id = 0;  // in the pool
    uint16_t count = 0;
    bool gap = false;  // some interval does not start where the previous one ends
  };
  std::vector<Block> blocks_;
  size_t size_ = 0;
};

// ---- depth compositing ----

// Reused buffers of composite().
struct CompositeScratch {
  std::vector<Interval> out, tmp;
};

double sphere_depth_at(const Interval& i, std::span<const SphereDepth> spheres, double s);
// The depth of interval `i` at s (a line inline: it is in every inner loop).
inline double depth_at(const Interval& i, std::span<const SphereDepth> spheres, double s) {
  return i.sphere < 0 ? i.p + i.q * s : sphere_depth_at(i, spheres, s);
}
// Depth-composites `in` into the sorted, disjoint list `list` (its blocks in `pool`): where `in`
// is nearer it replaces what was there, where nothing was it is added, ties keep the list.
// Returns false when the list did not change (`in` hidden wherever it covers).
bool composite(IntervalList* list, IntervalPool* pool, const Interval& in,
               std::span<const SphereDepth> spheres, CompositeScratch* scratch);

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
