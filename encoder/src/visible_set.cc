// The from-segment visibility driver (paper 004, Alg. 1 over a perimeter, Sec. 4.1): checks,
// then per distinct frame and segment the six cube faces are cut into tiles; primitives are
// binned to the tiles their pixel bounds touch (in scene order), each tile composites its
// primitives' coverage intervals pixel by pixel and marks the primitives left in its lists.
// Tiles run in parallel; a tile's result depends only on its own primitives, in a fixed order,
// so the set is the same for any thread count.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include "calf/encoder/visible_set.h"
#include "visible_set_coupled.h"
#include "visible_set_internal.h"

namespace calf::encoder {

using namespace visibility;

std::vector<ViewSegment> perimeter_segments(const Box3& region, double eye_height,
                                            uint32_t segments_per_edge) {
  const uint32_t k = std::max<uint32_t>(1, segments_per_edge);
  const Vec3 c[4] = {{region.min.x, eye_height, region.min.z},
                     {region.min.x, eye_height, region.max.z},
                     {region.max.x, eye_height, region.max.z},
                     {region.max.x, eye_height, region.min.z}};
  const bool flat_x = region.min.x == region.max.x, flat_z = region.min.z == region.max.z;
  std::vector<ViewSegment> out;
  for (int e = 0; e < 4; ++e) {
    const Vec3& a = c[e];
    const Vec3& b = c[(e + 1) % 4];
    if (a == b) continue;
    // Flat in one axis: edges 2 and 3 run back over edges 0 and 1.
    if ((flat_x || flat_z) && e >= 2) continue;
    for (uint32_t i = 0; i < k; ++i) {
      const double t0 = static_cast<double>(i) / k, t1 = static_cast<double>(i + 1) / k;
      out.push_back({a + (b - a) * t0, i + 1 == k ? b : a + (b - a) * t1});
    }
  }
  return out;
}

namespace {

constexpr uint32_t kTile = 32;
constexpr uint32_t kChunk = 2048;

std::string point_string(const Vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.9g, %.9g, %.9g)", v.x, v.y, v.z);
  return buf;
}

struct TileScratch {
  std::vector<IntervalList> lists = std::vector<IntervalList>(kTile * kTile);
  IntervalPool pool;
  CompositeScratch composite;
  std::vector<SphereDepth> spheres;
  // Per pixel: an upper bound of the farthest depth of its list when the list covers all of
  // [0, 1], else inf (pixel_far); whether the list changed since; a time in the gap pixel_far
  // found last (negative: none).
  std::vector<double> far = std::vector<double>(kTile * kTile);
  std::vector<uint8_t> dirty = std::vector<uint8_t>(kTile * kTile);
  std::vector<double> gap = std::vector<double>(kTile * kTile);
};

constexpr double kInf = std::numeric_limits<double>::infinity();

// Whether no interval of `list` covers time s.
bool uncovered(const IntervalList& list, const IntervalPool& pool, double s) {
  const IntervalList::Pos p = list.first_ending_after(pool, s);
  return p == list.end() || list.at(pool, p).s0 > s;
}

// The farthest distance (along the unit ray) of a list that covers all of [0, 1], else inf.
// `gap` remembers a time in a gap: lists only fill up, so while that time stays uncovered (a
// binary search) the list is still incomplete and its blocks are not read again. On grass the
// lists near the horizon keep a gap to the end (sky beyond the field) and are long (~1,000
// intervals).
double pixel_far(const IntervalList& list, const IntervalPool& pool, double length, double* gap) {
  if (*gap >= 0 && uncovered(list, pool, *gap)) return kInf;
  const double far = list.far_bound(pool, gap);
  if (far == kInf) return kInf;
  *gap = -1;
  return far * length;
}

// The occlusion bound of a tile: the largest pixel_far over its pixels (inf while one pixel's
// list has a gap). Lists only ever get nearer and fill up, so a bound computed earlier stays
// an upper bound: only pixels whose list changed since (dirty) are recomputed, and the scan stops
// at the first pixel with a gap (rechecked in O(log k) by pixel_far's memo).
double tile_far(TileScratch* s, int w, int h, int px0, int py0, uint32_t n) {
  double out = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * int{kTile} + x;
      if (s->dirty[i]) {
        const double sc = pixel_sc(static_cast<uint32_t>(px0 + x), n);
        const double tc = pixel_sc(static_cast<uint32_t>(py0 + y), n);
        s->far[i] = pixel_far(s->lists[i], s->pool, std::sqrt(1 + sc * sc + tc * tc), &s->gap[i]);
        s->dirty[i] = 0;
      }
      if (s->far[i] == kInf) return kInf;
      out = std::max(out, s->far[i]);
    }
  return out;
}

double segment_distance(const Vec3& p, const Vec3& v0, const Vec3& w, double ww) {
  const double t = std::clamp(dot(p - v0, w) / ww, 0.0, 1.0);
  return length(p - (v0 + w * t));
}

class SegmentRunner {
 public:
  SegmentRunner(const VisibleSetOptions& options, const Prepared& prepared)
      : options_(options), prepared_(prepared), visible_(prepared.table.count(), 0) {
    if (options.witnesses) witnesses_.resize(prepared.table.count());
    for (int f = 0; f < kCubeFaceCount; ++f) bases_[f] = face_basis(f);
  }

  void run(const FrameGeometry& geo, const ViewSegment& segment, uint32_t segment_index,
           uint32_t frame);

  std::vector<uint8_t>& visible() { return visible_; }
  uint64_t pairs() const { return pairs_.load(); }
  std::vector<VisibilityWitness> witnesses() const;

 private:
  void mark(uint32_t primitive, const VisibilityWitness& w) {
    std::atomic_ref<uint8_t>(visible_[primitive]).store(1, std::memory_order_relaxed);
    if (!options_.witnesses) return;
    std::lock_guard<std::mutex> lock(mutex_);
    VisibilityWitness& best = witnesses_[primitive];
    if (best.s1 <= best.s0 || better_witness(w, best)) best = w;
  }
  // Pixel corners of item `item` (a triangle, or a sphere's bounding cube).
  int item_points(const FrameGeometry& geo, uint32_t item, Vec3* pts) const {
    const uint32_t nt = static_cast<uint32_t>(geo.triangles.size());
    if (item < nt) {
      std::copy_n(&geo.vertices[3 * static_cast<size_t>(item)], 3, pts);
      return 3;
    }
    const WorldSphere& s = geo.spheres[item - nt];
    for (int i = 0; i < 8; ++i)
      pts[i] = s.centre + Vec3{i & 1 ? s.radius : -s.radius, i & 2 ? s.radius : -s.radius,
                               i & 4 ? s.radius : -s.radius};
    return 8;
  }

  const VisibleSetOptions& options_;
  const Prepared& prepared_;
  FaceBasis bases_[kCubeFaceCount];
  std::vector<uint8_t> visible_;
  std::vector<VisibilityWitness> witnesses_;
  std::mutex mutex_;
  std::atomic<uint64_t> pairs_{0};
  tbb::enumerable_thread_specific<TileScratch> scratch_;
};

void SegmentRunner::run(const FrameGeometry& geo, const ViewSegment& segment,
                        uint32_t segment_index, uint32_t frame) {
  const uint32_t n = options_.face_size;
  const uint32_t tiles_per_side = (n + kTile - 1) / kTile;
  const uint32_t tiles_per_face = tiles_per_side * tiles_per_side;
  const uint32_t tiles = tiles_per_face * kCubeFaceCount;
  const Vec3 v0 = segment.a, v1 = segment.b, w = segment.b - segment.a;
  const uint32_t nt = static_cast<uint32_t>(geo.triangles.size());
  const uint32_t items = nt + static_cast<uint32_t>(geo.spheres.size());

  // A segment through a sphere sees it from inside (Sec. 3.3 assumes the eye outside).
  for (const WorldSphere& s : geo.spheres) {
    const double ww = dot(w, w);
    const double t = std::clamp(dot(s.centre - v0, w) / ww, 0.0, 1.0);
    const Vec3 gap = s.centre - (v0 + w * t);
    if (dot(gap, gap) < s.radius * s.radius)
      mark(s.primitive, {0, 0, true, segment_index, frame, kCubeFaceCount, 0, 0, t, t});
  }

  // Front to back: items sorted by a lower bound of their distance to the segment (ties: scene
  // order), so that most later items are hidden and rejected early (composite's fast path, and
  // whole tiles once every pixel's list covers [0, 1] nearer than the item can be).
  std::vector<double> near(items);
  std::vector<uint32_t> sorted(items);
  const double ww = dot(w, w);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, items, kChunk),
                    [&](const tbb::blocked_range<uint32_t>& range) {
                      Vec3 pts[8];
                      for (uint32_t item = range.begin(); item < range.end(); ++item) {
                        Vec3 centre;
                        double radius = 0;
                        if (item < nt) {
                          item_points(geo, item, pts);
                          centre = (pts[0] + pts[1] + pts[2]) / 3.0;
                          for (int k = 0; k < 3; ++k)
                            radius = std::max(radius, length(pts[k] - centre));
                        } else {
                          centre = geo.spheres[item - nt].centre;
                          radius = geo.spheres[item - nt].radius;
                        }
                        near[item] = std::max(0.0, segment_distance(centre, v0, w, ww) - radius);
                      }
                    });
  std::iota(sorted.begin(), sorted.end(), 0u);
  tbb::parallel_sort(sorted.begin(), sorted.end(), [&](uint32_t a, uint32_t b) {
    return near[a] != near[b] ? near[a] < near[b] : a < b;
  });

  // Binning: (tile, position in `sorted`) pairs per chunk, then a counting sort in chunk order,
  // so each tile lists its items front to back whatever thread binned them.
  const uint32_t chunks = (items + kChunk - 1) / kChunk;
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> binned(chunks);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, chunks, 1), [&](const tbb::blocked_range<
                                                                    uint32_t>& range) {
    PixelBound bound;
    Vec3 pts[8];
    for (uint32_t c = range.begin(); c < range.end(); ++c) {
      auto& out = binned[c];
      const uint32_t end = std::min(items, (c + 1) * kChunk);
      for (uint32_t pos = c * kChunk; pos < end; ++pos) {
        const int np = item_points(geo, sorted[pos], pts);
        for (int f = 0; f < kCubeFaceCount; ++f) {
          if (!bound.compute({pts, static_cast<size_t>(np)}, v0, v1, bases_[f], n, prepared_.delta))
            continue;
          for (int ty = bound.y0() / kTile; ty <= bound.y1() / int{kTile}; ++ty)
            for (int tx = bound.x0() / kTile; tx <= bound.x1() / int{kTile}; ++tx)
              out.emplace_back(f * tiles_per_face + ty * tiles_per_side + tx, pos);
        }
      }
    }
  });
  std::vector<uint64_t> start(tiles + 1, 0);
  for (const auto& chunk : binned)
    for (const auto& p : chunk) ++start[p.first + 1];
  for (uint32_t t = 0; t < tiles; ++t) start[t + 1] += start[t];
  std::vector<uint32_t> order(start[tiles]);
  {
    std::vector<uint64_t> fill(start.begin(), start.end() - 1);
    for (const auto& chunk : binned)
      for (const auto& p : chunk) order[fill[p.first]++] = p.second;
  }
  binned.clear();

  tbb::parallel_for(
      tbb::blocked_range<uint32_t>(0, tiles, 1), [&](const tbb::blocked_range<uint32_t>& range) {
        TileScratch& scratch = scratch_.local();
        PixelBound bound;
        TriangleSetup setup;
        Vec3 pts[8];
        for (uint32_t tile = range.begin(); tile < range.end(); ++tile) {
          if (start[tile] == start[tile + 1]) continue;
          const int face = static_cast<int>(tile / tiles_per_face);
          const FaceBasis& basis = bases_[face];
          const uint32_t in_face = tile % tiles_per_face;
          const int px0 = static_cast<int>((in_face % tiles_per_side) * kTile);
          const int py0 = static_cast<int>((in_face / tiles_per_side) * kTile);
          const int px1 = std::min<int>(static_cast<int>(n), px0 + kTile) - 1;
          const int py1 = std::min<int>(static_cast<int>(n), py0 + kTile) - 1;
          scratch.spheres.clear();
          std::fill(scratch.far.begin(), scratch.far.end(), kInf);
          std::fill(scratch.dirty.begin(), scratch.dirty.end(), 0);
          std::fill(scratch.gap.begin(), scratch.gap.end(), -1.0);
          double far = kInf;
          uint32_t changed = 0;
          uint64_t pairs = 0;
          for (uint64_t k = start[tile]; k < start[tile + 1]; ++k) {
            const uint32_t item = sorted[order[k]];
            if (changed >= 16) {
              far = tile_far(&scratch, px1 - px0 + 1, py1 - py0 + 1, px0, py0, n);
              changed = 0;
            }
            // Occluded in the whole tile: nearer surfaces cover every pixel over all of [0, 1]
            // (the item is at least near[item] from every point of the segment).
            if (near[item] >= far) continue;
            const int np = item_points(geo, item, pts);
            if (!bound.compute({pts, static_cast<size_t>(np)}, v0, v1, basis, n, prepared_.delta))
              continue;
            const bool triangle = item < nt;
            if (triangle) setup_triangle(pts, v0, w, basis, &setup);
            const uint32_t primitive =
                triangle ? geo.triangles[item] : geo.spheres[item - nt].primitive;
            bool any = false;
            for (int y = std::max(py0, bound.y0()); y <= std::min(py1, bound.y1()); ++y) {
              int xa, xb;
              if (!bound.row_span(y, &xa, &xb)) continue;
              xa = std::max(xa, px0), xb = std::min(xb, px1);
              const double tc = pixel_sc(static_cast<uint32_t>(y), n);
              const int row = (y - py0) * int{kTile} - px0;
              for (int x = xa; x <= xb; ++x) {
                const int i = row + x;
                // Occluded at this pixel (the same bound, one pixel; possibly stale, so larger).
                if (near[item] >= scratch.far[i]) continue;
                ++pairs;
                const double sc = pixel_sc(static_cast<uint32_t>(x), n);
                IntervalList& list = scratch.lists[i];
                Interval iv[2];
                bool hit = false;
                if (triangle) {
                  if (!triangle_coverage(setup, sc, tc, &iv[0])) continue;
                  iv[0].primitive = primitive;
                  hit = composite(&list, &scratch.pool, iv[0], scratch.spheres, &scratch.composite);
                } else {
                  const Vec3 d = basis.m + basis.s * sc + basis.t * tc;
                  SphereDepth depth;
                  const int c = sphere_coverage(geo.spheres[item - nt], v0, w, d, iv, &depth);
                  if (c == 0) continue;
                  scratch.spheres.push_back(depth);
                  for (int j = 0; j < c; ++j) {
                    iv[j].sphere = static_cast<int32_t>(scratch.spheres.size() - 1);
                    hit |=
                        composite(&list, &scratch.pool, iv[j], scratch.spheres, &scratch.composite);
                  }
                }
                if (hit) scratch.dirty[i] = 1, any = true;
              }
            }
            changed += any;
          }
          pairs_.fetch_add(pairs, std::memory_order_relaxed);
          // Alg. 1 lines 10-13: the primitives left in the lists.
          for (int y = py0; y <= py1; ++y)
            for (int x = px0; x <= px1; ++x) {
              IntervalList& list = scratch.lists[(y - py0) * kTile + (x - px0)];
              list.for_each(scratch.pool, [&](const Interval& iv) {
                if (iv.s1 - iv.s0 > options_.min_interval)
                  mark(iv.primitive,
                       {0, 0, iv.sphere >= 0, segment_index, frame, static_cast<uint32_t>(face),
                        static_cast<uint32_t>(x), static_cast<uint32_t>(y), iv.s0, iv.s1});
                return true;
              });
              list.clear();
            }
          scratch.pool.reset();
        }
      });
}

std::vector<VisibilityWitness> SegmentRunner::witnesses() const {
  std::vector<VisibilityWitness> out;
  const PrimitiveTable& table = prepared_.table;
  for (uint64_t p = 0; p < visible_.size(); ++p) {
    if (!visible_[p]) continue;
    VisibilityWitness w = witnesses_[p];
    const size_t o = static_cast<size_t>(std::upper_bound(table.base.begin(), table.base.end(), p) -
                                         table.base.begin() - 1);
    w.object = static_cast<uint32_t>(o);
    w.primitive = static_cast<uint32_t>(p - table.base[o]);
    w.sphere = w.primitive >= table.mesh_triangles[o];
    out.push_back(w);
  }
  return out;
}

}  // namespace

Expected<VisibleSet> compute_visible_set(const capture::SceneFile& scene,
                                         std::span<const ViewSegment> segments,
                                         const VisibleSetOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (segments.empty())
    return Status(ErrorId::kVisibleSetNoSegment,
                  "no view segment given for scene '" + scene.name + "'");
  for (size_t i = 0; i < segments.size(); ++i) {
    const ViewSegment& s = segments[i];
    if (!is_finite(s.a) || !is_finite(s.b) || s.a == s.b || !(dot(s.b - s.a, s.b - s.a) > 0))
      return Status(ErrorId::kVisibleSetSegment,
                    "segment " + std::to_string(i) + " from " + point_string(s.a) + " to " +
                        point_string(s.b) +
                        (is_finite(s.a) && is_finite(s.b) ? " has zero length" : " is not finite"));
  }
  CALF_ASSIGN_OR_RETURN(Prepared prepared, prepare(scene, options));
  for (size_t i = 0; i < segments.size(); ++i) {
    CALF_RETURN_IF_ERROR(
        check_point(prepared, segments[i].a, "segment " + std::to_string(i) + " start"));
    CALF_RETURN_IF_ERROR(
        check_point(prepared, segments[i].b, "segment " + std::to_string(i) + " end"));
  }
  // Paper 004 Sec. 3.2's coupled eye and vertex motion: visible_set_coupled.cc.
  if (options.motion == VisibilityMotion::kCoupled)
    return solve_coupled(scene, segments, options, prepared, t0);
  if (options.motion != VisibilityMotion::kPerFrame)
    return Status(ErrorId::kVisibleSetOption, "motion " +
                                                  std::to_string(static_cast<int>(options.motion)) +
                                                  " is neither per-frame (0) nor coupled (1)");
  SegmentRunner runner(options, prepared);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  FrameGeometry geo;
  for (uint32_t frame : prepared.frames) {
    build_frame(scene, prepared.table, frame, &geo);
    for (size_t i = 0; i < segments.size(); ++i)
      arena.execute([&] { runner.run(geo, segments[i], static_cast<uint32_t>(i), frame); });
  }
  VisibleSet out;
  collect(scene, prepared.table, runner.visible(), options.object_granularity, &out);
  if (options.witnesses) out.witnesses = runner.witnesses();
  out.stats.triangle_pixel_pairs = runner.pairs();
  out.stats.frames_solved = prepared.frames.size();
  out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace calf::encoder
