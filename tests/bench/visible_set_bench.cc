// bench-visible_set_bench: the from-segment visibility builder (paper 004) on a procedural city of
// boxes generated here (--blocks x --blocks buildings, each face cut into --subdiv^2 quads, on a
// tessellated ground: about 1 M triangles by default), from the perimeter of a view region in a
// street. Prints, as markdown tables:
//   1. from-segment: seconds, seconds per Mtri per metre of perimeter, (triangle, pixel) pairs per
//      second, visible share of the triangles (paper 004 Table 2 reports 0.9-9.9 % on cities);
//   2. time against the number of vertex states (a swaying sub-city, one distinct frame a state),
//      per --motion: per-frame (each state a static scene) and/or coupled (paper 004 Sec. 3.2:
//      the eye walks each segment while the city moves from state k to k + 1; states - 1 steps);
//   3. from-point sampling (ID buffers at evenly spaced points, the paper's Sec. 4.5 baseline) at
//      equal time (triangles found when it has spent the from-segment time; acceptance: the
//      from-segment set is >= 1.2x larger) and at equal completeness (time to find 99 % and
//      100 % of the from-segment set, doubling the points until --max-ratio x the from-segment
//      time).
// Each timing is the median of --repeats runs. docs/VISIBILITY.md keeps a committed run.
//
// With --scene-file DIR it instead runs from-segment only on an exported scene file
// (calf-capture --export-scene), from the perimeter of the scene's view region at the middle of its
// height, for each count of --frames (time against the number of distinct frames, i.e. of vertex
// states sampled), optionally on one --segment only: the blades scene's figures.
#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <string>
#include <thread>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/encoder/visible_set.h"

namespace {

using calf::Box3;
using calf::Vec3;
using calf::capture::SceneFile;
using calf::capture::SceneMesh;
using calf::capture::SceneObject;
using namespace calf::encoder;

uint32_t hash(uint32_t x) {
  x = (x ^ 61) ^ (x >> 16);
  x *= 9;
  x ^= x >> 4;
  x *= 0x27d4eb2d;
  return x ^ (x >> 15);
}

// A grid of n x n quads spanning origin + i/n u + j/n v (both triangles wound the same way).
void add_grid(SceneMesh* m, Vec3 origin, Vec3 u, Vec3 v, int n) {
  const uint32_t base = static_cast<uint32_t>(m->positions.size() / 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec3 p = origin + u * (double(i) / n) + v * (double(j) / n);
      m->positions.insert(m->positions.end(), {float(p.x), float(p.y), float(p.z)});
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = base + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      m->indices.insert(m->indices.end(), {a, b, d, a, d, c});
    }
}

struct City {
  SceneFile scene;
  Box3 region;  // the view region: a stretch of the street between block columns 0 and 1
};

// `states` > 1: every building sways, its roof moving sideways by up to 2 m, one state a frame.
City make_city(int blocks, int subdiv, int states) {
  const double block = 30, street = 12;
  City c;
  SceneFile& s = c.scene;
  s.name = "bench-city";
  s.fps = 1;
  s.frame_count = static_cast<uint32_t>(std::max(1, states));
  s.materials.push_back({});
  const double size = blocks * (block + street);
  SceneMesh ground;
  ground.name = "ground";
  add_grid(&ground, {-street, 0, -street}, {size + street, 0, 0}, {0, 0, size + street}, 64);
  // Wound to face up.
  for (size_t t = 0; t < ground.indices.size(); t += 3)
    std::swap(ground.indices[t + 1], ground.indices[t + 2]);
  s.meshes.push_back(ground);
  s.objects.push_back({"ground", 0, 0, {}});
  for (int bz = 0; bz < blocks; ++bz)
    for (int bx = 0; bx < blocks; ++bx) {
      const uint32_t h = hash(static_cast<uint32_t>(bz * blocks + bx));
      const double x0 = bx * (block + street), z0 = bz * (block + street);
      const double height = 8 + (h % 4000) / 100.0;
      SceneMesh m;
      m.name = fmt::format("building{}_{}", bx, bz);
      const Vec3 o{x0, 0, z0};
      const Vec3 X{block, 0, 0}, Y{0, height, 0}, Z{0, 0, block};
      add_grid(&m, o, Y, X, subdiv);      // z = z0 wall, facing -z
      add_grid(&m, o + Z, X, Y, subdiv);  // z = z0 + block, facing +z
      add_grid(&m, o, Z, Y, subdiv);      // x = x0, facing -x
      add_grid(&m, o + X, Y, Z, subdiv);  // x = x0 + block, facing +x
      add_grid(&m, o + Y, Z, X, subdiv);  // roof, facing +y
      if (states > 1) {
        const size_t nv = m.positions.size() / 3;
        for (int k = 0; k < states; ++k) {
          m.state_times.push_back(static_cast<float>(k));
          const double phase = std::sin(0.9 * k + 0.1 * (h % 31));
          for (size_t v = 0; v < nv; ++v) {
            const double y = m.positions[3 * v + 1];
            m.state_positions.push_back(m.positions[3 * v] + float(2 * phase * y / height));
            m.state_positions.push_back(m.positions[3 * v + 1]);
            m.state_positions.push_back(m.positions[3 * v + 2]);
          }
        }
      }
      s.meshes.push_back(std::move(m));
      s.objects.push_back({fmt::format("building{}_{}", bx, bz),
                           static_cast<uint32_t>(s.meshes.size() - 1),
                           0,
                           {}});
    }
  // The street between block columns 0 and 1, 4 m wide and 40 m long, near the city's middle.
  const double xs = block + 0.5 * street, zm = 0.5 * size;
  c.region = {{xs - 2, 0, zm - 20}, {xs + 2, 3, zm + 20}};
  return c;
}

// Wall and process CPU seconds (all threads) of the run with the median CPU time. The CPU time
// is what the comparisons use: on a shared machine the wall time depends on the other load.
struct Timing {
  double wall = 0, cpu = 0;
};
template <typename F>
Timing median_seconds(int repeats, F&& run) {
  std::vector<Timing> t;
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    run();
    t.push_back({std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(),
                 double(std::clock() - c0) / CLOCKS_PER_SEC});
  }
  std::sort(t.begin(), t.end(), [](const Timing& a, const Timing& b) { return a.cpu < b.cpu; });
  return t[t.size() / 2];
}

double perimeter(const std::vector<ViewSegment>& segs) {
  double p = 0;
  for (const ViewSegment& s : segs) p += calf::length(s.b - s.a);
  return p;
}

// --scene-file: one row per frame count.
int run_scene_file(const std::string& dir, const std::vector<int>& frame_counts, int segment,
                   int segments_per_edge, int repeats, const VisibleSetOptions& base) {
  auto scene = calf::capture::read_scene_file(dir);
  if (!scene.ok()) {
    fmt::print("error: {}\n", scene.status().to_string());
    return 1;
  }
  const Box3 region = scene->view_volume;
  std::vector<ViewSegment> segs = perimeter_segments(region, 0.5 * (region.min.y + region.max.y),
                                                     static_cast<uint32_t>(segments_per_edge));
  if (segment >= 0) {
    if (static_cast<size_t>(segment) >= segs.size()) {
      fmt::print("error: --segment {} of {}\n", segment, segs.size());
      return 1;
    }
    segs = {segs[static_cast<size_t>(segment)]};
  }
  const double mtri = scene->triangle_count() / 1e6, metres = perimeter(segs);
  fmt::print(
      "# visible-set bench: scene '{}' ({}), {:.3f} Mtri, {} frames, {} segment(s), {:.2f} m, face "
      "{}\n\n",
      scene->name, dir, mtri, scene->frame_count, segs.size(), metres, base.face_size);
  fmt::print(
      "| frames | solved | wall s | CPU s | CPU s / frame | CPU s / Mtri / m | (tri, pixel) pairs "
      "| "
      "Mpairs / CPU s | visible tri | visible % |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (int frames : frame_counts) {
    VisibleSetOptions o = base;
    o.frames = static_cast<uint32_t>(std::max(1, frames));
    VisibleSet v;
    const Timing t = median_seconds(repeats, [&] {
      auto r = compute_visible_set(*scene, segs, o);
      if (!r.ok()) {
        fmt::print("error: {}\n", r.status().to_string());
        std::exit(1);
      }
      v = std::move(*r);
    });
    const uint64_t solved = std::max<uint64_t>(1, v.stats.frames_solved);
    fmt::print("| {} | {} | {:.2f} | {:.2f} | {:.2f} | {:.4f} | {} | {:.2f} | {} | {:.3f} |\n",
               frames, v.stats.frames_solved, t.wall, t.cpu, t.cpu / solved,
               t.cpu / solved / mtri / metres, v.stats.triangle_pixel_pairs,
               v.stats.triangle_pixel_pairs / t.cpu / 1e6, v.stats.visible_triangles,
               100.0 * v.stats.visible_triangles / std::max<uint64_t>(1, v.stats.scene_triangles));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int blocks = 14, subdiv = 23, repeats = 1, segments_per_edge = 1, state_blocks = 4;
  uint32_t face = 800, threads = 0;
  double max_ratio = 30, eye = 1.7;
  std::vector<int> state_counts = {1, 2, 4, 8};
  std::vector<std::string> motions = {"per-frame"};
  CLI::App app{"From-segment visibility (paper 004) on a procedural city, against from-point"};
  app.add_option("--blocks", blocks, "buildings per side of the city (default 14)");
  app.add_option("--subdiv", subdiv, "quads per side of each building face (default 23: ~1 Mtri)");
  app.add_option("--face", face, "cube face size (default 800, the paper's)");
  app.add_option("--threads", threads, "worker threads (0: all)");
  app.add_option("--repeats", repeats, "timing repetitions (median reported)");
  app.add_option("--segments-per-edge", segments_per_edge, "perimeter segments per region edge");
  app.add_option("--state-blocks", state_blocks, "buildings per side of the swaying city");
  app.add_option("--states", state_counts, "vertex-state counts to time (default 1 2 4 8)");
  app.add_option("--max-ratio", max_ratio,
                 "from-point stops doubling its points past this x the from-segment time");
  app.add_option("--eye", eye, "eye height of the perimeter (default 1.7)");
  app.add_option("--motion", motions,
                 "table 2's motion models: per-frame and/or coupled (default per-frame)")
      ->check(CLI::IsMember({"per-frame", "coupled"}));
  std::string scene_dir;
  std::vector<int> frame_counts = {1};
  int segment = -1;
  app.add_option("--scene-file", scene_dir,
                 "run from-segment only on this exported scene file (its view region)");
  app.add_option("--frames", frame_counts, "with --scene-file: frame counts to time (default 1)");
  app.add_option("--segment", segment, "with --scene-file: only this perimeter segment");
  CLI11_PARSE(app, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // rows appear as they are measured
  if (!scene_dir.empty()) {
    VisibleSetOptions o;
    o.face_size = face;
    o.threads = threads;
    return run_scene_file(scene_dir, frame_counts, segment, segments_per_edge, repeats, o);
  }

  const City city = make_city(blocks, subdiv, 1);
  const std::vector<ViewSegment> segs =
      perimeter_segments(city.region, eye, static_cast<uint32_t>(segments_per_edge));
  VisibleSetOptions o;
  o.face_size = face;
  o.threads = threads;
  const double mtri = city.scene.triangle_count() / 1e6;
  const double metres = perimeter(segs);
  fmt::print(
      "# visible-set bench: city {}x{} buildings, {:.3f} Mtri, region {}x{} m "
      "(perimeter {:.0f} m, {} segments), face {}, {} threads\n\n",
      blocks, blocks, mtri, city.region.max.x - city.region.min.x,
      city.region.max.z - city.region.min.z, metres, segs.size(), face,
      threads == 0 ? std::thread::hardware_concurrency() : threads);

  // 1. From-segment.
  VisibleSet seg;
  const Timing t_segment = median_seconds(repeats, [&] {
    auto r = compute_visible_set(city.scene, segs, o);
    if (!r.ok()) {
      fmt::print("error: {}\n", r.status().to_string());
      std::exit(1);
    }
    seg = std::move(*r);
  });
  const double t_seg = t_segment.cpu;
  const double share = 100.0 * seg.stats.visible_triangles / seg.stats.scene_triangles;
  fmt::print("## From-segment (paper 004 Alg. 1)\n\n");
  fmt::print(
      "| wall s | CPU s | CPU s / Mtri / m | (tri, pixel) pairs | Mpairs / CPU s | "
      "visible tri | visible % | paper (Table 2: Manhattan 0.9 %, Medieval 8.9 %) |\n"
      "|---|---|---|---|---|---|---|---|\n");
  fmt::print(
      "| {:.2f} | {:.2f} | {:.4f} | {} | {:.1f} | {} | {:.2f} | set <= 10 % of the city: {} "
      "|\n\n",
      t_segment.wall, t_seg, t_seg / mtri / metres, seg.stats.triangle_pixel_pairs,
      seg.stats.triangle_pixel_pairs / t_seg / 1e6, seg.stats.visible_triangles, share,
      share <= 10 ? "yes" : "NO");

  // 2. Time against the number of vertex states.
  fmt::print("## Time against vertex states (swaying {}x{} city, one distinct frame a state)\n\n",
             state_blocks, state_blocks);
  fmt::print(
      "| states | motion | Mtri | wall s | CPU s | frames / steps solved | CPU s / solved | CPU s "
      "/ state | visible tri |\n"
      "|---|---|---|---|---|---|---|---|---|\n");
  for (int states : state_counts)
    for (const std::string& motion : motions) {
      const City sway = make_city(state_blocks, subdiv, states);
      const std::vector<ViewSegment> ss =
          perimeter_segments(sway.region, eye, static_cast<uint32_t>(segments_per_edge));
      VisibleSetOptions om = o;
      om.motion = motion == "coupled" ? VisibilityMotion::kCoupled : VisibilityMotion::kPerFrame;
      VisibleSet v;
      const Timing t =
          median_seconds(repeats, [&] { v = *compute_visible_set(sway.scene, ss, om); });
      fmt::print("| {} | {} | {:.3f} | {:.2f} | {:.2f} | {} | {:.2f} | {:.2f} | {} |\n", states,
                 motion, sway.scene.triangle_count() / 1e6, t.wall, t.cpu, v.stats.frames_solved,
                 t.cpu / std::max<uint64_t>(1, v.stats.frames_solved), t.cpu / states,
                 v.stats.visible_triangles);
    }
  fmt::print("\n");

  // 3. From-point at equal time and equal completeness.
  fmt::print("## From-point sampling (ID buffers at evenly spaced points of each segment)\n\n");
  fmt::print(
      "| points / segment | wall s | CPU s | tri found | of from-segment % |\n"
      "|---|---|---|---|---|\n");
  double equal_time_found = 0, t99 = -1, t100 = -1;
  uint64_t prev_found = 0;
  double prev_t = 0;
  for (uint32_t points = 1;; points *= 2) {
    VisibleSet p;
    const Timing timing = median_seconds(
        repeats, [&] { p = *compute_visible_set_from_points(city.scene, segs, points, o); });
    const double t = timing.cpu;
    const uint64_t found = p.stats.visible_triangles;
    const double pct = 100.0 * found / seg.stats.visible_triangles;
    fmt::print("| {} | {:.2f} | {:.2f} | {} | {:.1f} |\n", points, timing.wall, t, found, pct);
    if (t >= t_seg && equal_time_found == 0) {
      // Linear interpolation in time between the last run below and this one.
      const double f = t > prev_t ? (t_seg - prev_t) / (t - prev_t) : 1;
      equal_time_found = prev_found + f * (double(found) - double(prev_found));
    }
    if (pct >= 99 && t99 < 0) t99 = t;
    if (pct >= 100 && t100 < 0) t100 = t;
    prev_found = found;
    prev_t = t;
    if ((t100 >= 0) || t > max_ratio * t_seg || points >= (1u << 16)) break;
  }
  if (equal_time_found == 0) equal_time_found = double(prev_found);
  const double ratio = seg.stats.visible_triangles / std::max(1.0, equal_time_found);
  fmt::print(
      "\n| comparison | from-segment | from-point | ratio | acceptance |\n|---|---|---|---|---|\n");
  fmt::print("| equal CPU time ({:.2f} s): triangles | {} | {:.0f} | {:.2f}x | >= 1.2x: {} |\n",
             t_seg, seg.stats.visible_triangles, equal_time_found, ratio,
             ratio >= 1.2 ? "yes" : "NO");
  auto when = [&](double t) {
    return t < 0 ? fmt::format("not within {:.0f}x", max_ratio) : fmt::format("{:.2f} s", t);
  };
  fmt::print("| equal completeness 99 %: time | {:.2f} s | {} | {} | (paper: 30 min vs 3.84 s) |\n",
             t_seg, when(t99), t99 < 0 ? "-" : fmt::format("{:.1f}x", t99 / t_seg));
  fmt::print("| equal completeness 100 %: time | {:.2f} s | {} | {} | |\n", t_seg, when(t100),
             t100 < 0 ? "-" : fmt::format("{:.1f}x", t100 / t_seg));
  return 0;
}
