// From-segment visibility (paper 004, Popescu et al., Alg. 1): the triangles of a scene that are
// visible from some point of a view segment, computed exactly (up to a documented float
// tolerance) on the segments of a view region's perimeter. The mesh track encoder keeps only
// these triangles (calf-encode --mode mesh --visible-set).
//
// This header is the contract between the builder (encoder/src/visible_set*.cc) and its callers;
// the builder's documentation of the algorithm, its tolerances and its costs lives here too
// (docs/VISIBILITY.md has the figures and the commands).
//
// What "visible" means. The eye moves along a segment [a, b], v(s) = a + s (b - a), s in [0, 1],
// and looks through the pixel centres of the six faces of a world-aligned cube map around it
// (calf/format/cube.h: OpenGL order and orientation, `face_size` pixels a side, centres at
// half-integers). A primitive (triangle or analytic sphere) is visible when, for some pixel
// centre p, some frame f and an interval of s longer than `min_interval` (default 1e-9), the ray
// from v(s) through p hits it first (smallest positive distance along the ray) among every
// primitive of the scene at frame f. A primitive seen only at isolated instants (a pixel centre
// grazing a vertex) or through a rounding-size crack is not visible.
//
// Time. Frame f shows every object at transform_at(object, f) and every mesh's vertices at
// positions_at(mesh, f / fps) (calf/capture/scene_file.h): the scene the player draws at frame f.
// A primitive is in the set when it is visible at some frame f in [first_frame, first_frame +
// frames); each distinct frame is solved exactly as a static scene (frames whose world geometry
// repeats the previous one's are skipped). Poses between frames, which no frame shows, are not
// considered; so the paper's coupled motion (Eqs. 3-4: eye and vertices moving with one
// parameter, quadratic edge events) is not needed for an exact answer at every frame, and the
// cost grows linearly with the number of distinct frames (of vertex states sampled by frames).
// The coupled motion answers another question and is offered beside it:
// VisibleSetOptions::motion = VisibilityMotion::kCoupled (below).
//
// Algorithm (per segment, frame and face; Alg. 1). Per triangle ABC, the directions from points of
// the segment to points of the triangle are those of the convex hull of the six points
// {A, B, C} - {a, b}; that hull, clipped to the face's half-space (depth >= a tiny delta) and
// projected, bounds every pixel the triangle can cover (the paper's hull of the two projections,
// made correct for triangles behind the eye or crossing its plane). Per pixel centre inside the
// bound, each edge PQ gives an edge function f(s) = d . ((P - v(s)) x (Q - P)), linear in s
// (Eq. 2; d the pixel's direction): the ray crosses the triangle exactly when all three have the
// sign of d . N (N the triangle's normal, their sum), and the hit lies ahead of the eye when
// N . (A - v(s)) has that sign too. The four half-lines give the coverage interval
// [s0, s1]; the hit distance along the ray is linear in s over it. Each pixel keeps a list of
// disjoint intervals, each with the primitive nearest over it and its depth line; a new interval
// is depth-composited into it (the lower envelope of depth lines, split where two lines cross:
// intersecting triangles are handled). The set is the union of the primitives left in the lists.
//
// Float tolerance. Everything is computed in double from the scene's float positions. Edge
// functions are evaluated with the edge's endpoints in a canonical order (lexicographic world
// position), so two triangles sharing an edge compute the same event time bit for bit: no crack
// between them lets a hidden primitive through, and no overlap hides one; edges meeting at a
// T-junction do differ by rounding, hence `min_interval` below. Pixel bounds are grown
// by 1e-3 pixel and clipped at a depth of 1e-9 times the scene's extent along the face axis, so
// only geometry closer than that to the eye can be missed by the bound. Ties (equal depth over an
// interval, e.g. coplanar duplicates) go to the primitive inserted first (front to back by a
// lower bound of the distance to the segment, then scene order: triangles, then spheres). Spheres'
// depths are not linear in s: crossings between two depth curves of which one is a sphere's are
// found by 32 samples and bisection, so two depth curves crossing twice within 1/32 of an interval
// may miss a sliver. tests/encoder/visible_set_test.cc checks the set against from-point ID buffers
// at >= 1000 random points per segment and checks every member at the middle of its longest
// interval with an independent ray caster.
//
// Spheres (Sec. 3.3). An analytic sphere is one primitive: its coverage interval per pixel is
// where the ray's distance to the centre is at most the radius (a quadratic in s) and the eye is
// outside it; its depth is the near hit. A sphere found visible is kept whole: its triangles are
// numbered as calf/encoder/sphere_mesh.h says (after the mesh's own, kSphereTriangles each). A
// segment that passes through a sphere sees it (it is added) but the sphere then hides nothing
// for the times the eye is inside it (conservative).
//
// Costs. O(sum over triangles of the pixels of their bound x log of the intervals per pixel) per
// segment, face and frame (paper: O(n m k log k)); a pixel's list is kept in blocks of 32
// intervals so that a change costs a block, not the list (grass: ~1,000 intervals a pixel).
// The work is split into 32 x 32 pixel tiles run in parallel, each inserting its primitives
// front to back (so most insertions are hidden and change nothing) and skipping a primitive once
// every pixel of the tile is covered over all of [0, 1] by nearer surfaces. A tile's result
// depends only on its own primitives in a fixed order, so the set does not depend on the thread
// count. docs/VISIBILITY.md has the figures.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::encoder {

// One view segment: the eye moves along [a, b].
struct ViewSegment {
  Vec3 a;
  Vec3 b;
};

// The segments of the perimeter of `region`'s horizontal cross-section at height `eye_height`
// (a rectangle, +Y up), each of its four edges split into `segments_per_edge` equal segments,
// in counter-clockwise order seen from above (a positive turn about +Y) starting at
// (min.x, min.z): (min.x, min.z) -> (min.x, max.z) -> (max.x, max.z) -> (max.x, min.z) -> back.
// A region flat in x or z gives a degenerate rectangle whose two long edges coincide: only the
// first of them is returned; a region flat in both gives one point: no segment (an error for
// compute_visible_set). segments_per_edge 0 is taken as 1.
std::vector<ViewSegment> perimeter_segments(const Box3& region, double eye_height,
                                            uint32_t segments_per_edge);

// Largest face_size accepted.
inline constexpr uint32_t kVisibleSetMaxFaceSize = 8192;

// How time and the eye's motion are combined (VisibleSetOptions::motion).
//   kPerFrame: each displayed frame is a static scene and the eye sweeps the whole segment at
//     every frame: "what can be seen from some point of the segment at some frame?" (the
//     default; exact for every pose the player draws).
//   kCoupled: paper 004 Sec. 3.2 (Eqs. 3-4). For each motion step, a pair of consecutive frames
//     (f, f + 1) of the range whose world geometry differs from the previous step's, the eye and
//     every vertex move with one parameter t in [0, 1]: the eye at v(t) = a + t (b - a), each
//     world-space vertex at (1 - t) X_f + t X_{f+1} (a chord between the two frames: exact for
//     vertex states no finer than frames, an approximation for rigid rotations and for states
//     finer than frames). "What can be seen by an eye that walks the segment while the scene
//     moves from frame f to f + 1?": the diagonal of (eye position x time), not a superset of
//     the per-frame sets (a triangle seen only from the end of the segment at frame f is not
//     seen by it). A range of one frame (or a scene that never moves) is solved as one step with
//     no motion, which answers the per-frame question. Edge events are quadratic in t, the
//     "ahead" test cubic, depth rational (cubic over quadratic): see visible_set_coupled.h in
//     encoder/src. VisibleSetStats::frames_solved then counts motion steps; witnesses carry the
//     step's first frame and an interval of t. Only compute_visible_set honours it (the
//     from-point functions sample frames).
enum class VisibilityMotion : uint8_t { kPerFrame = 0, kCoupled = 1 };

struct VisibleSetOptions {
  // Side of each of the six cube faces rasterised around a segment (paper 004: 800), 1 ..
  // kVisibleSetMaxFaceSize.
  uint32_t face_size = 800;
  // true: an object is kept whole as soon as one of its triangles is visible (object
  // granularity); false: individual triangles.
  bool object_granularity = false;
  // Worker threads (0: hardware concurrency), at most 256. The result never depends on it.
  uint32_t threads = 0;
  // The frames solved: [first_frame, first_frame + frames), frames 0 meaning "to the last frame".
  // first_frame must be < the scene's frame_count; the range is clipped to it.
  uint32_t first_frame = 0;
  uint32_t frames = 0;
  // An interval of the segment parameter at most this long does not make a primitive visible.
  // Edges that meet at a T-junction (a vertex of one triangle on the edge of another) give event
  // times that differ by rounding, a crack of ~1e-15 through which what lies behind would leak;
  // 1e-9 of a segment (10 nm of a 10 m segment) is far above rounding and far below anything a
  // from-point sample can hit. 0: every positive length counts.
  double min_interval = 1e-9;
  // Fill VisibleSet::witnesses (tests and debugging; costs a little time and memory).
  bool witnesses = false;
  // Per-frame (default) or the paper's coupled eye and vertex motion (see VisibilityMotion).
  VisibilityMotion motion = VisibilityMotion::kPerFrame;
};

// What was computed, for reports and benchmarks.
struct VisibleSetStats {
  uint64_t scene_triangles = 0;       // over objects (instances counted each time; a sphere
                                      // counts kSphereTriangles)
  uint64_t visible_triangles = 0;     // in the set (same counting)
  uint64_t triangle_pixel_pairs = 0;  // (primitive, pixel) pairs whose coverage was computed
                                      // (pixels inside bounds; primitives a tile culled as hidden
                                      // not counted), over segments, faces and frames
                                      // (from-point: over points, faces, frames)
  uint64_t frames_solved = 0;         // distinct frames solved (repeated geometry skipped)
  double seconds = 0;                 // wall time of compute_visible_set
};

// Why a primitive is in the set (VisibleSetOptions::witnesses): one pixel of one segment, frame
// and face where it is nearest over [s0, s1] (its longest such interval; ties: the smallest
// (segment, frame, face, y, x)). For the from-point functions s0 = s1 = the point's parameter
// (from_points) or 0 (at_points, `segment` then the eye's index).
struct VisibilityWitness {
  uint32_t object = 0;
  uint32_t primitive = 0;  // triangle index in the mesh, or mesh triangles + sphere index
  bool sphere = false;
  uint32_t segment = 0, frame = 0, face = 0, x = 0, y = 0;
  double s0 = 0, s1 = 0;
};

// The visible set: for each object of the scene (SceneFile::objects order) the sorted indices
// of its mesh's triangles that are visible from some point of some segment at some frame
// (sphere s of a mesh with T triangles adds [T + s kSphereTriangles, T + (s + 1)
// kSphereTriangles)).
struct VisibleSet {
  std::vector<std::vector<uint32_t>> triangles;
  VisibleSetStats stats;
  // One per visible primitive (object, then primitive order) when options.witnesses is set.
  std::vector<VisibilityWitness> witnesses;
};

// Computes the visible set of `scene` from `segments` over the frames of `options` (rigid
// transforms per frame, piecewise-linear vertex states, spheres). Errors (one line each, naming
// the culprit): no segment (E110), a degenerate (zero-length or non-finite) segment (E111), a
// segment endpoint outside the scene's bounds (E112: the box of every primitive over the frames
// solved, grown on every side by twice its largest side), a scene without triangles or spheres
// (E113), an option out of range (E114), more primitives than 2^31 (E115).
Expected<VisibleSet> compute_visible_set(const capture::SceneFile& scene,
                                         std::span<const ViewSegment> segments,
                                         const VisibleSetOptions& options);

// The from-point baseline (paper 004 Sec. 4.5): ID buffers rendered by a CPU z-buffer rasteriser
// (nearest primitive per pixel centre, the same cube faces) at `points_per_segment` evenly spaced
// points of each segment (s = i / (n - 1), both ends included; one point: the middle), united.
// Same options, errors and statistics as compute_visible_set (E114 also for points_per_segment
// 0 or above 1,000,000).
Expected<VisibleSet> compute_visible_set_from_points(const capture::SceneFile& scene,
                                                     std::span<const ViewSegment> segments,
                                                     uint32_t points_per_segment,
                                                     const VisibleSetOptions& options);

// The same baseline at explicit eye points (random sampling, tests). Errors as above (no point:
// E110; a point outside the bounds or not finite: E112).
Expected<VisibleSet> compute_visible_set_at_points(const capture::SceneFile& scene,
                                                   std::span<const Vec3> eyes,
                                                   const VisibleSetOptions& options);

}  // namespace calf::encoder
