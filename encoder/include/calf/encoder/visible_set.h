// From-segment visibility (paper 004, Popescu et al., Alg. 1): the triangles of a scene that are
// visible from some point of a view segment, computed exactly (up to a documented float
// tolerance) on the segments of a view region's perimeter. The mesh track encoder keeps only
// these triangles (calf-encode --mode mesh --visible-set).
//
// This header is the contract between the builder (encoder/src/visible_set*.cc) and its callers;
// the builder's documentation of the algorithm, its tolerances and its costs lives here too.
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
// in counter-clockwise order seen from above starting at (min.x, min.z). A region flat in x or z
// gives a degenerate rectangle: its two distinct edges (or one point: no segment, an error for
// compute_visible_set).
std::vector<ViewSegment> perimeter_segments(const Box3& region, double eye_height,
                                            uint32_t segments_per_edge);

struct VisibleSetOptions {
  // Side of each of the six cube faces rasterised around a segment (paper 004: 800).
  uint32_t face_size = 800;
  // true: an object is kept whole as soon as one of its triangles is visible (object
  // granularity); false: individual triangles.
  bool object_granularity = false;
  // Worker threads (0: hardware concurrency). The result never depends on it.
  uint32_t threads = 0;
};

// What was computed, for reports and benchmarks.
struct VisibleSetStats {
  uint64_t scene_triangles = 0;       // over objects (instances counted each time)
  uint64_t visible_triangles = 0;     // in the set
  uint64_t triangle_pixel_pairs = 0;  // (triangle, pixel) pairs processed
  double seconds = 0;                 // wall time of compute_visible_set
};

// The visible set: for each object of the scene (SceneFile::objects order) the sorted indices
// of its mesh's triangles that are visible from some point of some segment at some frame.
struct VisibleSet {
  std::vector<std::vector<uint32_t>> triangles;
  VisibleSetStats stats;
};

// Computes the visible set of `scene` from `segments` over every frame of the scene (rigid
// transforms per frame, piecewise-linear vertex states, spheres). Errors (one line each, naming
// the culprit): no segment, a degenerate (zero-length) segment, a segment outside the scene's
// bounds, a scene without triangles.
Expected<VisibleSet> compute_visible_set(const capture::SceneFile& scene,
                                         std::span<const ViewSegment> segments,
                                         const VisibleSetOptions& options);

}  // namespace calf::encoder
