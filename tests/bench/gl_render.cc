// bench-gl_render: frame time of the GL ray-march renderer (calf/player/lightfield_gl_renderer.h)
// under OSMesa (llvmpipe on a machine without a GPU driver), plain and RR, for image sizes and view
// counts, with the scalar CPU reference renderer on the same frame as the peer.
//
// Scene: the synthetic room of the player tests (tests/player/synthetic_scene.h: a box room with
// spheres, RR with a mirror floor), views on the corners of a cube of side 1 around the eye (plus
// its centre for 9), faces of --face texels uploaded as rgba16f colour / r16 depth / rgba8
// material (updates_from_view_set). Eye between the views, 70° field of view.
// Each figure: the first frame (includes the driver's shader JIT) and the median, min and max of
// --repeats frames after it; a frame is draw + glReadPixels of the RGBA32F target. Mpix/s counts
// output pixels (from the median). cpu-time: the process's CPU time per timed frame, summed over
// llvmpipe's threads — on a shared machine wall time depends on the load, this hardly does. The CPU
// peer renders the same frame with --cpu-threads threads (sizes up to
// --cpu-max-size: it is slow).
#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <ctime>
#include <string>
#include <vector>

#include "../player/synthetic_scene.h"
#include "bench_clock.h"
#include "calf/player/gl_context.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/lightfield_gl_renderer.h"

namespace {

using namespace calf;
using namespace calf::player;

using bench::now_ms;
// CPU time of the whole process (every llvmpipe thread): unlike wall time, it hardly depends on
// what else runs on the machine.
double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

std::vector<Vec3> view_positions(uint32_t count) {
  std::vector<Vec3> v;
  for (int i = 0; i < 8; ++i) {
    v.push_back({(i & 1) ? -0.5 : 0.5, (i & 2) ? -0.5 : 0.5, 0.5 + ((i & 4) ? -0.5 : 0.5)});
  }
  v.push_back({0, 0, 0.5});
  v.resize(count);
  return v;
}

testing::Scene scene(bool mirror) {
  testing::Scene s;
  s.spheres = {{{0, -0.5, -2.2}, 0.8}, {{1.6, 0.6, -1.2}, 0.45}};
  s.mirror_floor = mirror;
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"GL ray-march renderer frame time under OSMesa, with the CPU reference as peer"};
  std::vector<uint32_t> sizes = {256, 512}, view_counts = {4, 9};
  uint32_t face = 256, steps = 64, repeats = 5, cpu_threads = 2, cpu_max_size = 256;
  LightfieldRenderOptions defaults;
  uint32_t hints = defaults.surface_hints, hint_substeps = defaults.surface_hint_substeps;
  bool rr_replace = defaults.rr_replace_view_reflection;
  app.add_option("--sizes", sizes, "square image sizes")->capture_default_str();
  app.add_option("--views", view_counts, "view counts (1..9)")->capture_default_str();
  app.add_option("--face", face, "view face size, texels")->capture_default_str();
  app.add_option("--steps", steps, "ray-march steps N_step")->capture_default_str();
  app.add_option("--repeats", repeats, "timed frames after the first")->capture_default_str();
  app.add_option("--cpu-threads", cpu_threads, "threads of the CPU peer")->capture_default_str();
  app.add_option("--cpu-max-size", cpu_max_size, "largest size the CPU peer renders (0: none)")
      ->capture_default_str();
  app.add_option("--hints", hints, "LightfieldRenderOptions::surface_hints")->capture_default_str();
  app.add_option("--hint-substeps", hint_substeps, "LightfieldRenderOptions::surface_hint_substeps")
      ->capture_default_str();
  app.add_option("--rr-replace", rr_replace,
                 "LightfieldRenderOptions::rr_replace_view_reflection (0/1)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  Expected<std::unique_ptr<OsMesaContext>> ctx = OsMesaContext::make();
  if (!ctx.ok()) {
    fmt::print("no GL context: {}\n", ctx.status().to_string());
    return 1;
  }
  const GlFunctions& gl = (*ctx)->gl();
  fmt::print(
      "renderer: {} (GL {}.{}); faces {}^2, {} steps, {} hints x {} substeps, RR replace {}, "
      "{} repeats\n",
      gl.renderer, gl.major_version, gl.minor_version, face, steps, hints, hint_substeps,
      rr_replace ? 1 : 0, repeats + 1);
  fmt::print("{:>5} {:>5} {:>5} | {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} | {:>8} {:>6}\n", "size",
             "views", "mode", "first ms", "median", "min", "max", "Mpix/s", "cpu-time", "peer ms",
             "GL/CPU");
  for (bool rr : {false, true}) {
    const testing::Scene s = scene(rr);
    for (uint32_t count : view_counts) {
      const ViewSet views = testing::make_views(s, view_positions(count), face, rr);
      Expected<ViewSetUpload> up = updates_from_view_set(views);
      if (!up.ok()) return 1;
      Expected<std::unique_ptr<GlViews>> gv = GlViews::make(gl, up->layout);
      if (!gv.ok() || !(*gv)->apply(up->frame).ok()) {
        fmt::print("upload failed\n");
        return 1;
      }
      for (uint32_t size : sizes) {
        Camera cam;
        cam.position = {0.12, 0.07, 0.55};
        cam.forward = {-0.1, -0.15, -1};
        cam.fov_y = 70 * 3.141592653589793 / 180;
        cam.width = cam.height = size;
        LightfieldRenderOptions o;
        o.steps = steps;
        o.rr = rr;
        o.surface_hints = hints;
        o.surface_hint_substeps = hint_substeps;
        o.rr_replace_view_reflection = rr_replace;
        o = *march_range_for(up->layout, cam.position, o);
        Expected<std::unique_ptr<LightfieldGlRenderer>> r = LightfieldGlRenderer::make(**gv, o);
        if (!r.ok()) {
          fmt::print("{}\n", r.status().to_string());
          return 1;
        }
        RenderedImage img;
        double t0 = now_ms();
        if (!(*r)->render(cam, &img).ok()) return 1;
        const double first = now_ms() - t0;
        std::vector<double> ms;
        const double cpu0 = process_cpu_ms();
        for (uint32_t i = 0; i < repeats; ++i) {
          t0 = now_ms();
          if (!(*r)->render(cam, &img).ok()) return 1;
          ms.push_back(now_ms() - t0);
        }
        const double cpu_per_frame = (process_cpu_ms() - cpu0) / std::max(repeats, 1u);
        std::sort(ms.begin(), ms.end());
        const double median = ms.empty() ? first : ms[ms.size() / 2];
        std::string cpu = "-", ratio = "-";
        if (size <= cpu_max_size) {
          o.threads = cpu_threads;
          const Expected<LightfieldCpuRenderer> c = LightfieldCpuRenderer::make(views, o);
          t0 = now_ms();
          if (!c.ok() || !c->render(cam, &img).ok()) return 1;
          const double cpu_ms = now_ms() - t0;
          cpu = fmt::format("{:.0f}", cpu_ms);
          ratio = fmt::format("{:.2f}", median / cpu_ms);
        }
        fmt::print(
            "{:>5} {:>5} {:>5} | {:>8.0f} {:>8.1f} {:>8.1f} {:>8.1f} {:>7.2f} {:>8.1f} | {:>8} "
            "{:>6}\n",
            size, count, rr ? "RR" : "plain", first, median, ms.empty() ? first : ms.front(),
            ms.empty() ? first : ms.back(), static_cast<double>(size) * size / median / 1e3,
            cpu_per_frame, cpu, ratio);
      }
    }
  }
  return 0;
}
