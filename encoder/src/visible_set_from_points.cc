// The from-point baseline (paper 004, Sec. 4.5): an ID buffer per eye point and cube face,
// rendered by a CPU z-buffer rasteriser (the nearest primitive at each pixel centre), united over
// the points. It shares the pixel bounds and the edge functions of the from-segment builder with
// a zero-length motion (w = 0: every edge event is constant), so both see the same pixel centres.
// (eye, face) jobs run in parallel; each writes only flags, so the set is thread-count free.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/visible_set.h"
#include "visible_set_internal.h"

namespace calf::encoder {

using namespace visibility;

namespace {

struct Eye {
  Vec3 position;
  uint32_t index;  // segment (from_points) or eye (at_points)
  double s;        // the point's parameter on its segment
};

struct ZBuffer {
  std::vector<double> depth;
  std::vector<uint32_t> id;
};

Expected<VisibleSet> render_points(const capture::SceneFile& scene, const Prepared& prepared,
                                   const std::vector<Eye>& eyes, const VisibleSetOptions& options,
                                   std::chrono::steady_clock::time_point t0) {
  const uint32_t n = options.face_size;
  const PrimitiveTable& table = prepared.table;
  std::vector<uint8_t> visible(table.count(), 0);
  std::vector<VisibilityWitness> witnesses(options.witnesses ? table.count() : 0);
  std::vector<uint8_t> has_witness(witnesses.size(), 0);
  std::mutex mutex;
  std::atomic<uint64_t> pairs{0};
  tbb::enumerable_thread_specific<ZBuffer> buffers;
  FaceBasis bases[kCubeFaceCount];
  for (int f = 0; f < kCubeFaceCount; ++f) bases[f] = face_basis(f);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  FrameGeometry geo;
  const Vec3 still{0, 0, 0};
  for (uint32_t frame : prepared.frames) {
    build_frame(scene, table, frame, &geo);
    const uint32_t nt = static_cast<uint32_t>(geo.triangles.size());
    const uint32_t jobs = static_cast<uint32_t>(eyes.size()) * kCubeFaceCount;
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<uint32_t>(0, jobs, 1), [&](const tbb::blocked_range<uint32_t>& range) {
            ZBuffer& z = buffers.local();
            z.depth.resize(static_cast<size_t>(n) * n);
            z.id.resize(static_cast<size_t>(n) * n);
            PixelBound bound;
            TriangleSetup setup;
            for (uint32_t job = range.begin(); job < range.end(); ++job) {
              const Eye& eye = eyes[job / kCubeFaceCount];
              const int face = static_cast<int>(job % kCubeFaceCount);
              const FaceBasis& basis = bases[face];
              std::fill(z.depth.begin(), z.depth.end(), std::numeric_limits<double>::infinity());
              std::fill(z.id.begin(), z.id.end(), 0xffffffffu);
              uint64_t count = 0;
              // Triangles in scene order, then spheres; a tie keeps the earlier primitive.
              for (uint32_t t = 0; t < nt; ++t) {
                const Vec3* c = &geo.vertices[3 * static_cast<size_t>(t)];
                if (!bound.compute({c, 3}, eye.position, eye.position, basis, n, prepared.delta))
                  continue;
                setup_triangle(c, eye.position, still, basis, &setup);
                for (int y = bound.y0(); y <= bound.y1(); ++y) {
                  int xa, xb;
                  if (!bound.row_span(y, &xa, &xb)) continue;
                  const double tc = pixel_sc(static_cast<uint32_t>(y), n);
                  for (int x = xa; x <= xb; ++x) {
                    ++count;
                    Interval iv;
                    if (!triangle_coverage(setup, pixel_sc(static_cast<uint32_t>(x), n), tc, &iv))
                      continue;
                    const size_t i = static_cast<size_t>(y) * n + x;
                    if (iv.p < z.depth[i]) z.depth[i] = iv.p, z.id[i] = geo.triangles[t];
                  }
                }
              }
              for (const WorldSphere& s : geo.spheres) {
                Vec3 pts[8];
                for (int i = 0; i < 8; ++i)
                  pts[i] =
                      s.centre + Vec3{i & 1 ? s.radius : -s.radius, i & 2 ? s.radius : -s.radius,
                                      i & 4 ? s.radius : -s.radius};
                if (!bound.compute({pts, 8}, eye.position, eye.position, basis, n, prepared.delta))
                  continue;
                for (int y = bound.y0(); y <= bound.y1(); ++y) {
                  int xa, xb;
                  if (!bound.row_span(y, &xa, &xb)) continue;
                  const double tc = pixel_sc(static_cast<uint32_t>(y), n);
                  for (int x = xa; x <= xb; ++x) {
                    ++count;
                    const double sc = pixel_sc(static_cast<uint32_t>(x), n);
                    Interval iv[2];
                    SphereDepth depth;
                    if (sphere_coverage(s, eye.position, still,
                                        basis.m + basis.s * sc + basis.t * tc, iv, &depth) == 0)
                      continue;
                    const SphereDepth table_one[1] = {depth};
                    iv[0].sphere = 0;
                    const double d = depth_at(iv[0], table_one, 0);
                    const size_t i = static_cast<size_t>(y) * n + x;
                    if (d < z.depth[i]) z.depth[i] = d, z.id[i] = s.primitive;
                  }
                }
              }
              pairs.fetch_add(count, std::memory_order_relaxed);
              for (uint32_t y = 0; y < n; ++y)
                for (uint32_t x = 0; x < n; ++x) {
                  const uint32_t id = z.id[static_cast<size_t>(y) * n + x];
                  if (id == 0xffffffffu) continue;
                  std::atomic_ref<uint8_t>(visible[id]).store(1, std::memory_order_relaxed);
                  if (!options.witnesses) continue;
                  const VisibilityWitness w{
                      0, 0, false, eye.index, frame, static_cast<uint32_t>(face),
                      x, y, eye.s, eye.s};
                  std::lock_guard<std::mutex> lock(mutex);
                  if (!has_witness[id] || better_witness(w, witnesses[id]))
                    witnesses[id] = w, has_witness[id] = 1;
                }
            }
          });
    });
  }
  VisibleSet out;
  collect(scene, table, visible, options.object_granularity, &out);
  if (options.witnesses)
    for (uint64_t p = 0; p < visible.size(); ++p) {
      if (!visible[p]) continue;
      VisibilityWitness w = witnesses[p];
      const size_t o = static_cast<size_t>(
          std::upper_bound(table.base.begin(), table.base.end(), p) - table.base.begin() - 1);
      w.object = static_cast<uint32_t>(o);
      w.primitive = static_cast<uint32_t>(p - table.base[o]);
      w.sphere = w.primitive >= table.mesh_triangles[o];
      out.witnesses.push_back(w);
    }
  out.stats.triangle_pixel_pairs = pairs.load();
  out.stats.frames_solved = prepared.frames.size();
  out.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace

Expected<VisibleSet> compute_visible_set_from_points(const capture::SceneFile& scene,
                                                     std::span<const ViewSegment> segments,
                                                     uint32_t points_per_segment,
                                                     const VisibleSetOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (segments.empty())
    return Status(ErrorId::kVisibleSetNoSegment,
                  "no view segment given for scene '" + scene.name + "'");
  if (points_per_segment == 0 || points_per_segment > 1000000)
    return Status(
        ErrorId::kVisibleSetOption,
        "points_per_segment " + std::to_string(points_per_segment) + " is outside 1..1000000");
  for (size_t i = 0; i < segments.size(); ++i) {
    const ViewSegment& s = segments[i];
    if (!is_finite(s.a) || !is_finite(s.b) || s.a == s.b)
      return Status(ErrorId::kVisibleSetSegment,
                    "segment " + std::to_string(i) +
                        (is_finite(s.a) && is_finite(s.b) ? " has zero length" : " is not finite"));
  }
  CALF_ASSIGN_OR_RETURN(Prepared prepared, prepare(scene, options));
  std::vector<Eye> eyes;
  for (size_t i = 0; i < segments.size(); ++i) {
    CALF_RETURN_IF_ERROR(
        check_point(prepared, segments[i].a, "segment " + std::to_string(i) + " start"));
    CALF_RETURN_IF_ERROR(
        check_point(prepared, segments[i].b, "segment " + std::to_string(i) + " end"));
    for (uint32_t k = 0; k < points_per_segment; ++k) {
      const double s =
          points_per_segment == 1 ? 0.5 : static_cast<double>(k) / (points_per_segment - 1);
      eyes.push_back(
          {segments[i].a + (segments[i].b - segments[i].a) * s, static_cast<uint32_t>(i), s});
    }
  }
  return render_points(scene, prepared, eyes, options, t0);
}

Expected<VisibleSet> compute_visible_set_at_points(const capture::SceneFile& scene,
                                                   std::span<const Vec3> points,
                                                   const VisibleSetOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  if (points.empty())
    return Status(ErrorId::kVisibleSetNoSegment,
                  "no eye point given for scene '" + scene.name + "'");
  CALF_ASSIGN_OR_RETURN(Prepared prepared, prepare(scene, options));
  std::vector<Eye> eyes;
  for (size_t i = 0; i < points.size(); ++i) {
    CALF_RETURN_IF_ERROR(check_point(prepared, points[i], "eye " + std::to_string(i)));
    eyes.push_back({points[i], static_cast<uint32_t>(i), 0});
  }
  return render_points(scene, prepared, eyes, options, t0);
}

}  // namespace calf::encoder
