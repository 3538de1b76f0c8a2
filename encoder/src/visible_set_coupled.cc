// The coupled-motion driver (paper 004 Sec. 3.2; VisibilityMotion::kCoupled): per motion step
// (a pair of consecutive frames) and segment, the six cube faces are cut into tiles, primitives
// are sorted front to back and binned to the tiles their pixel bounds touch, and each tile
// composites the coverage intervals of its primitives (visible_set_coupled_intervals.cc) pixel by
// pixel. The structure is the per-frame driver's (visible_set.cc), kept apart so that the two
// paths can change independently; the same determinism argument holds: a tile's result depends
// only on its own primitives in a fixed order, so the set does not depend on the thread count.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include "visible_set_coupled.h"

namespace calf::encoder::visibility {
namespace {

constexpr uint32_t kTile = 32;
constexpr uint32_t kChunk = 2048;
constexpr double kInf = std::numeric_limits<double>::infinity();

struct TileScratch {
  std::vector<std::vector<CoupledInterval>> lists =
      std::vector<std::vector<CoupledInterval>>(kTile * kTile);
  std::vector<CoupledInterval> tmp;
  // Per pixel: an upper bound of the metric depth of its list when the list covers [0, 1].
  std::vector<double> far = std::vector<double>(kTile * kTile);
};

double pixel_far(const std::vector<CoupledInterval>& list, double length) {
  if (list.empty() || list.front().s0 > 0 || list.back().s1 < 1) return kInf;
  double far = 0;
  for (size_t i = 0; i < list.size(); ++i) {
    if (i > 0 && list[i].s0 != list[i - 1].s1) return kInf;
    far = std::max(far, list[i].far);
  }
  return far * length;
}

double segment_distance(const Vec3& p, const Vec3& v0, const Vec3& w, double ww) {
  const double t = std::clamp(dot(p - v0, w) / ww, 0.0, 1.0);
  return length(p - (v0 + w * t));
}

// One motion step: the scene at its first and second frame (the same primitives in the same
// order: build_frame's layout depends only on the scene's structure).
struct Step {
  const FrameGeometry* g0;
  const FrameGeometry* g1;
  uint32_t frame;
};

class CoupledRunner {
 public:
  CoupledRunner(const VisibleSetOptions& options, const Prepared& prepared)
      : options_(options), prepared_(prepared), visible_(prepared.table.count(), 0) {
    if (options.witnesses) witnesses_.resize(prepared.table.count());
    for (int f = 0; f < kCubeFaceCount; ++f) bases_[f] = face_basis(f);
  }

  void run(const Step& step, const ViewSegment& segment, uint32_t segment_index);

  std::vector<uint8_t>& visible() { return visible_; }
  uint64_t pairs() const { return pairs_.load(); }
  const std::vector<VisibilityWitness>& raw_witnesses() const { return witnesses_; }

 private:
  void mark(uint32_t primitive, const VisibilityWitness& w) {
    std::atomic_ref<uint8_t>(visible_[primitive]).store(1, std::memory_order_relaxed);
    if (!options_.witnesses) return;
    std::lock_guard<std::mutex> lock(mutex_);
    VisibilityWitness& best = witnesses_[primitive];
    if (best.s1 <= best.s0 || better_witness(w, best)) best = w;
  }
  // Points whose differences with the segment's ends bound the pixels of item `item` over the
  // step. A triangle: its corners at both frames. Why that suffices: a point of the triangle at
  // t is sum_i b_i ((1 - t) P_i0 + t P_i1) (barycentric b_i >= 0, sum 1), the eye
  // (1 - t) a + t b, so their difference is sum_i b_i ((1 - t) (P_i0 - a) + t (P_i1 - b)): a
  // convex combination of the six points P_i0 - a, P_i1 - b. PixelBound takes the hull of all
  // twelve P_ij - {a, b}, a superset, and projects it: every direction the moving triangle is
  // seen in lies inside. A sphere: the corners of a cube around the ball that holds it at both
  // frames (its centre and radius move linearly, so it stays inside that convex ball).
  int item_points(const Step& step, uint32_t item, Vec3* pts) const {
    const uint32_t nt = static_cast<uint32_t>(step.g0->triangles.size());
    if (item < nt) {
      std::copy_n(&step.g0->vertices[3 * static_cast<size_t>(item)], 3, pts);
      std::copy_n(&step.g1->vertices[3 * static_cast<size_t>(item)], 3, pts + 3);
      return 6;
    }
    Vec3 c;
    double r;
    sphere_ball(step, item - nt, &c, &r);
    for (int i = 0; i < 8; ++i) pts[i] = c + Vec3{i & 1 ? r : -r, i & 2 ? r : -r, i & 4 ? r : -r};
    return 8;
  }
  static void sphere_ball(const Step& step, uint32_t s, Vec3* c, double* r) {
    const WorldSphere& a = step.g0->spheres[s];
    const WorldSphere& b = step.g1->spheres[s];
    *c = (a.centre + b.centre) * 0.5;
    *r = 0.5 * length(b.centre - a.centre) + std::max(a.radius, b.radius);
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

void CoupledRunner::run(const Step& step, const ViewSegment& segment, uint32_t segment_index) {
  const uint32_t n = options_.face_size;
  const uint32_t tiles_per_side = (n + kTile - 1) / kTile;
  const uint32_t tiles_per_face = tiles_per_side * tiles_per_side;
  const uint32_t tiles = tiles_per_face * kCubeFaceCount;
  const Vec3 v0 = segment.a, v1 = segment.b, w = segment.b - segment.a;
  const double ww = dot(w, w);
  const FrameGeometry& g0 = *step.g0;
  const FrameGeometry& g1 = *step.g1;
  const uint32_t nt = static_cast<uint32_t>(g0.triangles.size());
  const uint32_t items = nt + static_cast<uint32_t>(g0.spheres.size());

  // An eye that enters a moving sphere sees it (Sec. 3.3 assumes the eye outside): |e(t)|^2 -
  // r(t)^2 < 0 for some t, e = centre - eye; the quadratic's minimum over [0, 1].
  for (size_t i = 0; i < g0.spheres.size(); ++i) {
    const WorldSphere& a = g0.spheres[i];
    const WorldSphere& b = g1.spheres[i];
    const Vec3 e0 = a.centre - v0, u = (b.centre - a.centre) - w;
    const double dr = b.radius - a.radius;
    const double c0 = dot(e0, e0) - a.radius * a.radius, c1 = 2 * dot(e0, u) - 2 * a.radius * dr,
                 c2 = dot(u, u) - dr * dr;
    double t = 0;
    double best = c0;
    for (double cand : {1.0, c2 > 0 ? std::clamp(-c1 / (2 * c2), 0.0, 1.0) : 0.0}) {
      const double v = (c2 * cand + c1) * cand + c0;
      if (v < best) best = v, t = cand;
    }
    if (best < 0)
      mark(a.primitive, {0, 0, true, segment_index, step.frame, kCubeFaceCount, 0, 0, t, t});
  }

  // Bounds of the distance from v(t) to the item at t, over the step (metric). Near: the item
  // stays in a ball (centre, radius), the eye on the segment. Far: |X - v| is convex in the pair
  // (X, v), so over the item's hull at both frames and the segment it is largest at a pair of
  // vertices.
  std::vector<double> near(items), far(items);
  tbb::parallel_for(tbb::blocked_range<uint32_t>(0, items, kChunk),
                    [&](const tbb::blocked_range<uint32_t>& range) {
                      Vec3 pts[8];
                      for (uint32_t item = range.begin(); item < range.end(); ++item) {
                        Vec3 centre;
                        double radius = 0, extent = 0;
                        if (item < nt) {
                          item_points(step, item, pts);
                          centre = (pts[0] + pts[1] + pts[2] + pts[3] + pts[4] + pts[5]) / 6.0;
                          for (int k = 0; k < 6; ++k) {
                            radius = std::max(radius, length(pts[k] - centre));
                            extent = std::max({extent, length(pts[k] - v0), length(pts[k] - v1)});
                          }
                        } else {
                          sphere_ball(step, item - nt, &centre, &radius);
                          extent = std::max(length(centre - v0), length(centre - v1)) + radius;
                        }
                        near[item] = std::max(0.0, segment_distance(centre, v0, w, ww) - radius);
                        far[item] = extent;
                      }
                    });
  std::vector<uint32_t> sorted(items);
  std::iota(sorted.begin(), sorted.end(), 0u);
  tbb::parallel_sort(sorted.begin(), sorted.end(), [&](uint32_t a, uint32_t b) {
    return near[a] != near[b] ? near[a] < near[b] : a < b;
  });

  // Binning, as in visible_set.cc: per chunk, then a counting sort in chunk order.
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
        const int np = item_points(step, sorted[pos], pts);
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
        CoupledTriangleSetup setup;
        Vec3 pts[8];
        CoupledInterval iv[kMaxCoupledIntervals];
        for (uint32_t tile = range.begin(); tile < range.end(); ++tile) {
          if (start[tile] == start[tile + 1]) continue;
          const int face = static_cast<int>(tile / tiles_per_face);
          const FaceBasis& basis = bases_[face];
          const uint32_t in_face = tile % tiles_per_face;
          const int px0 = static_cast<int>((in_face % tiles_per_side) * kTile);
          const int py0 = static_cast<int>((in_face / tiles_per_side) * kTile);
          const int px1 = std::min<int>(static_cast<int>(n), px0 + kTile) - 1;
          const int py1 = std::min<int>(static_cast<int>(n), py0 + kTile) - 1;
          std::fill(scratch.far.begin(), scratch.far.end(), kInf);
          double tile_far = kInf;
          bool changed = false;
          uint64_t pairs = 0;
          for (uint64_t k = start[tile]; k < start[tile + 1]; ++k) {
            const uint32_t item = sorted[order[k]];
            if (changed && (k - start[tile]) % 16 == 0) {
              tile_far = 0;
              for (int y = py0; y <= py1; ++y)
                for (int x = px0; x <= px1; ++x)
                  tile_far = std::max(tile_far, scratch.far[(y - py0) * kTile + (x - px0)]);
              changed = false;
            }
            // Occluded in the whole tile over all of [0, 1] by surfaces nearer than it can be.
            if (near[item] >= tile_far) continue;
            const int np = item_points(step, item, pts);
            if (!bound.compute({pts, static_cast<size_t>(np)}, v0, v1, basis, n, prepared_.delta))
              continue;
            const bool triangle = item < nt;
            uint32_t primitive;
            if (triangle) {
              setup_coupled_triangle(&g0.vertices[3 * static_cast<size_t>(item)],
                                     &g1.vertices[3 * static_cast<size_t>(item)], v0, w, basis,
                                     &setup);
              setup.near = near[item], setup.far = far[item];
              primitive = g0.triangles[item];
            } else {
              primitive = g0.spheres[item - nt].primitive;
            }
            for (int y = std::max(py0, bound.y0()); y <= std::min(py1, bound.y1()); ++y) {
              int xa, xb;
              if (!bound.row_span(y, &xa, &xb)) continue;
              xa = std::max(xa, px0), xb = std::min(xb, px1);
              const double tc = pixel_sc(static_cast<uint32_t>(y), n);
              std::vector<CoupledInterval>* row = &scratch.lists[(y - py0) * kTile];
              for (int x = xa; x <= xb; ++x) {
                ++pairs;
                const double sc = pixel_sc(static_cast<uint32_t>(x), n);
                const double len = std::sqrt(1 + sc * sc + tc * tc);
                int c;
                if (triangle) {
                  c = coupled_triangle_coverage(setup, sc, tc, 1 / len, iv);
                } else {
                  const Vec3 d = basis.m + basis.s * sc + basis.t * tc;
                  c = coupled_sphere_coverage(g0.spheres[item - nt], g1.spheres[item - nt], v0, w,
                                              d, near[item], far[item], iv);
                }
                bool any = false;
                for (int i = 0; i < c; ++i) {
                  iv[i].primitive = primitive;
                  any |= coupled_composite(&row[x - px0], iv[i], &scratch.tmp);
                }
                if (!any) continue;
                scratch.far[(y - py0) * kTile + (x - px0)] = pixel_far(row[x - px0], len);
                changed = true;
              }
            }
          }
          pairs_.fetch_add(pairs, std::memory_order_relaxed);
          for (int y = py0; y <= py1; ++y)
            for (int x = px0; x <= px1; ++x) {
              std::vector<CoupledInterval>& list = scratch.lists[(y - py0) * kTile + (x - px0)];
              for (const CoupledInterval& e : list)
                if (e.s1 - e.s0 > options_.min_interval)
                  mark(e.primitive, {0, 0, e.depth.sphere, segment_index, step.frame,
                                     static_cast<uint32_t>(face), static_cast<uint32_t>(x),
                                     static_cast<uint32_t>(y), e.s0, e.s1});
              list.clear();
            }
        }
      });
}

}  // namespace

Expected<VisibleSet> solve_coupled(const capture::SceneFile& scene,
                                   std::span<const ViewSegment> segments,
                                   const VisibleSetOptions& options, const Prepared& prepared,
                                   std::chrono::steady_clock::time_point t0) {
  CoupledRunner runner(options, prepared);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  // Motion steps: (f, f + 1) over the range, skipping a step whose two frames repeat the previous
  // step's geometry; a range of one frame is one step without motion.
  const uint32_t last =
      options.frames == 0 ? scene.frame_count
                          : static_cast<uint32_t>(std::min<uint64_t>(
                                scene.frame_count, uint64_t{options.first_frame} + options.frames));
  FrameGeometry a, b, prev_a, prev_b;
  uint64_t steps = 0;
  auto solve = [&](const FrameGeometry& x, const FrameGeometry& y, uint32_t frame) {
    ++steps;
    const Step step{&x, &y, frame};
    for (size_t i = 0; i < segments.size(); ++i)
      arena.execute([&] { runner.run(step, segments[i], static_cast<uint32_t>(i)); });
  };
  if (last - options.first_frame <= 1) {
    build_frame(scene, prepared.table, options.first_frame, &a);
    solve(a, a, options.first_frame);
  } else {
    build_frame(scene, prepared.table, options.first_frame, &b);
    for (uint32_t f = options.first_frame; f + 1 < last; ++f) {
      std::swap(a, b);
      build_frame(scene, prepared.table, f + 1, &b);
      if (steps > 0 && a == prev_a && b == prev_b) continue;
      solve(a, b, f);
      prev_a = a, prev_b = b;
    }
  }
  VisibleSet out;
  collect(scene, prepared.table, runner.visible(), options.object_granularity, &out);
  if (options.witnesses) {
    const PrimitiveTable& table = prepared.table;
    const std::vector<uint8_t>& visible = runner.visible();
    for (uint64_t p = 0; p < visible.size(); ++p) {
      if (!visible[p]) continue;
      VisibilityWitness wit = runner.raw_witnesses()[p];
      const size_t o = static_cast<size_t>(
          std::upper_bound(table.base.begin(), table.base.end(), p) - table.base.begin() - 1);
      wit.object = static_cast<uint32_t>(o);
      wit.primitive = static_cast<uint32_t>(p - table.base[o]);
      wit.sphere = wit.primitive >= table.mesh_triangles[o];
      out.witnesses.push_back(wit);
    }
  }
  out.stats.triangle_pixel_pairs = runner.pairs();
  out.stats.frames_solved = steps;
  out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace calf::encoder::visibility
